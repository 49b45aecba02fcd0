// Files read in pieces, and welding. A file that a reader streams (binary
// STL and PLY) or reads from its first block on (the kind checks, headers)
// must give exactly what the same bytes give from memory: across block
// boundaries, past the first block, and through a pipe, which has no size.
// Welding is compared with a plain reference on many repeated positions.
#include <gtest/gtest.h>

#include <pthread.h>
#include <signal.h>
#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "io/io_internal.h"
#include "io_test_support.h"
#include "kdmesh/io.h"

namespace kdmesh::test {
namespace {

namespace fs = std::filesystem;
using io::Format;

void expectSameRead(const ReadResult& actual, const ReadResult& expected) {
  ASSERT_EQ(actual.status.ok(), expected.status.ok()) << actual.status.message;
  EXPECT_EQ(actual.status.message, expected.status.message);
  EXPECT_EQ(bitsOf(actual.complex.positions), bitsOf(expected.complex.positions));
  EXPECT_EQ(actual.complex.points, expected.complex.points);
  EXPECT_EQ(actual.complex.edges, expected.complex.edges);
  EXPECT_EQ(actual.complex.triangles, expected.complex.triangles);
  EXPECT_EQ(actual.complex.tetrahedra, expected.complex.tetrahedra);
  EXPECT_EQ(actual.notes, expected.notes);
}

// `bytes` written to `name` and read by readFile give what readMemory gives,
// which must be a success.
void expectFileReadsAsMemory(const std::string& name, const std::vector<uint8_t>& bytes,
                             bool weld = false) {
  SCOPED_TRACE(name + (weld ? " welded" : ""));
  TempDir dir;
  writeWhole(dir / name, bytes);
  const ReadResult memory = readBytes(io::formatFromPath(name), bytes, weld);
  ASSERT_TRUE(memory.status.ok()) << memory.status.message;
  expectSameRead(readPath(dir / name, weld), memory);
}

void put32(std::vector<uint8_t>& bytes, uint32_t value, bool bigEndian = false) {
  for (int i = 0; i < 4; ++i) bytes.push_back(uint8_t(value >> (8 * (bigEndian ? 3 - i : i))));
}

// Positions of `count` vertices, many of them repeated: drawn from `distinct`
// positions that include both zeros, NaNs with different payloads and
// denormals, so that welding must compare bits.
std::vector<float> repeatedPositions(size_t count, size_t distinct, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<float> pool = {0.0f, -0.0f, floatOf(0x7fc00001), floatOf(0x7fc00002),
                             floatOf(1), floatOf(0x80000001), 1.0f, -1.0f, 0.5f};
  while (pool.size() < 3 * distinct) pool.push_back(floatOf(uint32_t(rng())));
  pool.resize(3 * distinct);
  std::vector<float> positions;
  positions.reserve(3 * count);
  for (size_t v = 0; v < count; ++v) {
    const size_t p = rng() % distinct;
    positions.insert(positions.end(), &pool[3 * p], &pool[3 * p] + 3);
  }
  return positions;
}

// A binary STL of `triangles` triangles whose corners repeat (so welding
// merges some), with an attribute on every seventh.
std::vector<uint8_t> randomBinaryStl(size_t triangles, uint32_t seed) {
  const std::vector<float> corners = repeatedPositions(3 * triangles, triangles, seed);
  std::vector<uint8_t> bytes(80, 'x');
  put32(bytes, uint32_t(triangles));
  for (size_t t = 0; t < triangles; ++t) {
    for (int k = 0; k < 3; ++k) put32(bytes, bitsOf(0.0f));
    for (int k = 0; k < 9; ++k) put32(bytes, bitsOf(corners[9 * t + k]));
    bytes.push_back(t % 7 == 0 ? 1 : 0);
    bytes.push_back(0);
  }
  return bytes;
}

// ---------------------------------------------------------------------------
// STL
// ---------------------------------------------------------------------------

TEST(IoStreaming, BinaryStlAcrossBlocksReadsAsFromMemory) {
  // 50,000 triangles: 2.5 MB, so that triangles straddle the 1 MiB blocks.
  std::vector<uint8_t> bytes = randomBinaryStl(50000, 3);
  ASSERT_GT(bytes.size(), 2 * io::detail::ByteStream::kBlockBytes);
  expectFileReadsAsMemory("soup.stl", bytes);
  expectFileReadsAsMemory("soup.stl", bytes, /*weld=*/true);
  bytes.insert(bytes.end(), 3000000, 0x5a);  // bytes after the triangles
  expectFileReadsAsMemory("trailing.stl", bytes);
}

TEST(IoStreaming, AsciiStlLongerThanTheFirstBlockReadsAsFromMemory) {
  std::string text = "solid big\n";
  const std::vector<float> corners = repeatedPositions(3 * 5000, 4000, 4);
  for (size_t t = 0; t < 5000; ++t) {
    text += "facet normal 0 0 1\nouter loop\n";
    for (int k = 0; k < 3; ++k) {
      text += "vertex " + std::to_string(corners[9 * t + 3 * k]) + " " +
              std::to_string(corners[9 * t + 3 * k + 1]) + " " +
              std::to_string(corners[9 * t + 3 * k + 2]) + "\n";
    }
    text += "endloop\nendfacet\n";
  }
  text += "endsolid big\n";
  ASSERT_GT(text.size(), 4 * io::detail::Input::kHeadBytes);
  expectFileReadsAsMemory("text.stl", bytesOf(text));
  expectFileReadsAsMemory("text.stl", bytesOf(text), /*weld=*/true);
}

// ---------------------------------------------------------------------------
// PLY
// ---------------------------------------------------------------------------

// A binary PLY whose vertices carry a list property that the reader skips:
// short lists, and every 1000th vertex a list longer than a block, so that
// skipping must move past the block held.
std::vector<uint8_t> binaryPlyWithSkippedLists(bool bigEndian, const std::string& comments) {
  const size_t vertices = 20000, faces = 30000;
  const std::string header = std::string("ply\nformat ") +
                             (bigEndian ? "binary_big_endian" : "binary_little_endian") +
                             " 1.0\n" + comments + "element vertex " + std::to_string(vertices) +
                             "\nproperty float x\nproperty float y\nproperty float z\n"
                             "property list uint float extra\nelement face " +
                             std::to_string(faces) +
                             "\nproperty list uchar int vertex_indices\nend_header\n";
  std::vector<uint8_t> bytes(header.begin(), header.end());
  std::mt19937 rng(5);
  const std::vector<float> positions = repeatedPositions(vertices, vertices / 2, 6);
  for (size_t v = 0; v < vertices; ++v) {
    for (int k = 0; k < 3; ++k) put32(bytes, bitsOf(positions[3 * v + k]), bigEndian);
    const uint32_t length = v % 1000 == 999 ? 300000 : rng() % 4;
    put32(bytes, length, bigEndian);
    bytes.insert(bytes.end(), 4 * size_t{length}, 0x3f);
  }
  for (size_t f = 0; f < faces; ++f) {
    const uint8_t corners = f % 5 == 0 ? 4 : 3;
    bytes.push_back(corners);
    for (uint8_t k = 0; k < corners; ++k) put32(bytes, uint32_t(rng() % vertices), bigEndian);
  }
  return bytes;
}

TEST(IoStreaming, BinaryPlyAcrossBlocksReadsAsFromMemory) {
  for (bool bigEndian : {false, true}) {
    const std::vector<uint8_t> bytes = binaryPlyWithSkippedLists(bigEndian, "");
    ASSERT_GT(bytes.size(), 20 * io::detail::ByteStream::kBlockBytes);
    expectFileReadsAsMemory("lists.ply", bytes);
    expectFileReadsAsMemory("lists.ply", bytes, /*weld=*/true);
  }
}

TEST(IoStreaming, PlyHeadersPastTheFirstBlockAreReadWhole) {
  const size_t head = io::detail::Input::kHeadBytes;
  // Comments running past the first block, and comments that end so that
  // the end_header line straddles its end.
  std::string longComments;
  while (longComments.size() < head + 1000) longComments += "comment a header that runs on\n";
  const std::string prefix =
      "ply\nformat binary_little_endian 1.0\n";  // as binaryPlyWithSkippedLists writes it
  std::string straddling = "comment " + std::string(head - prefix.size() - 200, 'c') + "\n";
  const std::vector<uint8_t> probe = binaryPlyWithSkippedLists(false, straddling);
  const size_t endHeader = std::string(probe.begin(), probe.begin() + head + 100).find("end_header");
  ASSERT_NE(endHeader, std::string::npos);
  straddling.insert(8, head - 4 - endHeader, 'c');  // "end_" within the block, "header" past it
  for (const std::string& comments : {longComments, straddling}) {
    const std::vector<uint8_t> bytes = binaryPlyWithSkippedLists(false, comments);
    const size_t at = std::string(bytes.begin(), bytes.begin() + 2 * head).find("end_header");
    ASSERT_GT(at + 10, head);
    expectFileReadsAsMemory("comments.ply", bytes);
  }
}

// ---------------------------------------------------------------------------
// Pipes and blank files
// ---------------------------------------------------------------------------

// Reads `bytes` through a named pipe called `name`, written by another
// thread: a file without a size, read whole.
ReadResult readThroughPipe(const std::string& name, const std::vector<uint8_t>& bytes) {
  TempDir dir;
  const fs::path path = dir / name;
  EXPECT_EQ(mkfifo(path.c_str(), 0600), 0) << std::strerror(errno);
  std::thread writer([&path, &bytes] {
    // A reader that stops early closes the pipe: the write fails with EPIPE
    // rather than raising SIGPIPE in the test.
    sigset_t pipeSignal;
    sigemptyset(&pipeSignal);
    sigaddset(&pipeSignal, SIGPIPE);
    pthread_sigmask(SIG_BLOCK, &pipeSignal, nullptr);
    std::FILE* pipe = std::fopen(path.c_str(), "wb");
    if (pipe == nullptr) return;
    std::fwrite(bytes.data(), 1, bytes.size(), pipe);
    std::fclose(pipe);
  });
  ReadResult result = readPath(path);
  writer.join();
  return result;
}

TEST(IoStreaming, PipesAreReadWhole) {
  const std::vector<uint8_t> stl = randomBinaryStl(30000, 7);
  expectSameRead(readThroughPipe("pipe.stl", stl), readBytes(Format::Stl, stl));
  const std::vector<uint8_t> ply = binaryPlyWithSkippedLists(true, "");
  expectSameRead(readThroughPipe("pipe.ply", ply), readBytes(Format::Ply, ply));
  // A file of another kind is refused on its first block.
  std::vector<uint8_t> other = bytesOf("solid not a PLY\n");
  other.resize(3 * io::detail::Input::kHeadBytes, 'x');
  const ReadResult refused = readThroughPipe("other.ply", other);
  EXPECT_NE(refused.status.message.find("not a PLY file"), std::string::npos)
      << refused.status.message;
}

TEST(IoStreaming, BlanksPastTheFirstBlock) {
  const size_t head = io::detail::Input::kHeadBytes;
  std::string blank;
  while (blank.size() < 2 * head) blank += "  \t \r\n";
  TempDir dir;
  writeWhole(dir / "blank.obj", blank);
  expectFailure(readPath(dir / "blank.obj"), {"empty"});
  expectFailure(readText(Format::Obj, blank), {"empty"});
  writeWhole(dir / "late.obj", blank + "v 1 2 3\n");
  const ReadResult late = readPath(dir / "late.obj");
  ASSERT_TRUE(late.status.ok()) << late.status.message;
  EXPECT_EQ(late.complex.vertexCount(), 1u);
}

// ---------------------------------------------------------------------------
// Welding
// ---------------------------------------------------------------------------

// Welding by a map from position bits to the first vertex that has them.
Complex referenceWeld(const Complex& in, size_t& dropped) {
  Complex out;
  std::map<std::array<uint32_t, 3>, uint32_t> first;
  std::vector<uint32_t> newIndex(in.vertexCount());
  for (size_t v = 0; v < in.vertexCount(); ++v) {
    std::array<uint32_t, 3> bits;
    std::memcpy(bits.data(), &in.positions[3 * v], sizeof bits);
    const auto [it, added] = first.emplace(bits, uint32_t(out.vertexCount()));
    if (added) out.positions.insert(out.positions.end(), &in.positions[3 * v], &in.positions[3 * v] + 3);
    newIndex[v] = it->second;
  }
  dropped = 0;
  auto remap = [&](const std::vector<uint32_t>& from, size_t arity, std::vector<uint32_t>& to) {
    for (size_t i = 0; i < from.size(); i += arity) {
      std::vector<uint32_t> simplex;
      for (size_t k = 0; k < arity; ++k) simplex.push_back(newIndex[from[i + k]]);
      std::vector<uint32_t> sorted = simplex;
      std::sort(sorted.begin(), sorted.end());
      if (arity > 1 && std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) {
        ++dropped;
        continue;
      }
      to.insert(to.end(), simplex.begin(), simplex.end());
    }
  };
  remap(in.points, 1, out.points);
  remap(in.edges, 2, out.edges);
  remap(in.triangles, 3, out.triangles);
  remap(in.tetrahedra, 4, out.tetrahedra);
  return out;
}

TEST(IoWeld, MatchesAReferenceOnManyRepeatedPositions) {
  Complex c;
  c.positions = repeatedPositions(200000, 30000, 8);
  std::mt19937 rng(9);
  const auto vertex = [&rng] { return uint32_t(rng() % 200000); };
  for (int i = 0; i < 1000; ++i) c.points.push_back(vertex());
  for (int i = 0; i < 2 * 20000; ++i) c.edges.push_back(vertex());
  for (int i = 0; i < 3 * 60000; ++i) c.triangles.push_back(vertex());
  for (int i = 0; i < 4 * 20000; ++i) c.tetrahedra.push_back(vertex());
  size_t dropped = 0;
  const Complex expected = referenceWeld(c, dropped);
  ASSERT_GT(dropped, 0u);
  io::Notes notes;
  io::detail::weldVertices(c, notes);
  EXPECT_EQ(bitsOf(c.positions), bitsOf(expected.positions));
  EXPECT_EQ(c.points, expected.points);
  EXPECT_EQ(c.edges, expected.edges);
  EXPECT_EQ(c.triangles, expected.triangles);
  EXPECT_EQ(c.tetrahedra, expected.tetrahedra);
  const std::string counts =
      "(200000 -> " + std::to_string(expected.vertexCount()) + " vertices)";
  ReadResult result;
  result.notes = notes;
  EXPECT_TRUE(result.hasNote(counts)) << joined(notes);
  EXPECT_TRUE(result.hasNote("dropped " + std::to_string(dropped) + " simplices")) << joined(notes);
}

// Positions that differ only in a few bits, high or low, of one coordinate:
// patterns that make simple hashes collide. Each of 2,000,000 is distinct.
TEST(IoWeld, StructuredPositionsWeldInLinearTime) {
  std::vector<float> positions;
  for (uint32_t i = 0; i < 1000000; ++i) {
    for (uint32_t bits : {i, i << 11 | 0x80000000u}) {  // the sign keeps the two apart
      positions.insert(positions.end(), {floatOf(bits), 1.0f, floatOf(bits)});
    }
  }
  const auto start = std::chrono::steady_clock::now();
  std::vector<float> welded;
  io::detail::Welder welder(welded);
  for (size_t v = 0; v < positions.size() / 3; ++v) {
    ASSERT_EQ(welder.vertexAt(&positions[3 * v]), uint32_t(v));
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(welded.size(), positions.size());
  EXPECT_LT(seconds, 10.0) << "quadratic probing?";
}

}  // namespace
}  // namespace kdmesh::test
