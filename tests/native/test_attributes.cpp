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
