// Simplex labels: kept exactly through a round trip, present on every
// prefix, and corrupt label data refused cleanly.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <vector>

#include "complexes.h"
#include "io_test_support.h"
#include "container.h"
#include "crc32.h"
#include "kdmesh/io.h"
#include "kdmesh/kdmesh.h"
#include "labels.h"
#include "mutations.h"
#include "test_support.h"

namespace kdmesh::test {
namespace {

using PositionTuple = std::vector<std::array<uint32_t, 3>>;
using LabelledSimplex = std::pair<PositionTuple, int32_t>;

// The maximal simplices with their labels, vertices named by position and
// sorted: the multiset in which an input and its decoded complex must
// agree. Simplices the encoder drops (degenerate, duplicate, faces of
// other listed ones, highest dimension first) are dropped here too.
std::vector<LabelledSimplex> labelledForm(const Complex& c) {
  std::set<std::vector<uint32_t>> present;
  std::vector<LabelledSimplex> out;
  const bool labelled = !c.labels.empty();
  for (int d = 3; d >= 1; --d) {
    const std::vector<uint32_t>& list = d == 1 ? c.edges : d == 2 ? c.triangles : c.tetrahedra;
    for (size_t i = 0; i < list.size(); i += size_t(d + 1)) {
      std::vector<uint32_t> sorted(list.begin() + std::ptrdiff_t(i), list.begin() + std::ptrdiff_t(i) + d + 1);
      std::sort(sorted.begin(), sorted.end());
      if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) continue;
      if (!present.insert(sorted).second) continue;
      for (int mask = 1; mask < (1 << (d + 1)) - 1; ++mask) {
        std::vector<uint32_t> face;
        for (int b = 0; b <= d; ++b)
          if (mask >> b & 1) face.push_back(sorted[size_t(b)]);
        if (face.size() >= 2) present.insert(face);
      }
      PositionTuple tuple;
      for (const uint32_t v : sorted) tuple.push_back(positionBits(c, v));
      std::sort(tuple.begin(), tuple.end());
      out.push_back({tuple, labelled ? labelOf(c, d, i / size_t(d + 1)) : 0});
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

// Labels by a coordinate: `regions` slabs along x between lo and hi.
int32_t slab(float x, float lo, float hi, int regions) {
  const int r = int((x - lo) / (hi - lo) * float(regions));
  return int32_t(std::clamp(r, 0, regions - 1)) * 7 - 5;  // not 0..n-1: the table maps them
}

void labelBySlabs(Complex& c, int regions) {
  float lo = INFINITY, hi = -INFINITY;
  for (size_t v = 0; v < c.vertexCount(); ++v) {
    lo = std::min(lo, c.positions[3 * v]);
    hi = std::max(hi, c.positions[3 * v]);
  }
  for (int d = 1; d <= 3; ++d) {
    const std::vector<uint32_t>& list = d == 1 ? c.edges : d == 2 ? c.triangles : c.tetrahedra;
    std::vector<int32_t>& labels = c.labels.of(d);
    labels.clear();
    for (size_t i = 0; i < list.size(); i += size_t(d + 1)) {
      float x = 0;
      for (int k = 0; k <= d; ++k) x += c.positions[3 * size_t(list[i + size_t(k)])];
      labels.push_back(slab(x / float(d + 1), lo, hi, regions));
    }
  }
}

// A sphere with `edges` labelled by 3 slabs, the triangles' labels far
// from 0 and negative (-5, 995, 1995): what writers must keep as they are.
Complex sphereInSlabs(int rings, int segments, std::vector<uint32_t> edges) {
  Complex sphere = sphereMesh(rings, segments);
  sphere.edges = std::move(edges);
  labelBySlabs(sphere, 3);
  for (int32_t& label : sphere.labels.triangles) label = label * 1000 - 5;
  return sphere;
}

EncodeOptions exactOptions(size_t chunkBytes = 256) {
  EncodeOptions o;
  o.exact = true;  // positions name the vertices in the comparison
  o.chunkBytes = chunkBytes;
  return o;
}

Complex decodeOrFail(const std::vector<uint8_t>& bytes) {
  Complex out;
  const Status status = decode(bytes.data(), bytes.size(), out);
  EXPECT_TRUE(status.ok()) << status.message;
  return out;
}

// Round trip, then every chunk prefix: one label per listed simplex, each
// the label of an input simplex that projects (or collapses) onto it.
void expectLabelsKept(const Complex& input, const EncodeOptions& options = exactOptions()) {
  const EncodeResult encoded = encode(input, options);
  ASSERT_TRUE(encoded.status.ok()) << encoded.status.message;
  Decoder full;
  ASSERT_TRUE(full.push(encoded.bytes.data(), encoded.bytes.size()).ok());
  ASSERT_TRUE(full.complete());
  EXPECT_EQ(full.header().labelled, !input.labels.empty());
  const Complex final = full.snapshot();
  EXPECT_EQ(labelledForm(final), labelledForm(input));
  if (input.labels.empty()) {
    EXPECT_TRUE(final.labels.empty());
    return;
  }
  EXPECT_GT(encoded.cost.labelBits, 0);
  const std::vector<uint32_t>& parents = full.vertexParents();
  for (const ChunkInfo& chunk : full.chunks()) {
    Decoder decoder;
    ASSERT_TRUE(decoder.push(encoded.bytes.data(), chunk.offset).ok());
    const Complex prefix = decoder.snapshot();
    const uint32_t count = uint32_t(prefix.vertexCount());
    auto ancestor = [&](uint32_t v) {
      while (v >= count) v = parents[v];
      return v;
    };
    // Labels by the projected vertex sets of the complete complex's simplices.
    std::map<std::vector<uint32_t>, std::set<int32_t>> projected;
    for (int d = 1; d <= 3; ++d) {
      const std::vector<uint32_t>& list = d == 1 ? final.edges : d == 2 ? final.triangles : final.tetrahedra;
      for (size_t i = 0; i < list.size(); i += size_t(d + 1)) {
        std::vector<uint32_t> set;
        for (int k = 0; k <= d; ++k) set.push_back(ancestor(list[i + size_t(k)]));
        std::sort(set.begin(), set.end());
        set.erase(std::unique(set.begin(), set.end()), set.end());
        projected[set].insert(final.labels.of(d)[i / size_t(d + 1)]);
      }
    }
    for (int d = 1; d <= 3; ++d) {
      const std::vector<uint32_t>& list = d == 1 ? prefix.edges : d == 2 ? prefix.triangles : prefix.tetrahedra;
      const std::vector<int32_t>& labels = prefix.labels.of(d);
      ASSERT_EQ(labels.size(), list.size() / size_t(d + 1)) << "prefix of " << chunk.offset << " bytes";
      for (size_t i = 0; i < labels.size(); ++i) {
        std::vector<uint32_t> set(list.begin() + std::ptrdiff_t(i * size_t(d + 1)),
                                  list.begin() + std::ptrdiff_t((i + 1) * size_t(d + 1)));
        std::sort(set.begin(), set.end());
        const auto found = projected.find(set);
        ASSERT_NE(found, projected.end());
        EXPECT_TRUE(found->second.count(labels[i])) << "prefix of " << chunk.offset << " bytes, dimension " << d;
      }
    }
  }
}

TEST(Labels, TriangleMeshWithRegions) {
  Complex c = sphereMesh(24, 32);
  labelBySlabs(c, 5);
  expectLabelsKept(c);
}

TEST(Labels, TriangleMeshOnTheGrid) {
  Complex c = torusMesh(30, 40);
  labelBySlabs(c, 8);
  EncodeOptions o;
  o.bits = 12;
  const EncodeResult encoded = encode(c, o);
  ASSERT_TRUE(encoded.status.ok());
  const Complex out = decodeOrFail(encoded.bytes);
  // Grid positions differ from the input's; the label histogram must not.
  std::vector<int32_t> in = c.labels.triangles, decoded = out.labels.triangles;
  std::sort(in.begin(), in.end());
  std::sort(decoded.begin(), decoded.end());
  EXPECT_EQ(in, decoded);
}

TEST(Labels, TetrahedralMeshWithRegions) {
  Complex c = tetrahedralBlock(5, 3);
  labelBySlabs(c, 3);
  expectLabelsKept(c);
}

TEST(Labels, RandomLabelsOnTetrahedra) {
  Complex c = tetrahedralBlock(4, 9);
  std::mt19937 rng(4);
  for (size_t i = 0; i < c.simplexCount(3); ++i) c.labels.tetrahedra.push_back(int32_t(rng() % 5000) - 2500);
  expectLabelsKept(c);
}

TEST(Labels, MixedDimensions) {
  Complex c = tetrahedralBlock(3, 5);
  const uint32_t n = uint32_t(c.vertexCount());
  // A fin of triangles and a tail of edges off the block.
  for (int i = 0; i < 6; ++i) c.positions.insert(c.positions.end(), {-1.f - float(i), 0.5f * float(i), 0.25f});
  c.triangles = {0, n, n + 1, n, n + 1, n + 2, n + 1, n + 2, n + 3};
  c.edges = {n + 3, n + 4, n + 4, n + 5, n + 5, 1};
  labelBySlabs(c, 4);
  c.labels.edges = {-7, 3, 2147483647};
  c.labels.triangles[1] = -2147483647 - 1;
  expectLabelsKept(c);
}

TEST(Labels, UnlabelledListsGetZero) {
  Complex c = tetrahedralBlock(2, 1);
  const uint32_t n = uint32_t(c.vertexCount());
  c.positions.insert(c.positions.end(), {-3.f, 0.f, 0.f});
  c.edges = {0, n};
  c.labels.tetrahedra.assign(c.simplexCount(3), 9);
  const EncodeResult encoded = encode(c, exactOptions());
  ASSERT_TRUE(encoded.status.ok());
  const Complex out = decodeOrFail(encoded.bytes);
  EXPECT_EQ(out.labels.edges, std::vector<int32_t>{0});
  EXPECT_EQ(out.labels.tetrahedra, std::vector<int32_t>(c.simplexCount(3), 9));
}

TEST(Labels, CoincidentVertices) {
  Complex c = sphereMesh(10, 12);
  const size_t n = c.vertexCount();
  // A second sphere on the same positions, with its own labels.
  c.positions.insert(c.positions.end(), c.positions.begin(), c.positions.end());
  const size_t triangles = c.triangles.size();
  for (size_t i = 0; i < triangles; ++i) c.triangles.push_back(c.triangles[i] + uint32_t(n));
  for (size_t i = 0; i < c.simplexCount(2); ++i) c.labels.triangles.push_back(int32_t(i < triangles / 3 ? 1 : 2));
  expectLabelsKept(c);
}

TEST(Labels, Soups) {
  for (uint32_t seed = 0; seed < 30; ++seed) {
    Complex c = randomComplex(seed, 12 + int(seed % 20), 10 + int(seed * 3 % 60));
    std::mt19937 rng(seed);
    for (int d = 1; d <= 3; ++d)
      if (rng() % 4 != 0)
        for (size_t i = 0; i < c.simplexCount(d); ++i) c.labels.of(d).push_back(int32_t(rng() % 6));
    if (c.labels.empty()) c.labels.edges.assign(c.simplexCount(1), 1);
    SCOPED_TRACE(seed);
    expectLabelsKept(c, exactOptions(64));
  }
}

TEST(Labels, OneLabelCodesNothing) {
  Complex c = sphereMesh(12, 16);
  const EncodeResult plain = encode(c, exactOptions());
  c.labels.triangles.assign(c.simplexCount(2), 42);
  const EncodeResult labelled = encode(c, exactOptions());
  ASSERT_TRUE(plain.status.ok() && labelled.status.ok());
  EXPECT_EQ(labelled.cost.labelBits, 0);
  // The label table: count, label, checksum.
  EXPECT_EQ(labelled.bytes.size(), plain.bytes.size() + 1 + 1 + 4);
  EXPECT_EQ(decodeOrFail(labelled.bytes).labels.triangles, c.labels.triangles);
}

TEST(Labels, StreamsWithoutLabelsAreUnchanged) {
  const Complex c = torusMesh(20, 24);
  const EncodeResult encoded = encode(c, exactOptions());
  ASSERT_TRUE(encoded.status.ok());
  EXPECT_EQ(encoded.cost.labelBits, 0);
  Decoder decoder;
  ASSERT_TRUE(decoder.push(encoded.bytes.data(), encoded.bytes.size()).ok());
  EXPECT_FALSE(decoder.header().labelled);
  EXPECT_TRUE(decoder.snapshot().labels.empty());
}

// Decoder::labels() on every byte prefix: empty until the label table's
// last byte (after the header; the sphere has no attribute table), then
// the input's distinct labels, ascending, holding every label a snapshot
// shows; empty again after reset().
TEST(Labels, DecoderGivesTheTableOnceRead) {
  Complex c = sphereMesh(16, 20);
  std::mt19937 rng(7);
  for (size_t i = 0; i < c.simplexCount(2); ++i) c.labels.triangles.push_back(int32_t(rng() % 9) * 1000 - 4000);
  std::vector<int32_t> distinct = c.labels.triangles;
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  ASSERT_GT(distinct.size(), 5u);
  const EncodeResult encoded = encode(c, exactOptions());
  ASSERT_TRUE(encoded.status.ok());
  size_t headerBytes = 0;
  ASSERT_TRUE(headerSize(encoded.bytes.data(), headerBytes).ok());
  std::vector<uint8_t> table;
  writeLabelTable(distinct, table);
  const size_t tableEnd = headerBytes + table.size();
  Decoder decoder;
  for (size_t at = 0; at < encoded.bytes.size(); ++at) {
    if (at < tableEnd) {
      EXPECT_TRUE(decoder.labels().empty()) << "prefix of " << at << " bytes";
    } else {
      ASSERT_EQ(decoder.labels(), distinct) << "prefix of " << at << " bytes";
      for (const int32_t label : decoder.snapshot().labels.triangles)
        EXPECT_TRUE(std::binary_search(distinct.begin(), distinct.end(), label)) << label;
    }
    ASSERT_TRUE(decoder.push(&encoded.bytes[at], 1).ok());
  }
  ASSERT_TRUE(decoder.complete());
  EXPECT_EQ(decoder.labels(), distinct);
  decoder.reset();
  EXPECT_TRUE(decoder.labels().empty());
}

TEST(Labels, DecoderGivesNoTableWithoutLabels) {
  const EncodeResult encoded = encode(torusMesh(12, 16), exactOptions());
  ASSERT_TRUE(encoded.status.ok());
  Decoder decoder;
  ASSERT_TRUE(decoder.push(encoded.bytes.data(), encoded.bytes.size()).ok());
  ASSERT_TRUE(decoder.complete());
  EXPECT_TRUE(decoder.labels().empty());
}

TEST(Labels, EncoderRefusesMismatchedCounts) {
  Complex c = sphereMesh(6, 8);
  c.labels.triangles.assign(c.simplexCount(2) - 1, 1);
  EncodeResult r = encode(c);
  EXPECT_EQ(r.status.code, ErrorCode::InvalidInput);
  EXPECT_NE(r.status.message.find("triangle labels"), std::string::npos) << r.status.message;
  c.labels.triangles.clear();
  c.labels.edges = {1};  // no edges listed
  r = encode(c);
  EXPECT_EQ(r.status.code, ErrorCode::InvalidInput);
}

// A labelled stream with its label table replaced by `table` (raw bytes
// before the checksum, which is recomputed unless `badChecksum`), and the
// header's body size updated.
std::vector<uint8_t> withLabelTable(const std::vector<uint8_t>& stream, const std::vector<uint8_t>& table,
                                    bool badChecksum = false) {
  Header header;
  size_t headerBytes = 0;
  EXPECT_TRUE(headerSize(stream.data(), headerBytes).ok());
  EXPECT_TRUE(readHeader(stream.data(), headerBytes, DecoderLimits{}, header).ok());
  EXPECT_TRUE(header.labelled && header.attributeCount == 0);
  // The honest table's extent.
  std::vector<int32_t> honest;
  size_t tableBytes = 0;
  Status error;
  EXPECT_EQ(readLabelTable(stream.data() + headerBytes, stream.size() - headerBytes, 1u << 30, honest, tableBytes,
                           error),
            Parsed::Complete);
  std::vector<uint8_t> body(table);
  const uint32_t crc = crc32(table.data(), table.size()) ^ (badChecksum ? 1u : 0u);
  for (int i = 0; i < 4; ++i) body.push_back(uint8_t(crc >> (8 * i)));
  body.insert(body.end(), stream.begin() + std::ptrdiff_t(headerBytes + tableBytes), stream.end());
  header.bodyBytes = body.size();
  std::vector<uint8_t> out(kMaxHeaderBytes);
  out.resize(writeHeader(header, out.data()));
  out.insert(out.end(), body.begin(), body.end());
  return out;
}

ErrorCode decodeError(const std::vector<uint8_t>& bytes, std::string* message = nullptr) {
  Complex out;
  const Status status = decode(bytes.data(), bytes.size(), out);
  if (message) *message = status.message;
  return status.code;
}

TEST(Labels, CorruptTablesAreRefused) {
  Complex c = sphereMesh(8, 10);
  labelBySlabs(c, 4);  // labels -5, 2, 9, 16: zigzag 9, then deltas 6, 6, 6
  const EncodeResult encoded = encode(c, exactOptions());
  ASSERT_TRUE(encoded.status.ok());
  ASSERT_EQ(decodeError(withLabelTable(encoded.bytes, {4, 9, 6, 6, 6})), ErrorCode::Ok);
  std::string message;
  EXPECT_EQ(decodeError(withLabelTable(encoded.bytes, {4, 9, 6, 6, 6}, true), &message), ErrorCode::CorruptHeader);
  EXPECT_NE(message.find("label table"), std::string::npos) << message;
  EXPECT_EQ(decodeError(withLabelTable(encoded.bytes, {0})), ErrorCode::CorruptHeader);  // no labels
  // More labels than simplices.
  EXPECT_EQ(decodeError(withLabelTable(encoded.bytes, {0xff, 0xff, 0xff, 0xff, 0x0f, 9})), ErrorCode::CorruptHeader);
  // Beyond int32: 2^31 - 1, then one more.
  EXPECT_EQ(decodeError(withLabelTable(encoded.bytes, {4, 0xfe, 0xff, 0xff, 0xff, 0x0f, 0, 0, 0})),
            ErrorCode::CorruptHeader);
  // A varint longer than five bytes.
  EXPECT_EQ(decodeError(withLabelTable(encoded.bytes, {4, 0x80, 0x80, 0x80, 0x80, 0x80, 0x01, 6, 6, 6})),
            ErrorCode::CorruptHeader);
}

TEST(Labels, IndexBeyondTheTableIsCorrupt) {
  Complex c = sphereMesh(10, 12);
  labelBySlabs(c, 4);
  const EncodeResult encoded = encode(c, exactOptions());
  ASSERT_TRUE(encoded.status.ok());
  // Three labels code their indices in two bits like four: index 3 has no label.
  std::string message;
  const std::vector<uint8_t> corrupt = withLabelTable(encoded.bytes, {3, 9, 6, 6});
  EXPECT_EQ(decodeError(corrupt, &message), ErrorCode::CorruptChunk);
  EXPECT_FALSE(message.empty());
  // The model as far as it got stays readable, a label per simplex.
  Decoder decoder;
  EXPECT_EQ(decoder.push(corrupt.data(), corrupt.size()).code, ErrorCode::CorruptChunk);
  const Complex partial = decoder.snapshot();
  EXPECT_EQ(partial.labels.triangles.size(), partial.triangles.size() / 3);
}

// Header fields, chunk order and payload bytes of a labelled stream changed
// (checksums made valid again): clean errors, or a complex with one label
// per simplex.
TEST(Labels, MutatedLabelledStreamsFailCleanly) {
  Complex c = tetrahedralBlock(3, 8);
  labelBySlabs(c, 5);
  EncodeOptions o;
  o.bits = 10;
  o.chunkBytes = 256;
  const std::vector<MutatedStream> streams = mutatedStreams(encodeOrDie(c, o), 300, 31);
  ASSERT_EQ(streams.size(), 300u);
  int failed = 0;
  for (size_t trial = 0; trial < streams.size(); ++trial) {
    Complex out;
    const Status s = decode(streams[trial].bytes.data(), streams[trial].bytes.size(), out);
    if (s.ok()) {
      for (int d = 1; d <= 3; ++d) EXPECT_EQ(out.labels.of(d).size(), out.simplexCount(d)) << trial;
      continue;
    }
    ++failed;
    EXPECT_TRUE(s.code == ErrorCode::CorruptHeader || s.code == ErrorCode::CorruptChunk ||
                s.code == ErrorCode::LimitExceeded || s.code == ErrorCode::TrailingBytes ||
                s.code == ErrorCode::Truncated)
        << trial << " (" << streams[trial].kind << "): " << errorCodeName(s.code) << " " << s.message;
  }
  EXPECT_GT(failed, 0);
}

TEST(Labels, TruncatedTableIsIncomplete) {
  Complex c = sphereMesh(8, 10);
  labelBySlabs(c, 4);
  const EncodeResult encoded = encode(c, exactOptions());
  ASSERT_TRUE(encoded.status.ok());
  size_t headerBytes = 0;
  ASSERT_TRUE(headerSize(encoded.bytes.data(), headerBytes).ok());
  for (size_t cut = headerBytes; cut < headerBytes + 9; ++cut) {
    Decoder decoder;
    ASSERT_TRUE(decoder.push(encoded.bytes.data(), cut).ok());
    EXPECT_EQ(decoder.finish().code, ErrorCode::Truncated);
    EXPECT_TRUE(decoder.snapshot().labels.empty());
  }
}

Complex readText(io::Format format, const std::string& text, io::Notes& notes) {
  Complex out;
  const Status status =
      io::readMemory(format, reinterpret_cast<const uint8_t*>(text.data()), text.size(), out, notes);
  EXPECT_TRUE(status.ok()) << status.message;
  return out;
}

std::string joined(const io::Notes& notes) {
  std::string all;
  for (const std::string& note : notes) all += note + "\n";
  return all;
}

TEST(LabelFiles, PlyFaceProperty) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 2\nproperty list uchar int vertex_indices\nproperty short material_index\n"
      "property float quality\nend_header\n"
      "0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 0\n"
      "4 0 1 2 3 -3 0.5\n3 1 4 2 7 0.25\n";
  io::Notes notes;
  const Complex c = readText(io::Format::Ply, ply, notes);
  EXPECT_EQ(c.labels.triangles, (std::vector<int32_t>{-3, -3, 7}));  // the quadrilateral's two triangles
  EXPECT_NE(joined(notes).find("quality"), std::string::npos) << joined(notes);
  EXPECT_EQ(joined(notes).find("material_index"), std::string::npos) << joined(notes);
  for (const bool ascii : {true, false}) {
    std::vector<uint8_t> bytes;
    io::WriteOptions options;
    options.asciiPly = ascii;
    ASSERT_TRUE(io::writeMemory(io::Format::Ply, c, bytes, options).ok());
    io::Notes again;
    Complex back;
    ASSERT_TRUE(io::readMemory(io::Format::Ply, bytes.data(), bytes.size(), back, again).ok());
    EXPECT_EQ(back.labels.triangles, c.labels.triangles);
    EXPECT_EQ(back.triangles, c.triangles);
  }
}

TEST(LabelFiles, PlyLabelsOfEveryDimension) {
  Complex c = tetrahedralBlock(1, 2);
  const uint32_t n = uint32_t(c.vertexCount());
  c.positions.insert(c.positions.end(), {5.f, 5.f, 5.f, 6.f, 5.f, 5.f});
  c.triangles = {n, n + 1, 0};
  c.edges = {n + 1, 1};
  labelBySlabs(c, 3);
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(io::writeMemory(io::Format::Ply, c, bytes).ok());
  io::Notes notes;
  Complex back;
  ASSERT_TRUE(io::readMemory(io::Format::Ply, bytes.data(), bytes.size(), back, notes).ok());
  EXPECT_EQ(back.labels.edges, c.labels.edges);
  EXPECT_EQ(back.labels.triangles, c.labels.triangles);
  EXPECT_EQ(back.labels.tetrahedra, c.labels.tetrahedra);
}

TEST(LabelFiles, MeditReferences) {
  const std::string mesh =
      "MeshVersionFormatted 1\nDimension 3\nVertices\n6\n"
      "0 0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n1 1 1 0\n3 3 3 0\n"
      "Tetrahedra\n2\n1 2 3 4 5\n2 3 4 5 6\n"
      "Triangles\n2\n1 2 3 9\n4 5 6 8\n"  // the first is a face of a tetrahedron
      "Edges\n1\n1 6 2\nEnd\n";
  io::Notes notes;
  const Complex c = readText(io::Format::Medit, mesh, notes);
  EXPECT_EQ(c.labels.tetrahedra, (std::vector<int32_t>{5, 6}));
  EXPECT_EQ(c.labels.triangles, (std::vector<int32_t>{9, 8}));
  EXPECT_EQ(c.labels.edges, (std::vector<int32_t>{2}));
  // The vertex references are the attribute ref.
  ASSERT_EQ(c.attributes.size(), 1u);
  EXPECT_EQ(c.attributes[0].name, "ref");
  EXPECT_EQ(c.attributes[0].values, (std::vector<uint8_t>{1, 0, 0, 0, 0, 0}));
  EXPECT_NE(joined(notes).find("dropped the nonzero references of 1 edge or triangle that is a face"),
            std::string::npos)
      << joined(notes);
  // Through the codec: the face's reference goes, the others stay.
  const EncodeResult encoded = encode(c, exactOptions());
  ASSERT_TRUE(encoded.status.ok());
  const Complex decoded = decodeOrFail(encoded.bytes);
  EXPECT_EQ(labelledForm(decoded), labelledForm(c));
  EXPECT_EQ(decoded.labels.triangles, std::vector<int32_t>{8});
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(io::writeMemory(io::Format::Medit, decoded, bytes).ok());
  io::Notes again;
  Complex back;
  ASSERT_TRUE(io::readMemory(io::Format::Medit, bytes.data(), bytes.size(), back, again).ok());
  EXPECT_EQ(labelledForm(back), labelledForm(decoded));
}

TEST(LabelFiles, MeditZeroReferencesAreNoLabels) {
  const std::string mesh =
      "MeshVersionFormatted 1\nDimension 3\nVertices\n3\n0 0 0 0\n1 0 0 0\n0 1 0 0\n"
      "Triangles\n1\n1 2 3 0\nEnd\n";
  io::Notes notes;
  EXPECT_TRUE(readText(io::Format::Medit, mesh, notes).labels.empty());
}

TEST(LabelFiles, TetgenRegionAttribute) {
  Complex c = tetrahedralBlock(2, 6);
  labelBySlabs(c, 3);
  const std::string dir = ::testing::TempDir();
  ASSERT_TRUE(io::writeFile(dir + "/labels_region.node", c).ok());
  io::Notes notes;
  Complex back;
  ASSERT_TRUE(io::readFile(dir + "/labels_region.node", back, notes).ok());
  EXPECT_EQ(back.labels.tetrahedra, c.labels.tetrahedra);
  EXPECT_EQ(joined(notes).find("region"), std::string::npos) << joined(notes);
}

// OBJ materials (usemtl) label lines and faces, those before any usemtl
// counting as one more; the writer names materials by the labels.
TEST(LabelFiles, ObjMaterials) {
  const std::string obj =
      "mtllib scene.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\n"
      "f 1 2 3\nusemtl red paint\nf 1 3 4 5\nl 1 5 2\nusemtl blue\nf 2 5 3\nusemtl red paint\nf 1 2 5\n";
  io::Notes notes;
  const Complex c = readText(io::Format::Obj, obj, notes);
  // Faces before any usemtl are material 0; the quadrilateral is two triangles.
  EXPECT_EQ(c.labels.triangles, (std::vector<int32_t>{0, 1, 1, 2, 1}));
  EXPECT_EQ(c.labels.edges, (std::vector<int32_t>{1, 1}));
  EXPECT_NE(joined(notes).find("0 (none), 1 'red paint', 2 'blue'"), std::string::npos) << joined(notes);
  EXPECT_NE(joined(notes).find("1 material library (mtllib)"), std::string::npos) << joined(notes);
  EXPECT_EQ(joined(notes).find("material use"), std::string::npos) << joined(notes);

  const Complex sphere = sphereInSlabs(5, 6, {0, 1, 1, 2});
  const ReadResult back = writeThenRead(io::Format::Obj, sphere);
  ASSERT_TRUE(back.status.ok()) << back.status.message;
  EXPECT_TRUE(back.notes.empty()) << joined(back.notes);
  EXPECT_EQ(back.complex.triangles, sphere.triangles);
  EXPECT_EQ(back.complex.labels.triangles, sphere.labels.triangles);
  EXPECT_EQ(back.complex.labels.edges, sphere.labels.edges);
}

// Materials, or groups in a file without materials, name the labels: in
// order of first use, or as their values when all names are integers.
TEST(LabelFiles, ObjMaterialsOrGroupsAreLabels) {
  for (const auto& [keyword, kind] : {std::pair{"usemtl", "materials (usemtl)"}, std::pair{"g", "groups (g)"}}) {
    SCOPED_TRACE(keyword);
    const std::string k = keyword;
    io::Notes notes;
    const Complex c = readText(io::Format::Obj,
                               "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\n" + k + " wing\nf 1 2 3\n" + k +
                                   " body part\nf 1 3 4 5\nl 1 5 2\n" + k + " wing\nf 2 5 3\n",
                               notes);
    EXPECT_EQ(c.labels.triangles, (std::vector<int32_t>{0, 1, 1, 0}));
    EXPECT_EQ(c.labels.edges, (std::vector<int32_t>{1, 1}));
    EXPECT_NE(joined(notes).find("kept the 2 " + std::string(kind) +
                                 " of lines and faces as simplex labels, numbered in order of first use: 0 'wing', "
                                 "1 'body part'"),
              std::string::npos)
        << joined(notes);
    const Complex integers =
        readText(io::Format::Obj, "v 0 0 0\nv 1 0 0\nv 1 1 0\n" + k + " -7\nf 1 2 3\n" + k + " 40\nl 1 2\n", notes);
    EXPECT_EQ(integers.labels.triangles, (std::vector<int32_t>{-7}));
    EXPECT_EQ(integers.labels.edges, (std::vector<int32_t>{40}));
  }
}

TEST(LabelFiles, VtkCellDataLabelsRoundTrip) {
  Complex sphere = sphereInSlabs(8, 10, {0, 1, 2, 3});
  sphere.labels.edges = {-7, 70000};
  sphere.points = {4};
  const ReadResult back = writeThenRead(io::Format::Vtk, sphere);
  ASSERT_TRUE(back.status.ok()) << back.status.message;
  ASSERT_EQ(back.notes.size(), 1u) << joined(back.notes);
  EXPECT_EQ(back.notes[0], "kept the cell data array 'label' as simplex labels");
  EXPECT_EQ(back.complex.triangles, sphere.triangles);
  EXPECT_EQ(back.complex.edges, sphere.edges);
  EXPECT_EQ(back.complex.labels.triangles, sphere.labels.triangles);
  EXPECT_EQ(back.complex.labels.edges, sphere.labels.edges);
}

TEST(LabelFiles, FormatsWithoutLabelsRefuse) {
  Complex c = sphereMesh(5, 6);
  labelBySlabs(c, 2);
  std::vector<uint8_t> bytes;
  const Status status = io::writeMemory(io::Format::Off, c, bytes);
  EXPECT_EQ(status.code, ErrorCode::InvalidArgument);
  EXPECT_NE(status.message.find("labels"), std::string::npos) << status.message;
}

}  // namespace
}  // namespace kdmesh::test
