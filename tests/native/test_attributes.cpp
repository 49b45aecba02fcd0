// Vertex attributes through encode and decode: bit-exact values of every
// type on meshes, point clouds (coincident points with values of their
// own), tetrahedral meshes and a lone vertex; every prefix gives each of its
// vertices the values of an input vertex; damaged tables are refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <random>

#include "attribute_support.h"
#include "attributes.h"
#include "complexes.h"
#include "kdmesh/io.h"
#include "shapes.h"
#include "test_support.h"

namespace kdmesh::test {
namespace {

TEST(Attributes, EveryTypeRoundTripsOnAMesh) {
  Complex mesh = torusMesh(14, 22);
  mesh.attributes = everyKind(mesh, 1);
  EncodeOptions options;
  options.bits = 12;
  options.chunkBytes = 256;
  expectRoundTrip(mesh, options);
  options.exact = true;
  expectRoundTrip(mesh, options);
}

TEST(Attributes, CoincidentPointsKeepValuesOfTheirOwn) {
  Complex cloud = pointCloud(coincidentCloud(3000, 5));
  cloud.attributes = everyKind(cloud, 2);
  EncodeOptions options;
  options.exact = true;
  options.chunkBytes = 256;
  expectRoundTrip(cloud, options);
  // All at one place: no geometric level, the points told apart by their
  // coincident levels alone.
  Complex stack = pointCloud(std::vector<float>(3 * 100, 1.5f));
  stack.attributes = everyKind(stack, 3);
  expectRoundTrip(stack, options);
}

TEST(Attributes, PointCloudsMeshesWithCoincidentVerticesAndTetrahedra) {
  EncodeOptions options;
  options.exact = true;
  options.chunkBytes = 256;
  Complex cloud = pointCloud(sphereSurface(4000, 4));
  cloud.attributes = everyKind(cloud, 4);
  expectRoundTrip(cloud, options);
  Complex block = tetrahedralBlock(3, 5);
  block.attributes = everyKind(block, 5);
  expectRoundTrip(block, options);
  Complex mixed = randomComplex(77, 40, 60);
  mixed.attributes = everyKind(mixed, 6);
  expectRoundTrip(mixed, options);
  // Two triangles on the same three positions: a seam, each copy with values of its own.
  Complex seam;
  seam.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0};
  seam.triangles = {0, 1, 2, 3, 5, 4};
  seam.attributes = {attribute("uv", AttributeType::Float32, 2, std::vector<float>{0, 0, 1, 0, 0, 1, .5f, .5f, .7f, .5f, .5f, .7f})};
  expectRoundTrip(seam, options);
}

TEST(Attributes, ALoneVertexHasItsValuesInTheTable) {
  Complex one = pointCloud({0.25f, -1.f, 3.f});
  one.attributes = {attribute("color", AttributeType::UInt8, 4, std::vector<uint8_t>{1, 2, 3, 4})};
  EncodeOptions options;
  options.exact = true;
  expectRoundTrip(one, options);
}

TEST(Attributes, StreamsWithoutAttributesHaveNone) {
  const Complex mesh = torusMesh(8, 10);
  const std::vector<uint8_t> bytes = encodeOrDie(mesh, EncodeOptions{});
  Decoder decoder;
  ASSERT_TRUE(decoder.push(bytes.data(), bytes.size()).ok());
  EXPECT_EQ(decoder.header().attributeCount, 0);
  EXPECT_TRUE(decoder.snapshot().attributes.empty());
}

TEST(Attributes, InvalidAttributesAreRefusedByTheEncoder) {
  const Complex mesh = torusMesh(6, 8);
  auto refused = [&](std::vector<VertexAttribute> attributes) {
    Complex c = mesh;
    c.attributes = std::move(attributes);
    return encode(c, EncodeOptions{}).status;
  };
  const std::vector<uint8_t> rgb(mesh.vertexCount() * 3, 7);
  EXPECT_EQ(refused({attribute("", AttributeType::UInt8, 3, rgb)}).code, ErrorCode::InvalidInput);
  EXPECT_EQ(refused({attribute("a\n", AttributeType::UInt8, 3, rgb)}).code, ErrorCode::InvalidInput);
  EXPECT_EQ(refused({attribute("c", AttributeType::UInt8, 3, rgb), attribute("c", AttributeType::UInt8, 3, rgb)}).code,
            ErrorCode::InvalidInput);
  EXPECT_EQ(refused({attribute("c", AttributeType::UInt8, 5, std::vector<uint8_t>(mesh.vertexCount() * 5))}).code,
            ErrorCode::InvalidInput);
  const Status wrongSize = refused({attribute("c", AttributeType::UInt16, 3, rgb)});
  EXPECT_EQ(wrongSize.code, ErrorCode::InvalidInput);
  EXPECT_NE(wrongSize.message.find("3 uint16 per vertex"), std::string::npos) << wrongSize.message;
  std::vector<VertexAttribute> many;
  for (int i = 0; i <= int(kMaxAttributes); ++i) many.push_back(attribute("a" + std::to_string(i), AttributeType::UInt8, 3, rgb));
  EXPECT_EQ(refused(many).code, ErrorCode::Unsupported);
}

TEST(Attributes, ADamagedTableIsACorruptHeader) {
  Complex mesh = torusMesh(6, 8);
  mesh.attributes = everyKind(mesh, 7);
  const std::vector<uint8_t> bytes = encodeOrDie(mesh, EncodeOptions{});
  Decoder reference;
  ASSERT_TRUE(reference.push(bytes.data(), bytes.size()).ok());
  const size_t tableAt = reference.header().headerBytes;
  const size_t tableEnd = reference.chunks().front().offset;
  for (size_t i = tableAt; i < tableEnd; ++i) {
    std::vector<uint8_t> damaged = bytes;
    damaged[i] ^= 0x10;
    Complex out;
    EXPECT_EQ(decode(damaged.data(), damaged.size(), out).code, ErrorCode::CorruptHeader) << "byte " << i;
  }
  // A table cut short waits for its bytes, then the stream is truncated.
  Decoder partial;
  ASSERT_TRUE(partial.push(bytes.data(), tableEnd - 1).ok());
  EXPECT_TRUE(partial.snapshot().attributes.empty());
  EXPECT_EQ(partial.finish().code, ErrorCode::Truncated);
}

// PLY holds every attribute: written binary or ascii and read back, the
// same names, types and values (colours, normals and texture coordinates
// under the property names other programs use); other formats refuse them.
TEST(Attributes, PlyKeepsThemAndOtherFormatsRefuseThem) {
  Complex mesh = torusMesh(6, 9);
  mesh.attributes = everyKind(mesh, 8);
  for (const bool ascii : {false, true}) {
    SCOPED_TRACE(ascii ? "ascii" : "binary");
    std::vector<uint8_t> file;
    io::WriteOptions options;
    options.asciiPly = ascii;
    ASSERT_TRUE(io::writeMemory(io::Format::Ply, mesh, file, options).ok());
    const std::string text(file.begin(), file.end());
    for (const char* property : {"property uchar red", "property float nx", "property float u", "property int label",
                                 "property float normal_0"})
      EXPECT_EQ(text.find(property) != std::string::npos, std::string(property) != "property float normal_0")
          << property;
    Complex back;
    io::Notes notes;
    ASSERT_TRUE(io::readMemory(io::Format::Ply, file.data(), file.size(), back, notes).ok());
    ASSERT_EQ(back.attributes.size(), mesh.attributes.size());
    for (size_t a = 0; a < mesh.attributes.size(); ++a) {
      EXPECT_EQ(back.attributes[a].name, mesh.attributes[a].name);
      EXPECT_EQ(back.attributes[a].type, mesh.attributes[a].type);
      EXPECT_EQ(back.attributes[a].components, mesh.attributes[a].components);
      // Ascii float text cannot carry NaN payloads: compare the bits elsewhere.
      if (!ascii || mesh.attributes[a].type != AttributeType::Float32) {
        EXPECT_EQ(back.attributes[a].values, mesh.attributes[a].values) << mesh.attributes[a].name;
      }
    }
  }
  // Properties named name_0, name_1, ... are one attribute of several components.
  Complex pair = pointCloud({0, 0, 0, 1, 1, 1});
  pair.attributes = {attribute("weights", AttributeType::UInt16, 2, std::vector<uint16_t>{1, 2, 3, 4})};
  std::vector<uint8_t> file;
  ASSERT_TRUE(io::writeMemory(io::Format::Ply, pair, file).ok());
  Complex back;
  io::Notes notes;
  ASSERT_TRUE(io::readMemory(io::Format::Ply, file.data(), file.size(), back, notes).ok());
  ASSERT_EQ(back.attributes.size(), 1u);
  EXPECT_EQ(back.attributes[0].name, "weights");
  EXPECT_EQ(back.attributes[0].components, 2);
  for (const io::Format format : {io::Format::Obj, io::Format::Off, io::Format::Xyz}) {
    const Status s = io::writeMemory(format, mesh, file);
    EXPECT_EQ(s.code, ErrorCode::InvalidArgument) << io::formatName(format);
    EXPECT_NE(s.message.find("write PLY"), std::string::npos) << s.message;
  }
}

// Welding merges vertices only when their positions and values are all
// bit-identical: a seam's vertices, with values of their own, stay apart.
TEST(Attributes, WeldingKeepsVerticesWhoseValuesDiffer) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n"
      "0 0 0 1 2 3\n0 0 0 1 2 3\n0 0 0 9 9 9\n1 0 0 1 2 3\n3 0 2 3\n";
  Complex c;
  io::Notes notes;
  io::ReadOptions options;
  options.weld = true;
  ASSERT_TRUE(io::readMemory(io::Format::Ply, reinterpret_cast<const uint8_t*>(ply.data()), ply.size(), c, notes,
                             options)
                  .ok());
  EXPECT_EQ(c.vertexCount(), 3u);
  ASSERT_EQ(c.attributes.size(), 1u);
  EXPECT_EQ(c.attributes[0].values, (std::vector<uint8_t>{1, 2, 3, 9, 9, 9, 1, 2, 3}));
  EXPECT_EQ(c.triangles, (std::vector<uint32_t>{0, 1, 2}));
}

}  // namespace
}  // namespace kdmesh::test

namespace kdmesh::test {
namespace {

// Quantized values stand for floats whose images are those values again,
// so that encoder and decoder predict from the same images: every
// octahedral image of every dequantized normal is a fixed point, and inside
// the square's edges every quantized pair is its own image.
TEST(AttributeQuantization, OctahedralImagesOfDequantizedNormalsAreFixedPoints) {
  const VertexAttribute normal{"normal", AttributeType::Float32, 3, {}, {}};
  for (int bits = 2; bits <= 12; ++bits) {
    AttributeQuantization q;
    q.kind = AttributeQuantization::Octahedral;
    q.bits = uint8_t(bits);
    const AttributeCoder::Layout layout = AttributeCoder::layoutOf(normal, q, 0);
    const uint32_t top = (1u << bits) - 2;
    ASSERT_EQ(layout.top, top);
    uint8_t values[12], again[12];
    for (uint32_t u = 0; u <= top; ++u)
      for (uint32_t v = 0; v <= top; ++v) {
        const uint32_t in[2] = {u, v};
        uint32_t image[2], second[2];
        AttributeCoder::store(layout, values, in);
        AttributeCoder::images(layout, values, image);
        if (u > 0 && u < top && v > 0 && v < top) {
          ASSERT_TRUE(image[0] == u && image[1] == v) << bits << " bits: " << u << ", " << v;
        }
        AttributeCoder::store(layout, again, image);
        AttributeCoder::images(layout, again, second);
        ASSERT_TRUE(second[0] == image[0] && second[1] == image[1]) << bits << " bits: " << u << ", " << v;
        ASSERT_EQ(std::memcmp(values, again, 12), 0) << bits << " bits: " << u << ", " << v;
        float n[3];
        std::memcpy(n, values, 12);
        ASSERT_NEAR(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2], 1.0, 1e-6);
        // The mirror image (z negated) of a canonical image is the canonical
        // image of the mirrored vector, and mirrors back.
        uint32_t mirrored[2] = {image[0], image[1]};
        AttributeCoder::mirrorOctahedral(layout, mirrored);
        // (On the diamond's edge z is 0 but its float may be just below.)
        if (std::fabs(n[2]) > 1e-6) {
          ASSERT_EQ(AttributeCoder::lowerHemisphere(layout, image), n[2] < 0) << bits << " bits: " << u << ", " << v;
        }
        const float flipped[3] = {n[0], n[1], -n[2]};
        uint32_t expected[2];
        AttributeCoder::images(layout, reinterpret_cast<const uint8_t*>(flipped), expected);
        ASSERT_TRUE(mirrored[0] == expected[0] && mirrored[1] == expected[1])
            << bits << " bits: " << image[0] << ", " << image[1] << " -> " << mirrored[0] << ", " << mirrored[1]
            << " (expected " << expected[0] << ", " << expected[1] << ")";
        AttributeCoder::mirrorOctahedral(layout, mirrored);
        ASSERT_TRUE(mirrored[0] == image[0] && mirrored[1] == image[1]) << bits << " bits: " << u << ", " << v;
      }
  }
}

TEST(AttributeQuantization, UniformImagesOfDequantizedValuesAreFixedPoints) {
  std::mt19937 rng(5);
  // Ranges of every scale, narrow ranges far from 0 (where the step is held
  // at 2^-22 of the magnitude), constants and ranges across 0.
  const std::vector<std::pair<float, float>> ranges = {
      {0.f, 1.f}, {-1.f, 1.f}, {1000.f, 1000.001f}, {-3e7f, 5e-3f}, {7.f, 7.f}, {1e-30f, 3e-30f}, {-1e30f, 1e30f}};
  for (const int bits : {1, 5, 12, 16, 20, 24}) {
    for (const auto& [low, high] : ranges) {
      Complex c = pointCloud({0, 0, 0, 1, 1, 1});
      c.attributes = {attribute("x", AttributeType::Float32, 1, std::vector<float>{low, high})};
      EncodeOptions options;
      options.attributeBits = bits;
      std::vector<AttributeQuantization> q;
      ASSERT_TRUE(chooseQuantization(c, options, q).ok());
      ASSERT_EQ(q[0].kind, AttributeQuantization::Uniform);
      const AttributeCoder::Layout layout = AttributeCoder::layoutOf(c.attributes[0], q[0], 0);
      // Both ends of the range are within half a step of their value.
      for (const float x : {low, high}) {
        uint32_t image;
        float back;
        AttributeCoder::images(layout, reinterpret_cast<const uint8_t*>(&x), &image);
        AttributeCoder::store(layout, reinterpret_cast<uint8_t*>(&back), &image);
        EXPECT_LE(std::fabs(double(back) - double(x)), 0.5 * double(q[0].step[0]) + std::fabs(double(x)) * 1e-7)
            << bits << " bits, " << low << ".." << high;
      }
      // Every image up to the range's end (those the encoder makes).
      uint32_t top;
      AttributeCoder::images(layout, reinterpret_cast<const uint8_t*>(&high), &top);
      ASSERT_LE(top, layout.top);
      for (int i = 0; i < 4096; ++i) {
        const uint32_t image = i < 2048 ? std::min<uint32_t>(uint32_t(i), top) : uint32_t(rng() % (uint64_t(top) + 1));
        float value;
        uint32_t again;
        AttributeCoder::store(layout, reinterpret_cast<uint8_t*>(&value), &image);
        AttributeCoder::images(layout, reinterpret_cast<const uint8_t*>(&value), &again);
        ASSERT_EQ(again, q[0].step[0] == 0 ? 0u : image) << bits << " bits, " << low << ".." << high;
      }
    }
  }
}

// Quantized attributes decode to the quantized input values: every vertex,
// and every prefix's, has the dequantized values of an input vertex, and
// they are within the quantization's error of the input.
TEST(AttributeQuantization, DecodesToTheQuantizedInputOnEveryPrefix) {
  Complex mesh = sphereMesh(16, 24);
  std::vector<float> normals, uv, weight;
  std::vector<uint8_t> colour;
  for (size_t v = 0; v < mesh.vertexCount(); ++v) {
    const float* p = &mesh.positions[3 * v];
    normals.insert(normals.end(), p, p + 3);  // a unit sphere: its normals
    uv.insert(uv.end(), {std::atan2(p[1], p[0]), p[2] * 0.5f + 0.5f});
    weight.push_back(float(v % 7) - 2.5f);
    colour.insert(colour.end(), {uint8_t(v), uint8_t(v * 3), uint8_t(v * 7)});
  }
  mesh.attributes = {attribute("normal", AttributeType::Float32, 3, normals),
                     attribute("uv", AttributeType::Float32, 2, uv),
                     attribute("weight", AttributeType::Float32, 1, weight),
                     attribute("color", AttributeType::UInt8, 3, colour)};
  for (const auto& [attributeBits, normalBits] : {std::pair{12, 10}, std::pair{6, 0}, std::pair{0, 8}}) {
    SCOPED_TRACE(std::to_string(attributeBits) + " attribute bits, " + std::to_string(normalBits) + " normal bits");
    EncodeOptions options;
    options.exact = true;
    options.attributeBits = attributeBits;
    options.normalBits = normalBits;
    options.chunkBytes = 256;
    const EncodeResult encoded = encode(mesh, options);
    ASSERT_TRUE(encoded.status.ok()) << encoded.status.message;
    Complex decoded;
    ASSERT_TRUE(decode(encoded.bytes.data(), encoded.bytes.size(), decoded).ok());
    expectSameDescriptors(mesh, decoded);
    // The input as the stream holds it: its values quantized and back.
    Complex expected = mesh;
    for (size_t a = 0; a < mesh.attributes.size(); ++a) {
      const AttributeQuantization& q = decoded.attributes[a].quantization;
      const AttributeQuantization::Kind kind =
          mesh.attributes[a].type != AttributeType::Float32 ? AttributeQuantization::Exact
          : a == 0 && normalBits > 0                        ? AttributeQuantization::GeometricOctahedral
          : attributeBits > 0                               ? AttributeQuantization::Uniform
                                                            : AttributeQuantization::Exact;
      ASSERT_EQ(q.kind, kind) << mesh.attributes[a].name;
      const AttributeCoder::Layout layout = AttributeCoder::layoutOf(mesh.attributes[a], q, 0);
      VertexAttribute& values = expected.attributes[a];
      for (size_t v = 0; v < mesh.vertexCount(); ++v) {
        uint32_t images[4];
        AttributeCoder::images(layout, &mesh.attributes[a].values[v * values.valueBytes()], images);
        AttributeCoder::store(layout, &values.values[v * values.valueBytes()], images);
      }
      // Within the quantization's error of the input.
      for (size_t i = 0; kind != AttributeQuantization::Exact && i < values.values.size() / 4; ++i) {
        float in, out;
        std::memcpy(&in, &mesh.attributes[a].values[4 * i], 4);
        std::memcpy(&out, &values.values[4 * i], 4);
        const double bound = kind == AttributeQuantization::Uniform ? 0.5 * q.step[i % values.components] * 1.0001
                                                                    : 4.0 / double(1 << q.bits);
        ASSERT_LE(std::fabs(double(in) - double(out)), bound) << mesh.attributes[a].name << " value " << i;
      }
    }
    auto sortedKeys = [](const Complex& c) {
      std::vector<VertexKey> keys = vertexKeys(c);
      std::sort(keys.begin(), keys.end());
      return keys;
    };
    EXPECT_TRUE(sortedKeys(decoded) == sortedKeys(expected)) << "decoded values are not the quantized input";
    // Prefixes: each vertex has the values of an input vertex, but for
    // normals coded after the kd-tree, which are unit vectors and, on a
    // vertex of the prefix's triangles, the outward normal of the surface.
    const bool geometricNormals = normalBits > 0;
    auto withoutNormals = [geometricNormals](Complex c) {
      if (geometricNormals) c.attributes.erase(c.attributes.begin());
      return c;
    };
    std::set<VertexKey> values;
    for (const VertexKey& key : vertexKeys(withoutNormals(expected)))
      values.insert(VertexKey(key.begin() + 12, key.end()));
    Decoder whole;
    ASSERT_TRUE(whole.push(encoded.bytes.data(), encoded.bytes.size()).ok());
    ASSERT_GT(whole.chunks().size(), 2u);
    for (const ChunkInfo& chunk : whole.chunks()) {
      Decoder prefix;
      ASSERT_TRUE(prefix.push(encoded.bytes.data(), chunk.offset).ok());
      if (!prefix.hasHeader()) continue;
      const Complex coarse = prefix.snapshot();
      if (coarse.attributes.empty()) continue;
      expectSameDescriptors(mesh, coarse);
      for (const VertexKey& key : vertexKeys(withoutNormals(coarse)))
        ASSERT_TRUE(values.count(VertexKey(key.begin() + 12, key.end()))) << "prefix of " << chunk.offset;
      if (!geometricNormals) continue;
      std::vector<bool> inTriangle(coarse.vertexCount(), false);
      for (const uint32_t v : coarse.triangles) inTriangle[v] = true;
      for (size_t v = 0; v < coarse.vertexCount(); ++v) {
        float n[3];
        std::memcpy(n, &coarse.attributes[0].values[12 * v], 12);
        const float* p = &coarse.positions[3 * v];
        ASSERT_NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1.0, 1e-5) << "prefix of " << chunk.offset;
        if (inTriangle[v]) {
          ASSERT_GT(n[0] * p[0] + n[1] * p[1] + n[2] * p[2], 0.0f) << "vertex " << v << ", prefix of " << chunk.offset;
        }
      }
    }
  }
}

TEST(AttributeQuantization, BadOptionsAndNonFiniteValuesAreRefused) {
  Complex c = pointCloud({0, 0, 0, 1, 1, 1});
  c.attributes = {attribute("normal", AttributeType::Float32, 3, std::vector<float>{0, 0, 1, 0, NAN, 1})};
  EncodeOptions options;
  EXPECT_TRUE(encode(c, options).status.ok());  // exact keeps NaN
  options.normalBits = 17;
  EXPECT_EQ(encode(c, options).status.code, ErrorCode::InvalidArgument);
  options.normalBits = 0;
  options.attributeBits = 25;
  EXPECT_EQ(encode(c, options).status.code, ErrorCode::InvalidArgument);
  options.attributeBits = 0;
  options.normalBits = 8;
  const Status s = encode(c, options).status;
  EXPECT_EQ(s.code, ErrorCode::InvalidInput);
  EXPECT_NE(s.message.find("attribute 'normal' of vertex 1 is not finite"), std::string::npos) << s.message;
}

}  // namespace
}  // namespace kdmesh::test
