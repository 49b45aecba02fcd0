// kdmesh::io formats beyond PLY/OBJ/OFF/XYZ: STL (read only), Medit .mesh,
// TetGen .node/.ele and legacy VTK. Round trips keep every float32 bit and the
// vertex order of every simplex; hand-written files cover the variants met in
// practice (CRLF, comments, wrapped values, skipped sections); bad input
// fails cleanly with a message naming the place. Every fixture is made here.
#include <gtest/gtest.h>

#include <array>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "io_test_support.h"
#include "kdmesh/io.h"

namespace kdmesh::test {
namespace {

namespace fs = std::filesystem;
using io::Format;

// Every prefix of `full` either reads (with valid indices) or fails with a
// one-line InvalidInput error and an empty complex; none crashes.
void expectPrefixesReadOrFailCleanly(Format format, const std::vector<uint8_t>& full,
                                     bool everyPrefixFails) {
  for (size_t length = 0; length < full.size(); ++length) {
    const std::vector<uint8_t> prefix(full.begin(), full.begin() + length);
    const ReadResult r = readBytes(format, prefix);
    if (r.status.ok()) {
      EXPECT_FALSE(everyPrefixFails) << "length " << length;
      expectValidIndices(r.complex);
    } else {
      ASSERT_EQ(r.status.code, ErrorCode::InvalidInput) << "length " << length;
      ASSERT_FALSE(r.status.message.empty());
      ASSERT_EQ(r.status.message.find('\n'), std::string::npos) << r.status.message;
      ASSERT_EQ(r.complex.vertexCount(), 0u);
    }
  }
}

// Every byte of `full` replaced by a few values (a digit, a minus, a
// separator, a line end, 0x00, 0xff): each result reads with valid indices
// or fails cleanly.
void expectCorruptionsReadOrFailCleanly(Format format, const std::vector<uint8_t>& full) {
  for (size_t i = 0; i < full.size(); ++i) {
    for (uint8_t value : {0x00, 0x0a, 0x20, 0x2d, 0x39, 0xff}) {
      std::vector<uint8_t> bytes = full;
      bytes[i] = value;
      const ReadResult r = readBytes(format, bytes);
      if (r.status.ok()) {
        expectValidIndices(r.complex);
      } else {
        ASSERT_FALSE(r.status.message.empty());
        ASSERT_EQ(r.status.message.find('\n'), std::string::npos) << r.status.message;
        ASSERT_EQ(r.complex.vertexCount(), 0u);
      }
    }
  }
}

// Every prefix and corruption of the file written for `complex` reads or
// fails with a clear error.
void expectDamagedCopiesReadOrFailCleanly(Format format, const Complex& complex) {
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(io::writeMemory(format, complex, bytes).ok());
  expectPrefixesReadOrFailCleanly(format, bytes, false);
  expectCorruptionsReadOrFailCleanly(format, bytes);
}

// Floats that text formats get wrong when they print too few digits, parse
// via double, or drop the sign of zero, plus random bit patterns.
std::vector<float> awkwardPositions(size_t vertices) {
  std::vector<float> p = {0.0f,   -0.0f,    1.0f,       0.1f,       1.0f / 3.0f,
                          FLT_MAX, -FLT_MAX, FLT_MIN,    floatOf(1), floatOf(0x807fffff),
                          1e-30f, 16777215.0f, 0.123456791f, 3.14159274f, 8388607.5f};
  std::mt19937 rng(99);
  while (p.size() < 3 * vertices) {
    const float f = floatOf(static_cast<uint32_t>(rng()));
    if (!std::isnan(f)) p.push_back(f);
  }
  p.resize(3 * vertices);
  return p;
}

// Edges, triangles and tetrahedra over 12 vertices, in orientations that a
// sorting writer would change; vertex 11 is isolated.
Complex mixedComplex() {
  Complex c;
  c.positions = awkwardPositions(12);
  c.edges = {9, 10, 10, 8};
  c.triangles = {2, 1, 0, 5, 7, 6, 0, 3, 1};
  c.tetrahedra = {4, 3, 2, 1, 8, 5, 6, 7};
  return c;
}

Complex tetrahedralComplex() {
  Complex c;
  c.positions = awkwardPositions(9);
  c.tetrahedra = {3, 2, 1, 0, 4, 5, 7, 6, 0, 8, 4, 2};
  return c;
}

// ---------------------------------------------------------------------------
// STL
// ---------------------------------------------------------------------------

struct StlTriangle {
  std::array<float, 3> normal;
  std::array<float, 9> corners;
  uint16_t attribute = 0;
};

std::vector<uint8_t> binaryStl(const std::string& header, const std::vector<StlTriangle>& triangles,
                               uint32_t declaredCount) {
  std::vector<uint8_t> bytes(80, 0);
  std::memcpy(bytes.data(), header.data(), std::min<size_t>(header.size(), 80));
  auto put32 = [&bytes](uint32_t value) {
    for (int i = 0; i < 4; ++i) bytes.push_back(uint8_t(value >> (8 * i)));
  };
  put32(declaredCount);
  for (const StlTriangle& t : triangles) {
    for (float f : t.normal) put32(bitsOf(f));
    for (float f : t.corners) put32(bitsOf(f));
    bytes.push_back(uint8_t(t.attribute));
    bytes.push_back(uint8_t(t.attribute >> 8));
  }
  return bytes;
}

std::vector<uint8_t> binaryStl(const std::string& header,
                               const std::vector<StlTriangle>& triangles) {
  return binaryStl(header, triangles, uint32_t(triangles.size()));
}

// Two triangles sharing the edge (1,0,0)-(0,1,0), with awkward floats and a
// NaN with a payload that only a binary path keeps.
std::vector<StlTriangle> twoTriangles() {
  return {
      {{0, 0, 1}, {0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.1f}, 0},
      {{0, 0, 1}, {1.0f, 0.0f, 0.0f, 1.0f, 1.0f, -0.0f, 0.0f, 1.0f, 0.1f}, 0x7c1f},
  };
}

TEST(IoStl, BinarySoupKeepsBitsEvenWhenTheHeaderStartsWithSolid) {
  std::vector<StlTriangle> triangles = twoTriangles();
  triangles.push_back({{0, 0, 0}, {floatOf(0x7fc12345), 2, 3, 4, 5, 6, FLT_MIN, floatOf(1), 9}});
  for (const char* header : {"solid exported by some CAD tool", "binary STL", ""}) {
    SCOPED_TRACE(header);
    const ReadResult r = readBytes(Format::Stl, binaryStl(header, triangles));
    ASSERT_TRUE(r.status.ok()) << r.status.message;
    ASSERT_EQ(r.complex.vertexCount(), 3 * triangles.size());
    EXPECT_EQ(r.complex.triangles, (std::vector<uint32_t>{0, 1, 2, 3, 4, 5, 6, 7, 8}));
    std::vector<float> expected;
    for (const StlTriangle& t : triangles) {
      expected.insert(expected.end(), t.corners.begin(), t.corners.end());
    }
    EXPECT_EQ(bitsOf(r.complex.positions), bitsOf(expected));
    EXPECT_TRUE(r.hasNote("attribute values (often a colour) of 1 triangle")) << joined(r.notes);
    EXPECT_TRUE(r.hasNote("facet normals of")) << joined(r.notes);
    EXPECT_EQ(r.notes.size(), 2u) << joined(r.notes);
  }
  // An empty binary STL and bytes after the triangles.
  const ReadResult empty = readBytes(Format::Stl, binaryStl("solid", {}));
  ASSERT_TRUE(empty.status.ok()) << empty.status.message;
  EXPECT_EQ(empty.complex.vertexCount(), 0u);
  std::vector<uint8_t> trailing = binaryStl("no solid here", twoTriangles());
  trailing.insert(trailing.end(), 7, 0xab);
  const ReadResult withTrailing = readBytes(Format::Stl, trailing);
  ASSERT_TRUE(withTrailing.status.ok()) << withTrailing.status.message;
  EXPECT_EQ(withTrailing.complex.vertexCount(), 6u);
  EXPECT_TRUE(withTrailing.hasNote("ignored 7 bytes after the triangles")) << joined(withTrailing.notes);
}

TEST(IoStl, AsciiSoupWithCrlfUppercaseSeveralSolidsAndAPolygon) {
  const std::string text =
      "solid part one\n"
      "  facet normal 0 0 1\n"
      "    outer loop\n"
      "      vertex 0 0 0\n"
      "      vertex 1 0 0\n"
      "      vertex 0 1 0.1\n"
      "    endloop\n"
      "  endfacet\n"
      "  facet normal 0 0 1\n"
      "    outer loop\n"
      "      vertex 1 0 0\n"
      "      vertex 1 1 -0\n"
      "      vertex 0 1 0.1\n"
      "    endloop\n"
      "  endfacet\n"
      "endsolid part one\n"
      "SOLID two\n"
      "FACET NORMAL 0 0 -1 OUTER LOOP\n"  // tokens may share lines
      "VERTEX 5 5 5 VERTEX 6 5 5 VERTEX 6 6 5 VERTEX 5 6 5\n"
      "ENDLOOP ENDFACET\n"
      "ENDSOLID\n";
  for (const std::string& variant : {text, crlf(text)}) {
    const ReadResult r = readText(Format::Stl, variant);
    ASSERT_TRUE(r.status.ok()) << r.status.message;
    ASSERT_EQ(r.complex.vertexCount(), 10u);
    EXPECT_EQ(r.complex.triangles,
              (std::vector<uint32_t>{0, 1, 2, 3, 4, 5, 6, 7, 8, 6, 8, 9}));
    EXPECT_EQ(bitsOf(r.complex.positions[2 * 3 + 2]), bitsOf(0.1f));
    EXPECT_EQ(bitsOf(r.complex.positions[4 * 3 + 2]), bitsOf(-0.0f));
    EXPECT_TRUE(r.hasNote("split 1 polygon with")) << joined(r.notes);
    EXPECT_TRUE(r.hasNote("facet normals of 3 triangles")) << joined(r.notes);
    EXPECT_EQ(r.notes.size(), 2u) << joined(r.notes);
  }
  // No endsolid: read, with a note.
  const ReadResult open = readText(Format::Stl, text.substr(0, text.find("endsolid part one")));
  ASSERT_TRUE(open.status.ok()) << open.status.message;
  EXPECT_EQ(open.complex.vertexCount(), 6u);
  EXPECT_TRUE(open.hasNote("without 'endsolid'")) << joined(open.notes);
}

TEST(IoStl, WeldMergesBitIdenticalVerticesOnly) {
  for (bool ascii : {false, true}) {
    SCOPED_TRACE(ascii ? "ascii" : "binary");
    std::vector<uint8_t> bytes;
    if (ascii) {
      bytes = bytesOf(
          "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0.1\n"
          "endloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 1 0 0\nvertex 1 1 -0\n"
          "vertex 0 1 0.1\nendloop\nendfacet\nendsolid s\n");
    } else {
      bytes = binaryStl("solid", twoTriangles());
    }
    const ReadResult soup = readBytes(Format::Stl, bytes);
    ASSERT_TRUE(soup.status.ok()) << soup.status.message;
    EXPECT_EQ(soup.complex.vertexCount(), 6u);

    const ReadResult welded = readBytes(Format::Stl, bytes, /*weld=*/true);
    ASSERT_TRUE(welded.status.ok()) << welded.status.message;
    // (1,0,0) and (0,1,0.1) are shared; order of first appearance is kept.
    ASSERT_EQ(welded.complex.vertexCount(), 4u);
    EXPECT_EQ(welded.complex.triangles, (std::vector<uint32_t>{0, 1, 2, 1, 3, 2}));
    EXPECT_EQ(bitsOf(welded.complex.positions),
              bitsOf(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0.1f, 1, 1, -0.0f}));
    EXPECT_TRUE(welded.hasNote("welded 2 vertices")) << joined(welded.notes);
    EXPECT_TRUE(welded.hasNote("6 -> 4")) << joined(welded.notes);
  }
  // +0 and -0 differ in their bits and stay apart; a triangle whose corners
  // weld together is dropped and noted, its vertices kept.
  std::vector<StlTriangle> signs = {
      {{0, 0, 1}, {0.0f, 0, 0, -0.0f, 0, 0, 1, 1, 1}, 0},
      {{0, 0, 1}, {2, 2, 2, 2, 2, 2, 3, 3, 3}, 0},
  };
  const ReadResult welded = readBytes(Format::Stl, binaryStl("x", signs), true);
  ASSERT_TRUE(welded.status.ok()) << welded.status.message;
  EXPECT_EQ(welded.complex.vertexCount(), 5u);
  EXPECT_EQ(welded.complex.triangles, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_TRUE(welded.hasNote("dropped 1 simplex that welding left with a repeated vertex"))
      << joined(welded.notes);

  // readFile passes the option on.
  TempDir dir;
  const fs::path path = dir / "soup.STL";
  const std::vector<uint8_t> bytes = binaryStl("solid", twoTriangles());
  writeWhole(path, std::string(bytes.begin(), bytes.end()));
  EXPECT_EQ(readPath(path).complex.vertexCount(), 6u);
  EXPECT_EQ(readPath(path, true).complex.vertexCount(), 4u);
}

TEST(IoStl, TruncatedBinaryFailsCleanlyAtEveryLength) {
  for (const char* header : {"solid but binary", "binary"}) {
    SCOPED_TRACE(header);
    const std::vector<uint8_t> full = binaryStl(header, twoTriangles());
    ASSERT_TRUE(readBytes(Format::Stl, full).status.ok());
    expectPrefixesReadOrFailCleanly(Format::Stl, full, /*everyPrefixFails=*/true);
    const std::vector<uint8_t> cut(full.begin(), full.end() - 1);
    expectFailure(readBytes(Format::Stl, cut), {"declares 2 triangles", "truncated"});
    expectCorruptionsReadOrFailCleanly(Format::Stl, full);
    const std::vector<uint8_t> tiny(full.begin(), full.begin() + 40);
    expectFailure(readBytes(Format::Stl, tiny), {"not an STL file", "40 bytes"});
  }
  // A count of 2^32 - 1 in a file of one triangle fails at once.
  const auto start = std::chrono::steady_clock::now();
  expectFailure(readBytes(Format::Stl, binaryStl("huge", twoTriangles(), 0xffffffffu)),
                {"4294967295 triangles", "truncated"});
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(200));
}

TEST(IoStl, AsciiErrorsNameTheLineAndFacet) {
  const std::string head = "solid s\nfacet normal 0 0 1\nouter loop\n";
  expectFailure(readText(Format::Stl, head + "vertex 0 0 0\nvertex 1 x 0\n"),
                {"line 5", "facet 0", "'x' is not a number"});
  expectFailure(readText(Format::Stl, head + "vertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\n"),
                {"line 6", "facet 0", "has 2 vertices"});
  expectFailure(readText(Format::Stl, head + "vertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendfacet\n"),
                {"line 7", "expected 'vertex' or 'endloop'", "'endfacet'"});
  expectFailure(readText(Format::Stl, head + "vertex 0 0 0\nvertex 1 0 0\n"),
                {"facet 0", "ends inside the loop"});
  expectFailure(readText(Format::Stl, "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                                      "vertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nfacet\n"),
                {"line 9", "facet 1", "ends before 'normal'"});
  expectFailure(readText(Format::Stl, "solid s\nendsolid s\nnonsense\n"),
                {"line 3", "expected 'solid'"});
  // Text that is not STL at all reads as a too-short binary file.
  expectFailure(readText(Format::Stl, "hello\n"), {"not an STL file"});
  expectFailure(readText(Format::Stl, "solid\n"), {"not an STL file"});
  // Every prefix of an ascii file reads or fails cleanly.
  expectPrefixesReadOrFailCleanly(
      Format::Stl,
      bytesOf(head + "vertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid s\n"),
      false);
}

TEST(IoStl, ExtensionNameAndNoWriter) {
  EXPECT_EQ(io::formatFromPath("part.stl"), Format::Stl);
  EXPECT_EQ(io::formatFromPath("C:\\cad\\PART.STL"), Format::Stl);
  EXPECT_STREQ(io::formatName(Format::Stl), "stl");
  std::vector<uint8_t> out;
  Complex c;
  c.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  c.triangles = {0, 1, 2};
  EXPECT_EQ(io::writeMemory(Format::Stl, c, out).code, ErrorCode::InvalidArgument);
  EXPECT_TRUE(out.empty());
}

// ---------------------------------------------------------------------------
// Medit
// ---------------------------------------------------------------------------

void expectSameComplex(const Complex& actual, const Complex& expected) {
  EXPECT_EQ(bitsOf(actual.positions), bitsOf(expected.positions));
  EXPECT_EQ(actual.points, expected.points);
  EXPECT_EQ(actual.edges, expected.edges);
  EXPECT_EQ(actual.triangles, expected.triangles);
  EXPECT_EQ(actual.tetrahedra, expected.tetrahedra);
}

// `complex` and a cloud of awkward floats come back from `format` exactly,
// without notes; returns the text written for `complex`.
std::string expectExactRoundTrip(Format format, const Complex& complex) {
  const ReadResult back = writeThenRead(format, complex);
  EXPECT_TRUE(back.status.ok()) << back.status.message;
  EXPECT_TRUE(back.notes.empty()) << joined(back.notes);
  expectSameComplex(back.complex, complex);

  Complex cloud;
  cloud.positions = awkwardPositions(500);
  const ReadResult cloudBack = writeThenRead(format, cloud);
  EXPECT_TRUE(cloudBack.status.ok()) << cloudBack.status.message;
  expectSameComplex(cloudBack.complex, cloud);

  std::vector<uint8_t> bytes;
  EXPECT_TRUE(io::writeMemory(format, complex, bytes).ok());
  return std::string(bytes.begin(), bytes.end());
}

TEST(IoMedit, RoundTripKeepsBitsOrientationAndEverySimplexType) {
  const Complex c = mixedComplex();
  const std::string text = expectExactRoundTrip(Format::Medit, c);
  EXPECT_EQ(text.rfind("MeshVersionFormatted 1\nDimension 3\nVertices\n12\n", 0), 0u) << text;
  EXPECT_NE(text.find("Triangles\n3\n3 2 1 0\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\nEnd\n"), std::string::npos);

  // Explicit points on used vertices have no place in Medit.
  std::vector<uint8_t> bytes;
  Complex withPoint = c;
  withPoint.points = {0};
  EXPECT_EQ(io::writeMemory(Format::Medit, withPoint, bytes).code, ErrorCode::InvalidArgument);
  withPoint.points = {11};  // isolated: implicit
  EXPECT_TRUE(io::writeMemory(Format::Medit, withPoint, bytes).ok());
}

TEST(IoMedit, ReadsCommentsCrlfWrappedValuesQuadsAndSkippedSections) {
  const std::string text =
      "# made by hand\n"
      "MeshVersionFormatted 2\n"
      "\n"
      "Dimension\n3\n"
      "Vertices 5\n"
      "0 0 0 1\n"
      "1 0 0 0   # a comment after a vertex\n"
      "1 1 0\n0\n"  // an item wrapped over two lines
      "0 1 0 0\n"
      "0.5 0.5 1 7\n"
      "Corners\n2\n1\n2\n"
      "Edges\n1\n1 5 0\n"
      "Quadrilaterals\n1\n1 2 3 4 3\n"
      "Triangles 1\n4 5 1 0\n"
      "Hexahedra\n1\n1 2 3 4 5 1 2 3 0\n"
      "Tetrahedra\n1\n1 2 4 5 2\n"
      "NormalAtVertices 0\n"
      "End\n"
      "whatever follows\n";
  for (const std::string& variant : {text, crlf(text)}) {
    const ReadResult r = readText(Format::Medit, variant);
    ASSERT_TRUE(r.status.ok()) << r.status.message;
    EXPECT_EQ(bitsOf(r.complex.positions),
              bitsOf(std::vector<float>{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5f, 0.5f, 1}));
    EXPECT_EQ(r.complex.edges, (std::vector<uint32_t>{0, 4}));
    EXPECT_EQ(r.complex.triangles, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 3, 4, 0}));
    EXPECT_EQ(r.complex.tetrahedra, (std::vector<uint32_t>{0, 1, 3, 4}));
    EXPECT_TRUE(r.complex.points.empty());
    EXPECT_TRUE(r.hasNote("split 1 polygon with")) << joined(r.notes);
    EXPECT_TRUE(r.hasNote("skipped 2 Corners")) << joined(r.notes);
    EXPECT_TRUE(r.hasNote("skipped 1 Hexahedra")) << joined(r.notes);
    // Vertex references are the attribute ref; element references the
    // simplices' labels.
    ASSERT_EQ(r.complex.attributes.size(), 1u);
    EXPECT_EQ(r.complex.attributes[0].name, "ref");
    EXPECT_EQ(r.complex.attributes[0].type, AttributeType::UInt8);
    EXPECT_EQ(r.complex.attributes[0].values, (std::vector<uint8_t>{1, 0, 0, 0, 7}));
    EXPECT_EQ(r.complex.labels.edges, (std::vector<int32_t>{0}));
    EXPECT_EQ(r.complex.labels.triangles, (std::vector<int32_t>{3, 3, 0}));
    EXPECT_EQ(r.complex.labels.tetrahedra, (std::vector<int32_t>{2}));
    EXPECT_TRUE(r.hasNote("double precision")) << joined(r.notes);
    EXPECT_TRUE(r.hasNote("follows End (from line 33)")) << joined(r.notes);
  }
  // Lower-case keywords and no End.
  const ReadResult lower = readText(
      Format::Medit, "meshversionformatted 1 dimension 3 vertices 3 0 0 0 0 1 0 0 0 0 1 0 0 "
                     "triangles 1 1 2 3 0");
  ASSERT_TRUE(lower.status.ok()) << lower.status.message;
  EXPECT_EQ(lower.complex.triangles, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_TRUE(lower.notes.empty()) << joined(lower.notes);
}

TEST(IoMedit, BadInputNamesTheLineAndKeyword) {
  const std::string head = "MeshVersionFormatted 1\nDimension 3\nVertices\n3\n0 0 0 0\n1 0 0 0\n0 1 0 0\n";
  expectFailure(readText(Format::Medit, "MeshVersionFormatted 1\nDimension 2\nVertices\n0\n"),
                {"line 2", "Dimension 2", "only Dimension 3"});
  expectFailure(readText(Format::Medit, head + "SolAtVertices\n1\n"),
                {"line 8", "'SolAtVertices'", "unknown Medit keyword"});
  expectFailure(readText(Format::Medit, head + "Triangles\n1\n1 2 4 0\n"),
                {"line 10", "triangle 0", "vertex index 4", "out of range (1 to 3)"});
  expectFailure(readText(Format::Medit, head + "Edges\n2\n1 2 0\n0 1 0\n"),
                {"line 11", "edge 1", "vertex index 0", "out of range"});
  expectFailure(readText(Format::Medit, head + "Tetrahedra\n1\n1 2 3 x 0\n"),
                {"line 10", "tetrahedron 0", "'x'"});
  expectFailure(readText(Format::Medit, head + "Triangles\n2\n1 2 3 0\n1 2 3\n"),
                {"the file ends inside triangle 1"});
  expectFailure(readText(Format::Medit, "MeshVersionFormatted 1\nTriangles 1\n1 2 3 0\nVertices 0\n"),
                {"line 2", "before the Vertices"});
  expectFailure(readText(Format::Medit, head + "Vertices 0\n"), {"second Vertices"});
  expectFailure(readText(Format::Medit, "Vertices 1\n0 0 0 0\n"), {"not a Medit file"});
  expectFailure(readText(Format::Medit, "MeshVersionFormatted 1\nVertices 1\n0 0 y 0\n"),
                {"line 3", "vertex 0", "'y' is not a number"});
  expectFailure(readText(Format::Medit, "MeshVersionFormatted 1\nVertices 1\n0 0 0 0.5\n"),
                {"line 3", "reference '0.5'"});
  // Huge counts fail before anything is allocated.
  const auto start = std::chrono::steady_clock::now();
  expectFailure(readText(Format::Medit, "MeshVersionFormatted 1\nVertices 4000000000\n0 0 0 0\n"),
                {"line 2", "4000000000", "more than the rest of the file"});
  expectFailure(readText(Format::Medit, head + "Tetrahedra 18446744073709551615\n1 2 3 1 0\n"),
                {"line 8", "more than the rest of the file"});
  expectFailure(readText(Format::Medit, head + "Hexahedra 99999999999\n"),
                {"Hexahedra", "more than the rest of the file"});
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(200));

  expectDamagedCopiesReadOrFailCleanly(Format::Medit, mixedComplex());
}

TEST(IoMedit, ExtensionAndName) {
  EXPECT_EQ(io::formatFromPath("a/b/wing.mesh"), Format::Medit);
  EXPECT_EQ(io::formatFromPath("WING.MESH"), Format::Medit);
  EXPECT_EQ(io::formatFromPath("wing.meshb"), Format::Unknown);
  EXPECT_STREQ(io::formatName(Format::Medit), "medit");
}

// ---------------------------------------------------------------------------
// TetGen
// ---------------------------------------------------------------------------

TEST(IoTetgen, NodeAndEleFilesRoundTripThroughEitherPath) {
  TempDir dir;
  const Complex c = tetrahedralComplex();
  for (const char* given : {"model.node", "model.ele"}) {
    SCOPED_TRACE(given);
    ASSERT_TRUE(io::writeFile((dir / given).string(), c).ok());
    EXPECT_TRUE(fs::exists(dir / "model.node"));
    EXPECT_TRUE(fs::exists(dir / "model.ele"));
    for (const char* read : {"model.node", "model.ele"}) {
      const ReadResult back = readPath(dir / read);
      ASSERT_TRUE(back.status.ok()) << back.status.message;
      EXPECT_TRUE(back.notes.empty()) << joined(back.notes);
      expectSameComplex(back.complex, c);
    }
  }
  EXPECT_EQ(readWhole(dir / "model.ele").rfind("# written by kdmesh\n3 4 0\n1 4 3 2 1\n2 5 6 8 7\n", 0),
            0u);

  // A point cloud writes the .node alone, and reads back with a note.
  Complex cloud;
  cloud.positions = awkwardPositions(300);
  ASSERT_TRUE(io::writeFile((dir / "cloud.node").string(), cloud).ok());
  EXPECT_FALSE(fs::exists(dir / "cloud.ele"));
  const ReadResult back = readPath(dir / "cloud.node");
  ASSERT_TRUE(back.status.ok()) << back.status.message;
  expectSameComplex(back.complex, cloud);
  EXPECT_TRUE(back.hasNote("read the nodes as a point cloud")) << joined(back.notes);
  // Asked for by name, the .ele is written even without tetrahedra.
  ASSERT_TRUE(io::writeFile((dir / "cloud.ele").string(), cloud).ok());
  EXPECT_EQ(readWhole(dir / "cloud.ele"), "# written by kdmesh\n0 4 0\n");
  // ...and then it must be there when the .ele is given.
  fs::remove(dir / "cloud.ele");
  const ReadResult noEle = readPath(dir / "cloud.ele");
  EXPECT_EQ(noEle.status.code, ErrorCode::InvalidArgument);
  EXPECT_NE(noEle.status.message.find("cloud.ele"), std::string::npos) << noEle.status.message;
  fs::remove(dir / "cloud.node");
  const ReadResult noNode = readPath(dir / "cloud.node");
  EXPECT_EQ(noNode.status.code, ErrorCode::InvalidArgument);
  EXPECT_NE(noNode.status.message.find("cloud.node"), std::string::npos);
}

TEST(IoTetgen, ReadsHandWrittenFilesNumberedFromZeroOrOne) {
  TempDir dir;
  // Numbered from 0, with attributes, markers, comments and CRLF.
  writeWhole(dir / "zero.node", crlf("# nodes\n"
                                     "5 3 2 1\n"
                                     "0 0 0 0 7.5 8 1\n"
                                     "1 1 0 0 7.5 8 0  # comment\n"
                                     "\n"
                                     "2 0 1 0 7.5 8 0\n"
                                     "3 0 0 1 7.5 8 0\n"
                                     "4 0.1 0.2 0.3 7.5 8 0\n"));
  writeWhole(dir / "zero.ele", crlf("2 4 1\n"
                                    "0 0 1 2 3 -1\n"
                                    "# between\n"
                                    "1 4 3 2 1 -1\n"));
  const ReadResult zero = readPath(dir / "zero.ele");
  ASSERT_TRUE(zero.status.ok()) << zero.status.message;
  EXPECT_EQ(bitsOf(zero.complex.positions),
            bitsOf(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.1f, 0.2f, 0.3f}));
  EXPECT_EQ(zero.complex.tetrahedra, (std::vector<uint32_t>{0, 1, 2, 3, 4, 3, 2, 1}));
  // The point attributes and the boundary markers are attributes.
  ASSERT_EQ(zero.complex.attributes.size(), 2u);
  EXPECT_EQ(zero.complex.attributes[0].name, "attribute");
  EXPECT_EQ(zero.complex.attributes[0].components, 2);
  EXPECT_EQ(zero.complex.attributes[0].values.size(), 40u);
  EXPECT_EQ(zero.complex.attributes[1].name, "marker");
  EXPECT_EQ(zero.complex.attributes[1].type, AttributeType::UInt8);
  EXPECT_EQ(zero.complex.attributes[1].values, (std::vector<uint8_t>{1, 0, 0, 0, 0}));
  EXPECT_EQ(zero.complex.labels.tetrahedra, (std::vector<int32_t>{-1, -1}));  // the region attribute

  // Numbered from 1, header without attribute counts, 10-node tetrahedra.
  writeWhole(dir / "one.node", "4 3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n");
  writeWhole(dir / "one.ele", "1 10\n1 4 3 2 1 1 2 3 4 1 2\n");
  const ReadResult one = readPath(dir / "one.node");
  ASSERT_TRUE(one.status.ok()) << one.status.message;
  EXPECT_EQ(one.complex.tetrahedra, (std::vector<uint32_t>{3, 2, 1, 0}));
  EXPECT_TRUE(one.hasNote("4 corners of 1 10-node")) << joined(one.notes);

  // readMemory reads a .node alone.
  const ReadResult memory = readText(Format::TetGen, "2 3 0 0\n1 1 2 3\n2 4 5 6\n");
  ASSERT_TRUE(memory.status.ok()) << memory.status.message;
  EXPECT_EQ(memory.complex.vertexCount(), 2u);
  EXPECT_FALSE(memory.complex.hasSimplices());
  // Weld applies to the pair.
  writeWhole(dir / "dup.node", "3 3\n1 0 0 0\n2 0 0 0\n3 1 1 1\n");
  writeWhole(dir / "dup.ele", "0 4\n");
  const ReadResult dup = readPath(dir / "dup.node", true);
  ASSERT_TRUE(dup.status.ok()) << dup.status.message;
  EXPECT_EQ(dup.complex.vertexCount(), 2u);
}

TEST(IoTetgen, BadInputNamesTheFileLineAndTetrahedron) {
  TempDir dir;
  const std::string node = "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n";
  writeWhole(dir / "a.node", node);
  writeWhole(dir / "a.ele", "1 4 0\n1 1 2 3 5\n");
  ReadResult r = readPath(dir / "a.node");
  expectFailure(r, {"a.ele: line 2", "tetrahedron 0", "point 5", "out of range (1 to 4)"});
  // The file the user named is not named again.
  r = readPath(dir / "a.ele");
  expectFailure(r, {"line 2", "point 5"});
  EXPECT_EQ(r.status.message.find("a.ele"), std::string::npos) << r.status.message;

  writeWhole(dir / "a.ele", "2 4 0\n1 1 2 3 4\n3 1 2 3 4\n");
  expectFailure(readPath(dir / "a.ele"), {"line 3", "tetrahedron 1 is numbered 3, expected 2"});
  writeWhole(dir / "a.ele", "1 6 0\n1 1 2 3 4 1 1\n");
  expectFailure(readPath(dir / "a.ele"), {"line 1", "6 nodes per tetrahedron"});
  writeWhole(dir / "a.ele", "2 4 0\n1 1 2 3 4\n");
  expectFailure(readPath(dir / "a.ele"), {"more than the rest of the file"});
  writeWhole(dir / "a.ele", "1 4 0\n1 1 2 3\n");
  expectFailure(readPath(dir / "a.ele"), {"tetrahedron 0 has 3 nodes"});
  writeWhole(dir / "a.ele", "");
  expectFailure(readPath(dir / "a.node"), {"a.ele", "empty"});
  writeWhole(dir / "a.ele", "1 4 0\n1 1 2 3 4\n");
  writeWhole(dir / "a.node", "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n");
  expectFailure(readPath(dir / "a.ele"), {"a.node", "more than the rest of the file"});

  expectFailure(readText(Format::TetGen, "2 2 0 0\n1 0 0\n2 1 1\n"),
                {"line 1", "dimension is 2", "only 3"});
  expectFailure(readText(Format::TetGen, "2 3 0 0\n2 0 0 0\n3 1 1 1\n"),
                {"line 2", "numbered 2, not 0 or 1"});
  expectFailure(readText(Format::TetGen, "2 3 0 0\n0 0 0 0\n2 1 1 1\n"),
                {"line 3", "numbered 2, expected 1"});
  expectFailure(readText(Format::TetGen, "2 3 1 0\n0 0 0 0 5\n1 1 1 1\n"),
                {"line 3", "point 1 lacks 1"});
  expectFailure(readText(Format::TetGen, "1 3 0 2\n0 0 0 0 1 1\n"), {"marker count is 2"});
  expectFailure(readText(Format::TetGen, "1 3 0 0\n0 0 z 0\n"), {"line 2", "'z'"});
  expectFailure(readText(Format::TetGen, "3\n"), {"line 1", "needs at least 2"});
  const auto start = std::chrono::steady_clock::now();
  expectFailure(readText(Format::TetGen, "4000000000 3 0 0\n0 0 0 0\n"),
                {"line 1", "4000000000", "more than the rest of the file"});
  expectFailure(readText(Format::TetGen, "1 3 18446744073709551615 0\n0 0 0 0\n"),
                {"more than the rest of the file"});
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(200));

  Complex cloud;
  cloud.positions = awkwardPositions(20);
  expectDamagedCopiesReadOrFailCleanly(Format::TetGen, cloud);
}

TEST(IoTetgen, WritersRefuseEdgesTrianglesAndTetrahedraInMemory) {
  TempDir dir;
  Complex withTriangles = tetrahedralComplex();
  withTriangles.triangles = {0, 1, 2};
  EXPECT_EQ(io::writeFile((dir / "t.node").string(), withTriangles).code,
            ErrorCode::InvalidArgument);
  Complex withEdges = tetrahedralComplex();
  withEdges.edges = {0, 1};
  EXPECT_EQ(io::writeFile((dir / "t.ele").string(), withEdges).code, ErrorCode::InvalidArgument);
  EXPECT_FALSE(fs::exists(dir / "t.node"));
  EXPECT_FALSE(fs::exists(dir / "t.ele"));
  Complex pointOnTetra = tetrahedralComplex();
  pointOnTetra.points = {0};
  EXPECT_EQ(io::writeFile((dir / "t.node").string(), pointOnTetra).code,
            ErrorCode::InvalidArgument);
  Complex badIndex = tetrahedralComplex();
  badIndex.tetrahedra.back() = 99;
  EXPECT_EQ(io::writeFile((dir / "t.node").string(), badIndex).code, ErrorCode::InvalidInput);
  std::vector<uint8_t> out;
  EXPECT_EQ(io::writeMemory(Format::TetGen, tetrahedralComplex(), out).code,
            ErrorCode::InvalidArgument);
  EXPECT_TRUE(out.empty());
}

TEST(IoTetgen, ExtensionsAndName) {
  EXPECT_EQ(io::formatFromPath("mesh.1.node"), Format::TetGen);
  EXPECT_EQ(io::formatFromPath("MESH.ELE"), Format::TetGen);
  EXPECT_EQ(io::formatFromPath("mesh.face"), Format::Unknown);
  EXPECT_STREQ(io::formatName(Format::TetGen), "tetgen");
}

// ---------------------------------------------------------------------------
// VTK
// ---------------------------------------------------------------------------

TEST(IoVtk, RoundTripKeepsBitsOrientationPointsAndEverySimplexType) {
  Complex c = mixedComplex();
  c.points = {11, 0};  // explicit points, even on a used vertex
  const std::string text = expectExactRoundTrip(Format::Vtk, c);
  EXPECT_EQ(text.rfind("# vtk DataFile Version 3.0\n", 0), 0u) << text;
  EXPECT_NE(text.find("POINTS 12 float\n"), std::string::npos);
  EXPECT_NE(text.find("CELLS 9 32\n1 11\n1 0\n2 9 10\n"), std::string::npos) << text;
  EXPECT_NE(text.find("CELL_TYPES 9\n1\n1\n3\n3\n5\n5\n5\n10\n10\n"), std::string::npos) << text;
}

TEST(IoVtk, ReadsUnstructuredGridWithEveryCellKindCrlfAndIgnoredData) {
  const std::string text =
      "# vtk DataFile Version 2.0\n"
      "hand-written grid\n"
      "ASCII\n"
      "\n"
      "DATASET UNSTRUCTURED_GRID\n"
      "FIELD FieldData 2\n"
      "TIME 1 1 double\n"
      "1.5\n"
      "CYCLE 1 1 int\n"
      "7\n"
      "POINTS 6 double\n"
      "0 0 0  1 0 0  0 1 0\n"  // several points on a line
      "0 0 1 0.1\n"            // and one split over lines
      "0.2 0.3  1 1 1\n"
      "\n"
      "CELLS 10 47\n"
      "1 5\n"
      "3 0 1 2\n"
      "2 3 4\n"
      "4 0 1 2 3\n"
      "4 0 1 5 2\n"
      "5 0 1 5 2 4\n"
      "3 0 1 2\n"
      "8 0 1 2 3 4 5 0 1\n"
      "3 5 4 3\n"
      "4 0 2 4 5\n"
      "CELL_TYPES 10\n"
      "1 5 3 10 9\n"
      "7 4 12 6\n"
      "9\n"
      "POINT_DATA 6\n"
      "SCALARS s float 1\n"
      "LOOKUP_TABLE default\n"
      "1 2 3 4 5 6\n"
      "CELL_DATA 10\n"
      "SCALARS quality float\n"
      "0.5 0.5 0.5 0.5 0.5 0.5 0.5 0.5 0.5 0.5\n"
      "SCALARS region int\n"
      "1 2 3 4 5 6 7 8 9 -10\n";
  for (const std::string& variant : {text, crlf(text)}) {
    const ReadResult r = readText(Format::Vtk, variant);
    ASSERT_TRUE(r.status.ok()) << r.status.message;
    EXPECT_EQ(bitsOf(r.complex.positions),
              bitsOf(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.1f, 0.2f, 0.3f, 1,
                                        1, 1}));
    EXPECT_EQ(r.complex.points, (std::vector<uint32_t>{5}));
    EXPECT_EQ(r.complex.edges, (std::vector<uint32_t>{3, 4, 0, 1, 1, 2}));
    // Triangle, quad (2), polygon (3), strip of one triangle, quad (2).
    EXPECT_EQ(r.complex.triangles,
              (std::vector<uint32_t>{0, 1, 2, 0, 1, 5, 0, 5, 2, 0, 1, 5, 0, 5, 2, 0, 2, 4,
                                     5, 4, 3, 0, 2, 4, 0, 4, 5}));
    EXPECT_EQ(r.complex.tetrahedra, (std::vector<uint32_t>{0, 1, 2, 3}));
    EXPECT_TRUE(r.hasNote("split 3 polygons")) << joined(r.notes);
    EXPECT_TRUE(r.hasNote("skipped 1 cell that is")) << joined(r.notes);
    EXPECT_TRUE(r.hasNote("types 12 x1")) << joined(r.notes);
    ASSERT_EQ(r.complex.attributes.size(), 1u);
    EXPECT_EQ(r.complex.attributes[0].name, "s");
    EXPECT_EQ(r.complex.attributes[0].type, AttributeType::Float32);
    EXPECT_EQ(r.complex.attributes[0].values.size(), 24u);
    EXPECT_TRUE(r.hasNote("ignored 1 data array (cell data")) << joined(r.notes);  // quality
    // The first integer cell array labels each cell's simplices: cells 2
    // (a line), 3 (the tetrahedron), 1, 4, 5, 6, 8, 9 and 10 in list order.
    EXPECT_TRUE(r.hasNote("kept the cell data array 'region' as simplex labels")) << joined(r.notes);
    EXPECT_EQ(r.complex.labels.edges, (std::vector<int32_t>{3, 7, 7}));
    EXPECT_EQ(r.complex.labels.triangles, (std::vector<int32_t>{2, 5, 5, 6, 6, 6, 9, -10, -10}));
    EXPECT_EQ(r.complex.labels.tetrahedra, (std::vector<int32_t>{4}));
    // Its double POINTS are decimals that float32 holds: nothing rounded.
    EXPECT_FALSE(r.hasNote("rounded to float32")) << joined(r.notes);
    EXPECT_TRUE(r.hasNote("ignored 1 FIELD")) << joined(r.notes);
  }
}

// A cell type of its own in every cell: the note names a few types and
// counts the rest, rather than growing with the file.
TEST(IoVtk, ManySkippedCellTypesMakeAShortNote) {
  std::string cells, types;
  for (int c = 0; c < 1000; ++c) {
    cells += "1 0\n";
    types += std::to_string(100 + c) + "\n";
  }
  const ReadResult r = readText(Format::Vtk, "# vtk DataFile Version 3.0\nt\nASCII\n"
                                             "DATASET UNSTRUCTURED_GRID\nPOINTS 1 float\n0 0 0\n"
                                             "CELLS 1000 2000\n" + cells + "CELL_TYPES 1000\n" + types);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  ASSERT_EQ(r.notes.size(), 1u) << joined(r.notes);
  EXPECT_TRUE(r.hasNote("skipped 1000 cells")) << joined(r.notes);
  EXPECT_TRUE(r.hasNote("types 100 x1, 101 x1")) << joined(r.notes);
  EXPECT_TRUE(r.hasNote("115 x1, other types x984)")) << joined(r.notes);
  EXPECT_LT(r.notes[0].size(), 400u) << r.notes[0];
}

TEST(IoVtk, ReadsVersion5OffsetsAndPolyData) {
  const std::string version5 =
      "# vtk DataFile Version 5.1\n"
      "vtk output\n"
      "ASCII\n"
      "DATASET UNSTRUCTURED_GRID\n"
      "POINTS 4 float\n"
      "0 0 0 1 0 0 0 1 0\n"
      "0 0 1\n"
      "METADATA\n"
      "INFORMATION 2\n"
      "NAME L2_NORM_RANGE LOCATION vtkDataArray\n"
      "DATA 2 0 1.73205\n"
      "\n"
      "CELLS 4 9\n"
      "OFFSETS vtktypeint64\n"
      "0 4 7 9\n"
      "CONNECTIVITY vtktypeint64\n"
      "0 1 2 3 3 2 1\n"
      "0 3\n"
      "CELL_TYPES 3\n"
      "10\n5\n3\n"
      "CELL_DATA 3\n";
  const ReadResult r = readText(Format::Vtk, version5);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  EXPECT_EQ(r.complex.vertexCount(), 4u);
  EXPECT_EQ(r.complex.tetrahedra, (std::vector<uint32_t>{0, 1, 2, 3}));
  EXPECT_EQ(r.complex.triangles, (std::vector<uint32_t>{3, 2, 1}));
  EXPECT_EQ(r.complex.edges, (std::vector<uint32_t>{0, 3}));
  EXPECT_TRUE(r.complex.attributes.empty());

  const std::string polyData =
      "# vtk DataFile Version 3.0\n"
      "\n"  // an empty title
      "ascii\n"
      "dataset polydata\n"
      "points 5 float\n"
      "0 0 0 1 0 0 1 1 0 0 1 0 2 2 2\n"
      "vertices 1 2\n1 4\n"
      "lines 1 4\n3 0 1 2\n"
      "polygons 2 9\n4 0 1 2 3\n3 3 2 1\n"
      "triangle_strips 1 5\n4 0 1 3 2\n";
  const ReadResult p = readText(Format::Vtk, polyData);
  ASSERT_TRUE(p.status.ok()) << p.status.message;
  EXPECT_EQ(p.complex.points, (std::vector<uint32_t>{4}));
  EXPECT_EQ(p.complex.edges, (std::vector<uint32_t>{0, 1, 1, 2}));
  EXPECT_EQ(p.complex.triangles,
            (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 3, 2, 1, 0, 1, 3, 3, 1, 2}));
  EXPECT_TRUE(p.hasNote("split 1 polygon with")) << joined(p.notes);
}

TEST(IoVtk, BadInputIsRejectedWithTheLine) {
  const std::string head =
      "# vtk DataFile Version 3.0\ntitle\nASCII\nDATASET UNSTRUCTURED_GRID\n"
      "POINTS 3 float\n0 0 0 1 0 0 0 1 0\n";
  expectFailure(readText(Format::Vtk, "# vtk DataFile Version 3.0\ntitle\nBINARY\n"
                                      "DATASET UNSTRUCTURED_GRID\nPOINTS 1 float\n\x3f\x80\0\0"),
                {"line 3", "binary VTK is not supported"});
  expectFailure(readText(Format::Vtk, "# not vtk\n"), {"not a legacy VTK file"});
  expectFailure(readText(Format::Vtk, "# vtk DataFile Version 3.0\ntitle\nASCII\n"
                                      "DATASET STRUCTURED_POINTS\n"),
                {"line 4", "'STRUCTURED_POINTS'", "not supported"});
  expectFailure(readText(Format::Vtk, head + "CELLS 2 8\n3 0 1 2\n3 0 1 3\nCELL_TYPES 2\n5 5\n"),
                {"line 9", "CELLS cell 1", "point index 3", "out of range (3 points)"});
  expectFailure(readText(Format::Vtk, head + "CELLS 1 5\n4 0 1 2 0\nCELL_TYPES 1\n5\n"),
                {"line 10", "cell 0 of VTK type 5 has 4 points, needs exactly 3"});
  expectFailure(readText(Format::Vtk, head + "CELLS 1 4\n3 0 1 2\nCELL_TYPES 2\n5 5\n"),
                {"line 9", "CELL_TYPES lists 2 types for 1 CELLS"});
  expectFailure(readText(Format::Vtk, head + "CELLS 1 5\n3 0 1 2\nCELL_TYPES 1\n5\n"),
                {"size of 5", "hold 4"});
  expectFailure(readText(Format::Vtk, head + "CELLS 1 4\n3 0 1 2\n"), {"CELLS but no CELL_TYPES"});
  expectFailure(readText(Format::Vtk, head + "POLYGONS 1 4\n3 0 1 2\n"),
                {"line 7", "'POLYGONS'"});
  expectFailure(readText(Format::Vtk, head + "CELLS 3 3\nOFFSETS int\n0 2 1\nCONNECTIVITY int\n0 1 2\n"),
                {"line 9", "OFFSETS value 2"});
  expectFailure(readText(Format::Vtk, "# vtk DataFile Version 3.0\nt\nASCII\n"
                                      "DATASET UNSTRUCTURED_GRID\nPOINTS 2 float\n0 0 0 1 1       \n"),
                {"ends inside point 1"});
  expectFailure(readText(Format::Vtk, "# vtk DataFile Version 3.0\nt\nASCII\n"
                                      "DATASET UNSTRUCTURED_GRID\nPOINTS 1 float\n0 0 q\n"),
                {"line 6", "point 0", "'q'"});
  // Huge declared counts fail before anything is allocated.
  const auto start = std::chrono::steady_clock::now();
  expectFailure(readText(Format::Vtk, "# vtk DataFile Version 3.0\nt\nASCII\n"
                                      "DATASET UNSTRUCTURED_GRID\nPOINTS 4000000000 float\n0 0 0\n"),
                {"line 5", "more than the rest of the file"});
  expectFailure(readText(Format::Vtk, head + "CELLS 1 18446744073709551615\n3 0 1 2\n"),
                {"line 7", "more than the rest of the file"});
  expectFailure(readText(Format::Vtk, head + "CELLS 9999999999 99999999999\nOFFSETS int\n0\n"),
                {"more than the rest of the file"});
  expectFailure(readText(Format::Vtk, "# vtk DataFile Version 3.0\nt\nASCII\nDATASET "
                                      "UNSTRUCTURED_GRID\nFIELD f 1\nA 4294967296 4294967296 float\n"),
                {"line 6", "more than the rest of the file"});
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(200));

  expectDamagedCopiesReadOrFailCleanly(Format::Vtk, mixedComplex());
}

TEST(IoVtk, FilesOnDiskExtensionAndName) {
  EXPECT_EQ(io::formatFromPath("grid.vtk"), Format::Vtk);
  EXPECT_EQ(io::formatFromPath("GRID.VTK"), Format::Vtk);
  EXPECT_EQ(io::formatFromPath("grid.vtu"), Format::Unknown);
  EXPECT_STREQ(io::formatName(Format::Vtk), "vtk");
  TempDir dir;
  const Complex c = mixedComplex();
  for (const char* name : {"m.vtk", "m.mesh"}) {
    ASSERT_TRUE(io::writeFile((dir / name).string(), c).ok()) << name;
    const ReadResult back = readPath(dir / name);
    ASSERT_TRUE(back.status.ok()) << back.status.message;
    expectSameComplex(back.complex, c);
  }
}

}  // namespace
}  // namespace kdmesh::test
