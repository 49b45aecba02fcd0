// kdmesh::io: every format written and read back bit for bit, readers on
// hand-made files of every supported flavour, correctly rounded number
// parsing, and malformed or truncated input that must fail cleanly with a
// message naming the place. Every fixture is generated here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "io/io_internal.h"
#include "io_test_support.h"
#include "kdmesh/io.h"
#include "test_support.h"

namespace kdmesh::test {
namespace {

using io::Format;

// Floats that text formats get wrong when they print too few digits, parse
// via double, or drop the sign of zero.
std::vector<float> awkwardFloats() {
  std::vector<float> v = {
      0.0f,
      -0.0f,
      1.0f,
      -1.0f,
      0.1f,
      1.0f / 3.0f,
      FLT_MAX,
      -FLT_MAX,
      FLT_MIN,                                // smallest normal
      -FLT_MIN,
      floatOf(0x00000001),                    // smallest denormal
      floatOf(0x80000001),
      floatOf(0x007fffff),                    // largest denormal
      floatOf(0x00400000),
      floatOf(0x00012345),
      1e-30f,
      -1e-30f,
      1e30f,
      16777216.0f,                            // 2^24
      16777215.0f,
      0.123456791f,                           // needs 9 significant digits
      123456.789f,
      3.14159274f,
      9.99999944e-11f,
      1.00000012f,
      8388607.5f,
  };
  const float seeds[] = {1.0f, 0.1f, 1e-30f, 3.4e38f, 1e-38f, 7.0f, 1234.5678f};
  for (float s : seeds) {
    v.push_back(std::nextafter(s, 0.0f));
    v.push_back(std::nextafter(s, FLT_MAX));
    v.push_back(-std::nextafter(s, FLT_MAX));
  }
  return v;
}

// The awkward floats padded to whole vertices, plus random bit patterns
// covering every exponent (NaN excluded: text keeps NaN but not its payload).
std::vector<float> awkwardCloud() {
  std::vector<float> p = awkwardFloats();
  std::mt19937 rng(2024);
  for (int i = 0; i < 3000; ++i) {
    float f;
    do {
      f = floatOf(static_cast<uint32_t>(rng()));
    } while (std::isnan(f));
    p.push_back(f);
  }
  while (p.size() % 3 != 0) p.push_back(0.5f);
  return p;
}

struct Target {
  const char* name;
  Format format;
  bool asciiPly;
};

const Target kAllTargets[] = {
    {"ply binary", Format::Ply, false}, {"ply ascii", Format::Ply, true},
    {"obj", Format::Obj, false},        {"off", Format::Off, false},
    {"xyz", Format::Xyz, false},
};

ReadResult writeThenRead(const Target& target, const Complex& complex) {
  SCOPED_TRACE(target.name);
  io::WriteOptions options;
  options.asciiPly = target.asciiPly;
  return kdmesh::test::writeThenRead(target.format, complex, options);
}

// Builds PLY files byte by byte: header text, then binary values in either
// byte order or ascii text.
class PlyBuilder {
 public:
  explicit PlyBuilder(bool bigEndian = false) : bigEndian_(bigEndian) {}

  PlyBuilder& text(const std::string& s) {
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    return *this;
  }
  template <typename T>
  PlyBuilder& put(T value) {
    uint8_t raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof raw);  // the tests run on little-endian hosts
    if (bigEndian_) std::reverse(raw, raw + sizeof raw);
    bytes_.insert(bytes_.end(), raw, raw + sizeof raw);
    return *this;
  }
  const std::vector<uint8_t>& bytes() const { return bytes_; }

 private:
  bool bigEndian_;
  std::vector<uint8_t> bytes_;
};

// ---------------------------------------------------------------------------
// Round trips
// ---------------------------------------------------------------------------

TEST(IoRoundTrip, PointCloudKeepsEveryFloatBitInEveryFormat) {
  const Complex cloud = pointCloud(awkwardCloud());
  for (const Target& target : kAllTargets) {
    SCOPED_TRACE(target.name);
    const ReadResult back = writeThenRead(target, cloud);
    ASSERT_TRUE(back.status.ok()) << back.status.message;
    EXPECT_TRUE(back.notes.empty()) << joined(back.notes);
    // Same vertices in the same order, every bit, the sign of zero included.
    ASSERT_EQ(back.complex.positions.size(), cloud.positions.size());
    const std::vector<uint32_t> expected = bitsOf(cloud.positions);
    const std::vector<uint32_t> actual = bitsOf(back.complex.positions);
    for (size_t i = 0; i < expected.size(); ++i) {
      ASSERT_EQ(actual[i], expected[i])
          << "coordinate " << i << ": wrote " << cloud.positions[i] << " read "
          << back.complex.positions[i];
    }
    EXPECT_FALSE(back.complex.hasSimplices());
  }
}

TEST(IoRoundTrip, InfinitiesKeepTheirBitsAndNaNStaysNaN) {
  const float nanWithPayload = floatOf(0x7fc12345);
  const Complex cloud = pointCloud({INFINITY, -INFINITY, 1.0f, nanWithPayload, -2.0f, 0.0f});
  for (const Target& target : kAllTargets) {
    SCOPED_TRACE(target.name);
    const ReadResult back = writeThenRead(target, cloud);
    ASSERT_TRUE(back.status.ok()) << back.status.message;
    ASSERT_EQ(back.complex.positions.size(), 6u);
    const std::vector<float>& p = back.complex.positions;
    EXPECT_EQ(bitsOf(p[0]), bitsOf(INFINITY));
    EXPECT_EQ(bitsOf(p[1]), bitsOf(-INFINITY));
    EXPECT_TRUE(std::isnan(p[3]));
    EXPECT_EQ(bitsOf(p[4]), bitsOf(-2.0f));
    // Binary PLY stores float32 as is, NaN payload included.
    if (target.format == Format::Ply && !target.asciiPly) {
      EXPECT_EQ(bitsOf(p[3]), 0x7fc12345u);
    }
  }
}

// A closed octahedron whose corners have infinite, NaN and signed-zero
// coordinates, plus a vertex in no triangle: what exact mode must keep.
Complex nonFiniteMesh() {
  Complex c;
  c.positions = {INFINITY,  0.0f,      -0.0f,  -INFINITY, 1.0f,  0.0f,
                 0.5f,      floatOf(0x7fc12345), 0.0f, -0.0f, floatOf(0xffc00001), 2.0f,
                 0.0f,      -0.0f,     INFINITY, 3.0f,    -1.0f, floatOf(0x7f800001),
                 floatOf(0x7fc00000), -INFINITY, -0.0f};
  c.triangles = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
  return c;
}

// Encodes `complex` exactly, checks that the decoded vertices carry the
// same bits (the decoder numbers them in its own order) and triangles,
// and that every prefix decodes in both coarse placements.
void expectExactRoundTrip(const Complex& complex) {
  EncodeOptions exact;
  exact.exact = true;
  exact.chunkBytes = 1024;
  const EncodeResult encoded = encode(complex, exact);
  ASSERT_TRUE(encoded.status.ok()) << encoded.status.message;
  Complex decoded;
  ASSERT_TRUE(decode(encoded.bytes.data(), encoded.bytes.size(), decoded).ok());
  EXPECT_EQ(sortedBitPatterns(decoded.positions), sortedBitPatterns(complex.positions));
  EXPECT_EQ(decoded.triangles.size(), complex.triangles.size());
  for (CoarsePlacement placement : {CoarsePlacement::Predicted, CoarsePlacement::CellCentre}) {
    DecoderOptions options;
    options.coarsePlacement = placement;
    for (size_t size = 0; size <= encoded.bytes.size(); ++size) {
      Decoder decoder(options);
      ASSERT_TRUE(decoder.push(encoded.bytes.data(), size).ok()) << size;
      Complex prefix;
      decoder.snapshot(prefix);
      EXPECT_GE(decoder.errorBound(), 0.0);
    }
  }
}

TEST(IoRoundTrip, ExactEncodingKeepsNonFiniteCoordinatesThroughObjAndPly) {
  const Complex mesh = nonFiniteMesh();
  for (const Target& target : kAllTargets) {
    if (target.format != Format::Obj && target.format != Format::Ply) continue;
    SCOPED_TRACE(target.name);
    const ReadResult read = writeThenRead(target, mesh);
    ASSERT_TRUE(read.status.ok()) << read.status.message;
    // Binary PLY keeps every NaN payload; text keeps a NaN's sign.
    if (target.format == Format::Ply && !target.asciiPly) {
      EXPECT_EQ(bitsOf(read.complex.positions), bitsOf(mesh.positions));
    }
    expectExactRoundTrip(read.complex);
    // Grid mode refuses them and names the option that keeps them.
    const EncodeResult grid = encode(read.complex);
    EXPECT_EQ(grid.status.code, ErrorCode::InvalidInput);
    EXPECT_NE(grid.status.message.find("--exact"), std::string::npos) << grid.status.message;
  }
  // As a point cloud too (other contexts, and cells of coincident NaNs).
  Complex cloud = pointCloud(mesh.positions);
  cloud.positions.insert(cloud.positions.end(), mesh.positions.begin(), mesh.positions.begin() + 12);
  expectExactRoundTrip(cloud);
}

Complex smallMesh() {
  // An octahedron with awkward coordinates, plus one isolated vertex.
  Complex c;
  c.positions = {1e-30f, 0.0f,   -0.0f, -FLT_MIN, 0.0f,         0.0f,
                 0.0f,   1.0f,   0.0f,  0.0f,     -0.123456791f, 0.0f,
                 0.0f,   0.0f,   3e38f, 0.0f,     0.0f,          -1e-38f,
                 7.0f,   7.0f,   7.0f};
  c.triangles = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
  return c;
}

TEST(IoRoundTrip, TrianglesSurviveObjOffAndPly) {
  const Complex mesh = smallMesh();
  for (const Target& target : kAllTargets) {
    if (target.format == Format::Xyz) continue;
    SCOPED_TRACE(target.name);
    const ReadResult back = writeThenRead(target, mesh);
    ASSERT_TRUE(back.status.ok()) << back.status.message;
    EXPECT_TRUE(back.notes.empty()) << joined(back.notes);
    EXPECT_EQ(bitsOf(back.complex.positions), bitsOf(mesh.positions));
    EXPECT_EQ(back.complex.triangles, mesh.triangles);
    EXPECT_TRUE(back.complex.edges.empty());
    EXPECT_TRUE(back.complex.tetrahedra.empty());
  }
}

TEST(IoRoundTrip, EdgesPointsAndTetrahedraWhereTheFormatHoldsThem) {
  Complex c = smallMesh();
  c.edges = {0, 6, 6, 1, 5, 4};
  // OBJ: explicit points (even on used vertices), polylines and faces.
  Complex objComplex = c;
  objComplex.points = {6, 0};
  const ReadResult obj = writeThenRead({"obj", Format::Obj, false}, objComplex);
  ASSERT_TRUE(obj.status.ok()) << obj.status.message;
  EXPECT_EQ(obj.complex.points, objComplex.points);
  EXPECT_EQ(obj.complex.edges, c.edges);
  EXPECT_EQ(obj.complex.triangles, c.triangles);
  EXPECT_EQ(bitsOf(obj.complex.positions), bitsOf(c.positions));

  // PLY: edge and tetra elements too.
  c.tetrahedra = {0, 1, 2, 4, 6, 5, 3, 2};
  for (bool ascii : {false, true}) {
    SCOPED_TRACE(ascii ? "ascii" : "binary");
    const ReadResult ply = writeThenRead({"ply", Format::Ply, ascii}, c);
    ASSERT_TRUE(ply.status.ok()) << ply.status.message;
    EXPECT_TRUE(ply.notes.empty()) << joined(ply.notes);
    EXPECT_EQ(ply.complex.edges, c.edges);
    EXPECT_EQ(ply.complex.triangles, c.triangles);
    EXPECT_EQ(ply.complex.tetrahedra, c.tetrahedra);
    EXPECT_EQ(bitsOf(ply.complex.positions), bitsOf(c.positions));
  }
}

TEST(IoRoundTrip, EmptyComplexWritesAndReadsBackAsPly) {
  const ReadResult back = writeThenRead({"ply", Format::Ply, false}, Complex{});
  ASSERT_TRUE(back.status.ok()) << back.status.message;
  EXPECT_EQ(back.complex.vertexCount(), 0u);
}

TEST(IoRoundTrip, WritersRefuseWhatTheFormatCannotHold) {
  std::vector<uint8_t> out;
  Complex mesh = smallMesh();
  EXPECT_EQ(io::writeMemory(Format::Xyz, mesh, out).code, ErrorCode::InvalidArgument);
  EXPECT_TRUE(out.empty());

  Complex withEdges = smallMesh();
  withEdges.edges = {0, 1};
  EXPECT_EQ(io::writeMemory(Format::Off, withEdges, out).code, ErrorCode::InvalidArgument);

  Complex withTetra = smallMesh();
  withTetra.tetrahedra = {0, 1, 2, 3};
  EXPECT_EQ(io::writeMemory(Format::Obj, withTetra, out).code, ErrorCode::InvalidArgument);
  EXPECT_EQ(io::writeMemory(Format::Off, withTetra, out).code, ErrorCode::InvalidArgument);

  // Explicit points on vertices that triangles use: only OBJ keeps them.
  Complex pointOnFace = smallMesh();
  pointOnFace.points = {0};
  EXPECT_EQ(io::writeMemory(Format::Ply, pointOnFace, out).code, ErrorCode::InvalidArgument);
  EXPECT_EQ(io::writeMemory(Format::Off, pointOnFace, out).code, ErrorCode::InvalidArgument);
  EXPECT_TRUE(io::writeMemory(Format::Obj, pointOnFace, out).ok());
  // Points on isolated vertices are implicit everywhere.
  Complex isolatedPoint = smallMesh();
  isolatedPoint.points = {6};
  EXPECT_TRUE(io::writeMemory(Format::Ply, isolatedPoint, out).ok());
  EXPECT_TRUE(io::writeMemory(Format::Off, isolatedPoint, out).ok());

  // Invalid complexes are refused before any writer sees them.
  Complex badIndex = smallMesh();
  badIndex.triangles.back() = 7;
  for (const Target& target : kAllTargets) {
    const Status status = io::writeMemory(target.format, badIndex, out);
    EXPECT_EQ(status.code, ErrorCode::InvalidInput) << target.name;
    EXPECT_NE(status.message.find("triangle 7"), std::string::npos) << status.message;
    EXPECT_TRUE(out.empty());
  }
  Complex ragged = pointCloud({1, 2, 3, 4});
  EXPECT_EQ(io::writeMemory(Format::Xyz, ragged, out).code, ErrorCode::InvalidInput);
  EXPECT_EQ(io::writeMemory(Format::Unknown, mesh, out).code, ErrorCode::InvalidArgument);
}

TEST(IoRoundTrip, FilesOnDiskAndFileErrors) {
  namespace fs = std::filesystem;
  const fs::path dir =
      fs::temp_directory_path() /
      ("kdmesh_io_test_" + std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
  ASSERT_TRUE(fs::create_directories(dir));
  const Complex mesh = smallMesh();
  for (const char* name : {"m.ply", "m.OBJ", "m.off"}) {
    const std::string path = (dir / name).string();
    ASSERT_TRUE(io::writeFile(path, mesh).ok()) << path;
    Complex back;
    io::Notes notes;
    const Status status = io::readFile(path, back, notes);
    ASSERT_TRUE(status.ok()) << status.message;
    EXPECT_EQ(bitsOf(back.positions), bitsOf(mesh.positions)) << name;
    EXPECT_EQ(back.triangles, mesh.triangles) << name;
  }
  Complex back;
  io::Notes notes;
  const std::string missing = (dir / "missing.ply").string();
  Status status = io::readFile(missing, back, notes);
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message.find(missing), std::string::npos) << status.message;
  status = io::readFile((dir / "m.stl").string(), back, notes);
  EXPECT_EQ(status.code, ErrorCode::InvalidArgument);
  EXPECT_NE(status.message.find("m.stl"), std::string::npos) << status.message;
  EXPECT_EQ(io::writeFile((dir / "m.stl").string(), mesh).code, ErrorCode::InvalidArgument);
  EXPECT_FALSE(fs::exists(dir / "m.stl"));
  EXPECT_FALSE(io::writeFile((dir / "no" / "such" / "dir.ply").string(), mesh).ok());
  fs::remove_all(dir);
}

// ---------------------------------------------------------------------------
// PLY reader
// ---------------------------------------------------------------------------

TEST(IoPly, ReadsAsciiWithDoublesExtraPropertiesAndCrlf) {
  const std::string text =
      "ply\r\n"
      "format ascii 1.0\r\n"
      "comment made by hand\r\n"
      "obj_info nothing\r\n"
      "element vertex 4\r\n"
      "property double x\r\n"
      "property uchar red\r\n"
      "property double y\r\n"
      "property float z\r\n"
      "property float nx\r\n"
      "element face 2\r\n"
      "property list uchar int vertex_indices\r\n"
      "property uchar flags\r\n"
      "end_header\r\n"
      "0.1 255 +2 -0 9\r\n"
      "1.00000005960464477539062500000001 0 1e-45 3.4028235e38 9\r\n"
      "-1.5 0 0 0 9\r\n"
      "  1 1 1 1 1\r\n"
      "3 0 1 2 7\r\n"
      "4 0 1 2 3 7\r\n";
  const ReadResult r = readText(Format::Ply, text);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  const std::vector<float> expected = {0.1f, 2.0f,  -0.0f, floatOf(0x3f800001), floatOf(1),
                                       FLT_MAX, -1.5f, 0.0f,  0.0f,  1.0f, 1.0f, 1.0f};
  EXPECT_EQ(bitsOf(r.complex.positions), bitsOf(expected));
  EXPECT_EQ(r.complex.triangles, (std::vector<uint32_t>{0, 1, 2, 0, 1, 2, 0, 2, 3}));
  // Vertex properties besides the coordinates are kept as attributes.
  ASSERT_EQ(r.complex.attributes.size(), 2u);
  EXPECT_EQ(r.complex.attributes[0].name, "red");
  EXPECT_EQ(r.complex.attributes[0].values, (std::vector<uint8_t>{255, 0, 0, 1}));
  EXPECT_EQ(r.complex.attributes[1].name, "nx");
  EXPECT_EQ(r.complex.attributes[1].type, AttributeType::Float32);
  EXPECT_EQ(r.complex.attributes[1].values.size(), 16u);
  EXPECT_FALSE(r.hasNote("vertex properties")) << joined(r.notes);
  EXPECT_TRUE(r.hasNote("flags")) << joined(r.notes);
  EXPECT_TRUE(r.hasNote("double")) << joined(r.notes);
  EXPECT_TRUE(r.hasNote("split 1 polygon with")) << joined(r.notes);
  EXPECT_EQ(r.notes.size(), 3u) << joined(r.notes);

  // Values after the declared elements are noted, not dropped silently.
  const ReadResult extra = readText(Format::Ply, text + "3 3 2 1 0\n\n");
  ASSERT_TRUE(extra.status.ok()) << extra.status.message;
  EXPECT_EQ(extra.complex.triangles, r.complex.triangles);
  EXPECT_TRUE(extra.hasNote("ignored 5 values after the last PLY element")) << joined(extra.notes);
}

// The same cloud and faces in both byte orders, float or double
// coordinates, uchar or int list counts, with properties to skip around them.
std::vector<uint8_t> binaryPly(bool bigEndian, bool doubles, bool intCounts,
                               const std::vector<double>& xyz) {
  const size_t n = xyz.size() / 3;
  const char* type = doubles ? "double" : "float";
  PlyBuilder ply(bigEndian);
  ply.text("ply\nformat ")
      .text(bigEndian ? "binary_big_endian" : "binary_little_endian")
      .text(" 1.0\nelement vertex " + std::to_string(n) + "\n")
      .text("property uchar red\n")
      .text(std::string("property ") + type + " x\n")
      .text(std::string("property ") + type + " y\n")
      .text(std::string("property ") + type + " z\n")
      .text("property list uchar float uv\n")
      .text("property double quality\n")
      .text("element face 2\n")
      .text(std::string("property list ") + (intCounts ? "int" : "uchar") +
            " uint vertex_indices\n")
      .text("property short material\n")
      .text("end_header\n");
  for (size_t v = 0; v < n; ++v) {
    ply.put<uint8_t>(200);
    for (int a = 0; a < 3; ++a) {
      if (doubles) {
        ply.put<double>(xyz[3 * v + a]);
      } else {
        ply.put<float>(static_cast<float>(xyz[3 * v + a]));
      }
    }
    ply.put<uint8_t>(2).put<float>(0.25f).put<float>(0.5f).put<double>(1e300);
  }
  auto count = [&](int value) {
    if (intCounts) {
      ply.put<int32_t>(value);
    } else {
      ply.put<uint8_t>(static_cast<uint8_t>(value));
    }
  };
  count(3);
  ply.put<uint32_t>(2).put<uint32_t>(1).put<uint32_t>(0).put<int16_t>(-5);
  count(5);
  for (uint32_t i : {0u, 1u, 2u, 3u, 1u}) ply.put<uint32_t>(i);
  ply.put<int16_t>(-6);
  return ply.bytes();
}

TEST(IoPly, ReadsBinaryInBothByteOrdersWithFloatOrDoubleCoordinates) {
  // Doubles that are not floats, and one whose float rounding is a tie.
  const std::vector<double> xyz = {0.1, -2.5, 1e-40, 1.0 + std::ldexp(1.0, -24), 3.0, -0.0,
                                   -7.25, 1e10, 123.456, 4.0, 5.0, 6.0};
  for (bool bigEndian : {false, true}) {
    for (bool doubles : {false, true}) {
      for (bool intCounts : {false, true}) {
        SCOPED_TRACE(std::string(bigEndian ? "big" : "little") + (doubles ? " double" : " float") +
                     (intCounts ? " int counts" : " uchar counts"));
        const ReadResult r = readBytes(Format::Ply, binaryPly(bigEndian, doubles, intCounts, xyz));
        ASSERT_TRUE(r.status.ok()) << r.status.message;
        std::vector<float> expected(xyz.size());
        for (size_t i = 0; i < xyz.size(); ++i) expected[i] = static_cast<float>(xyz[i]);
        EXPECT_EQ(bitsOf(r.complex.positions), bitsOf(expected));
        EXPECT_EQ(bitsOf(r.complex.positions[3]), bitsOf(1.0f));  // tie to even
        EXPECT_EQ(r.complex.triangles,
                  (std::vector<uint32_t>{2, 1, 0, 0, 1, 2, 0, 2, 3, 0, 3, 1}));
        // red is kept as an attribute; a list (uv) and a double (quality) are not.
        EXPECT_TRUE(r.hasNote("ignored vertex properties: uv quality")) << joined(r.notes);
        ASSERT_EQ(r.complex.attributes.size(), 1u);
        EXPECT_EQ(r.complex.attributes[0].name, "red");
        EXPECT_EQ(r.complex.attributes[0].values, std::vector<uint8_t>(4, 200));
        EXPECT_TRUE(r.hasNote("material")) << joined(r.notes);
        EXPECT_TRUE(r.hasNote("split 1 polygon with")) << joined(r.notes);
        EXPECT_EQ(r.hasNote("double"), doubles) << joined(r.notes);
      }
    }
  }
}

TEST(IoPly, ReadsEdgeAndTetraElementsAndSkipsUnknownElements) {
  PlyBuilder ply;
  ply.text(
      "ply\nformat binary_little_endian 1.0\n"
      "element material 2\nproperty float shine\nproperty list uchar uchar name\n"
      "element vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
      "element edge 2\nproperty int vertex1\nproperty int vertex2\nproperty uchar red\n"
      "element tetrahedron 1\nproperty list uchar int vertex_indices\n"
      "end_header\n");
  ply.put<float>(0.5f).put<uint8_t>(3).put<uint8_t>('a').put<uint8_t>('b').put<uint8_t>('c');
  ply.put<float>(0.5f).put<uint8_t>(0);
  for (int i = 0; i < 15; ++i) ply.put<float>(static_cast<float>(i) * 0.5f);
  ply.put<int32_t>(0).put<int32_t>(4).put<uint8_t>(1);
  ply.put<int32_t>(3).put<int32_t>(2).put<uint8_t>(1);
  ply.put<uint8_t>(4).put<int32_t>(4).put<int32_t>(3).put<int32_t>(2).put<int32_t>(1);
  ply.text("xyz");  // trailing bytes
  const ReadResult r = readBytes(Format::Ply, ply.bytes());
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  EXPECT_EQ(r.complex.vertexCount(), 5u);
  EXPECT_EQ(r.complex.positions[14], 7.0f);
  EXPECT_EQ(r.complex.edges, (std::vector<uint32_t>{0, 4, 3, 2}));
  EXPECT_EQ(r.complex.tetrahedra, (std::vector<uint32_t>{4, 3, 2, 1}));
  EXPECT_TRUE(r.hasNote("skipped PLY element 'material'")) << joined(r.notes);
  EXPECT_TRUE(r.hasNote("ignored 3 bytes")) << joined(r.notes);
}

TEST(IoPly, HeaderErrorsNameTheLine) {
  struct Case {
    std::string text;
    std::vector<const char*> parts;
  };
  const std::string vertex =
      "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n";
  const std::vector<Case> cases = {
      {"plyx\nformat ascii 1.0\nend_header\n", {"not a PLY file"}},
      {"solid cube\n", {"not a PLY file"}},
      {"ply\n" + vertex + "end_header\n0 0 0\n", {"no format line"}},
      {"ply\nformat ascii 1.0\n" + vertex, {"no end_header"}},
      {"ply\nformat ascii 1.0\n" + vertex + "end_hea", {"line 7", "end_hea"}},
      {"ply\nformat binary_middle_endian 1.0\n" + vertex + "end_header\n",
       {"line 2", "binary_middle_endian"}},
      {"ply\nformat\n", {"line 2"}},
      {"ply\nformat ascii 1.0\nproperty float x\n", {"line 3", "before any element"}},
      {"ply\nformat ascii 1.0\nelement vertex -1\n", {"line 3"}},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\n", {"line 4", "float128"}},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty list float int x\n", {"line 4"}},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float\n", {"line 4"}},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "end_header\n0 0\n",
       {"vertex", "z"}},
      {"ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int vertex_indices\n"
       "end_header\n",
       {"no vertex element"}},
      {"ply\nformat ascii 1.0\n" + vertex + vertex + "end_header\n0 0 0\n0 0 0\n",
       {"two vertex elements"}},
      {"ply\nformat ascii 1.0\n" + vertex +
           "element face 1\nproperty list uchar float vertex_indices\nend_header\n0 0 0\n",
       {"vertex_indices", "integer"}},
      {"ply\nformat ascii 1.0\n" + vertex + "element face 1\nproperty uchar red\nend_header\n",
       {"face", "vertex_indices"}},
      {"ply\nformat ascii 1.0\n" + vertex + "bogus 3\nend_header\n", {"line 7", "bogus"}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    expectFailure(readText(Format::Ply, c.text), c.parts);
  }
}

TEST(IoPly, BodyErrorsNameTheElementAndPlace) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  expectFailure(readText(Format::Ply, header + "0 0 0\n1 abc 0\n2 2 2\n3 0 1 2\n"),
                {"vertex 1", "line 11", "'abc'"});
  expectFailure(readText(Format::Ply, header + "0 0 0\n1 1 0\n2 2 2\n3 0 1 3\n"),
                {"face 0", "index 3", "out of range"});
  expectFailure(readText(Format::Ply, header + "0 0 0\n1 1 0\n2 2 2\n3 0 -1 2\n"),
                {"face 0", "-1", "out of range"});
  expectFailure(readText(Format::Ply, header + "0 0 0\n1 1 0\n2 2 2\n2 0 1\n"),
                {"face 0", "has 2 vertices"});
  expectFailure(readText(Format::Ply, header + "0 0 0\n1 1 0\n2 2 2\n3 0 1.5 2\n"),
                {"face 0", "'1.5'", "not an integer"});
  expectFailure(readText(Format::Ply, header + "0 0 0\n1 1 0\n2 2 2\n3 0 1          \n"),
                {"face 0", "ends early"});
  expectFailure(readText(Format::Ply, header + "0 0 0\n1 1 0\n2 2 2\n200 0 1 2\n"),
                {"face 0", "does not fit"});

  // Tetrahedra have exactly four vertices.
  PlyBuilder tetra;
  tetra.text(
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
      "property float y\nproperty float z\nelement tetra 1\n"
      "property list uchar int vertex_indices\nend_header\n");
  tetra.put<float>(0).put<float>(0).put<float>(0).put<uint8_t>(5);
  for (int i = 0; i < 5; ++i) tetra.put<int32_t>(0);
  expectFailure(readBytes(Format::Ply, tetra.bytes()), {"tetra 0", "has 5 vertices", "exactly 4"});

  // A negative length of a skipped list.
  PlyBuilder negative;
  negative.text(
      "ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty float x\n"
      "property float y\nproperty float z\nproperty list int float junk\nend_header\n");
  negative.put<float>(0).put<float>(0).put<float>(0).put<int32_t>(-3);
  expectFailure(readBytes(Format::Ply, negative.bytes()), {"vertex 0", "negative"});
}

std::string binaryHeader(uint64_t vertices, uint64_t faces) {
  return "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
         std::to_string(faces) + "\nproperty list uchar int vertex_indices\nend_header\n";
}

TEST(IoPly, TruncatedBinaryFailsMidVertexAndMidFace) {
  PlyBuilder full;
  full.text(binaryHeader(3, 2));
  for (int i = 0; i < 9; ++i) full.put<float>(static_cast<float>(i));
  full.put<uint8_t>(4).put<int32_t>(0).put<int32_t>(1).put<int32_t>(2).put<int32_t>(0);
  full.put<uint8_t>(4).put<int32_t>(2).put<int32_t>(1).put<int32_t>(0).put<int32_t>(1);
  const std::vector<uint8_t>& bytes = full.bytes();
  ASSERT_TRUE(readBytes(Format::Ply, bytes).status.ok());
  const size_t body = binaryHeader(3, 2).size();

  // Mid-vertex: the declared counts no longer fit.
  std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + body + 17);
  expectFailure(readBytes(Format::Ply, cut), {"vertex", "3 items"});

  // Mid-face: the minimum size still fits (two triangles), the quads do not.
  cut.assign(bytes.begin(), bytes.end() - 5);
  expectFailure(readBytes(Format::Ply, cut), {"face 1", "byte", "4 indices"});
}

TEST(IoPly, HugeDeclaredCountsFailFastWithoutAllocating) {
  const auto start = std::chrono::steady_clock::now();
  auto padded = [](std::string text) {
    text.resize(std::max<size_t>(text.size(), 100), 'x');
    return bytesOf(text);
  };
  // 2^40 vertices in a 100-byte file: more than 32-bit indices address.
  expectFailure(readBytes(Format::Ply, padded(binaryHeader(uint64_t{1} << 40, 0))),
                {"1099511627776 vertices"});
  // 2^31 vertices and 2^40 faces: more than the file can hold.
  expectFailure(readBytes(Format::Ply, padded(binaryHeader(uint64_t{1} << 31, 0))),
                {"vertex", "2147483648", "more than the rest of the file"});
  expectFailure(readBytes(Format::Ply, padded(binaryHeader(1, uint64_t{1} << 40) +
                                              std::string(16, '\0'))),
                {"face", "1099511627776"});
  std::string ascii = binaryHeader(uint64_t{1} << 31, 0);
  ascii.replace(ascii.find("binary_little_endian"), 20, "ascii");
  expectFailure(readBytes(Format::Ply, padded(ascii)), {"vertex", "2147483648"});
  // A count beyond 64 bits is not a count.
  expectFailure(readBytes(Format::Ply, padded("ply\nformat ascii 1.0\n"
                                              "element vertex 99999999999999999999999\n")),
                {"line 3"});
  // A list claiming 2^32 - 1 indices.
  std::string header = binaryHeader(1, 1);
  header.replace(header.find("uchar int"), 9, "uint int");
  PlyBuilder hugeList;
  hugeList.text(header).put<float>(0).put<float>(0).put<float>(0).put<uint32_t>(0xffffffffu);
  for (int i = 0; i < 3; ++i) hugeList.put<int32_t>(0);
  expectFailure(readBytes(Format::Ply, hugeList.bytes()), {"face 0", "4294967295"});
  // An element with no properties and an enormous count holds no data: it
  // must not take a step per declared item.
  PlyBuilder empty;
  empty.text(
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
      "property float y\nproperty float z\nelement nothing 18446744073709551615\n"
      "end_header\n");
  empty.put<float>(1).put<float>(2).put<float>(3);
  const ReadResult r = readBytes(Format::Ply, empty.bytes());
  EXPECT_TRUE(r.status.ok()) << r.status.message;
  EXPECT_EQ(r.complex.vertexCount(), 1u);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 0.5);
}

// ---------------------------------------------------------------------------
// OBJ reader
// ---------------------------------------------------------------------------

TEST(IoObj, ReadsVerticesPointsLinesFacesAndCorners) {
  const std::string text =
      "# a comment\r\n"
      "mtllib x.mtl\r\n"
      "o thing\r\n"
      "v 0 0 0\r\n"
      "v 1.5 0 0 1.0\r\n"           // w: extra column
      "v 0 1e-45 0   # trailing\r\n"
      "v +0.1 -0 2\r\n"
      "g group\r\n"
      "usemtl red\r\n"
      "s off\r\n"
      "\r\n"
      "   \t\r\n"
      "f 1 2 3\r\n"
      "f 1 2 3 4\r\n"              // quad: fan of two triangles
      "f 4 3 2\r\n"
      "f -1 -2 -3\r\n"             // negative: counted back from the last vertex
      "l 1 2 3\r\n"                // polyline: two edges
      "l 4 -4\r\n"
      "p 2\r\n"
      "p 1 3\r\n"
      "curv 0 1 1 2\r\n"          // unknown keyword
      "v 9 9 9\r\n"
      "f -1 1 2#comment";          // no final newline
  const ReadResult r = readText(Format::Obj, text);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  const std::vector<float> expected = {0, 0, 0, 1.5f, 0, 0, 0, floatOf(1), 0,
                                       0.1f, -0.0f, 2, 9, 9, 9};
  EXPECT_EQ(bitsOf(r.complex.positions), bitsOf(expected));
  EXPECT_EQ(r.complex.triangles, (std::vector<uint32_t>{0, 1, 2, 0, 1, 2, 0, 2, 3, 3, 2, 1,
                                                          3, 2, 1, 4, 0, 1}));
  EXPECT_EQ(r.complex.edges, (std::vector<uint32_t>{0, 1, 1, 2, 3, 0}));
  EXPECT_EQ(r.complex.points, (std::vector<uint32_t>{1, 0, 2}));
  EXPECT_TRUE(r.hasNote("split 1 polygon with")) << joined(r.notes);
  EXPECT_TRUE(r.hasNote("extra columns")) << joined(r.notes);
  EXPECT_TRUE(r.hasNote("'curv' on line 21")) << joined(r.notes);
  // What the OBJ held that the complex does not, counted by keyword.
  EXPECT_TRUE(r.hasNote("1 object name (o), 1 smoothing group (s), 1 material library (mtllib)")) << joined(r.notes);
  EXPECT_TRUE(r.hasNote("ignored 1 group name (g): the materials (usemtl) are the simplex labels")) << joined(r.notes);
  EXPECT_TRUE(r.hasNote("ignored 1 line with unknown keywords")) << joined(r.notes);
  EXPECT_TRUE(r.complex.attributes.empty());
  // The material labels every line and face (all follow its usemtl).
  EXPECT_TRUE(r.hasNote("1 material (usemtl) of lines and faces as simplex labels, numbered in order of first use: 0 "
                        "'red'"))
      << joined(r.notes);
  EXPECT_EQ(r.complex.labels.triangles, std::vector<int32_t>(6, 0));
  EXPECT_EQ(r.complex.labels.edges, std::vector<int32_t>(3, 0));
  EXPECT_EQ(r.notes.size(), 6u) << joined(r.notes);
}

TEST(IoObj, BadIndicesAndTokensNameTheLine) {
  const std::string v3 = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  expectFailure(readText(Format::Obj, v3 + "f 1 2 4\n"), {"line 4", "index 4", "out of range"});
  expectFailure(readText(Format::Obj, v3 + "f 1 2 0\n"), {"line 4", "index 0"});
  expectFailure(readText(Format::Obj, v3 + "f 1 2 -4\n"), {"line 4", "-4"});
  expectFailure(readText(Format::Obj, "f 1 2 3\n" + v3), {"line 1", "out of range"});
  expectFailure(readText(Format::Obj, v3 + "f 1 2 99999999999999999999\n"), {"line 4"});
  expectFailure(readText(Format::Obj, v3 + "f 1 2 x\n"), {"line 4", "'x'"});
  expectFailure(readText(Format::Obj, v3 + "f 1 2 /3\n"), {"line 4", "'/3'"});
  expectFailure(readText(Format::Obj, v3 + "f 1 2\n"), {"line 4", "face has 2 vertices"});
  expectFailure(readText(Format::Obj, v3 + "l 1\n"), {"line 4", "line has 1 vertex,"});
  expectFailure(readText(Format::Obj, v3 + "p\n"), {"line 4", "point has 0"});
  expectFailure(readText(Format::Obj, v3 + "l 1 5\n"), {"line 4", "line vertex index 5"});
  expectFailure(readText(Format::Obj, v3 + "p 4\n"), {"line 4", "point vertex index 4"});
  expectFailure(readText(Format::Obj, "v 0 0\n"), {"line 1", "2 coordinates"});
  expectFailure(readText(Format::Obj, "v 0 0 0\nv 1 zero 0\n"), {"line 2", "'zero'"});
  expectFailure(readText(Format::Obj, "v 0 0 0x1\n"), {"line 1", "'0x1'"});
  expectFailure(readText(Format::Obj, "v 0 0 1e\n"), {"line 1", "'1e'"});
  expectFailure(readText(Format::Obj, "v 0 0 --1\n"), {"line 1"});
}

// ---------------------------------------------------------------------------
// OFF reader
// ---------------------------------------------------------------------------

TEST(IoOff, ReadsCommentsColoursPolygonsAndCountsOnTheKeywordLine) {
  const std::string text =
      "# leading comment\n"
      "OFF 4 3 0   # counts on the keyword line\n"
      "\n"
      "0 0 0\n"
      "# comment between vertices\n"
      "1 0 0 255 0 0\n"
      "0 1 0\n"
      "0 0 -1e-45\n"
      "3 0 1 2\n"
      "4 0 1 2 3 0.5 0.5 0.5\n"
      "3 3 2 1 # comment\n";
  const ReadResult r = readText(Format::Off, text);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  EXPECT_EQ(r.complex.vertexCount(), 4u);
  EXPECT_EQ(bitsOf(r.complex.positions[11]), 0x80000001u);
  EXPECT_EQ(r.complex.triangles,
            (std::vector<uint32_t>{0, 1, 2, 0, 1, 2, 0, 2, 3, 3, 2, 1}));
  EXPECT_TRUE(r.hasNote("split 1 polygon with")) << joined(r.notes);
  EXPECT_TRUE(r.hasNote("colour values on 1 face")) << joined(r.notes);
  EXPECT_TRUE(r.hasNote("on 1 vertex")) << joined(r.notes);

  // Counts on their own line, CRLF, a variant keyword.
  const ReadResult crlf = readText(Format::Off, "COFF\r\n3 1\r\n0 0 0 1 1 1 1\r\n1 0 0 1 1 1 1\r\n"
                                                "0 1 0 1 1 1 1\r\n3 0 1 2\r\n");
  ASSERT_TRUE(crlf.status.ok()) << crlf.status.message;
  EXPECT_EQ(crlf.complex.triangles, (std::vector<uint32_t>{0, 1, 2}));
}

TEST(IoOff, WrongCountsAndBadFacesNameTheLine) {
  expectFailure(readText(Format::Off, "OFF\n3 1 0\n0 0 0\n1 0 0\n"),
                {"more than the rest of the file"});
  expectFailure(readText(Format::Off, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n# padding\n"),
                {"ends after 0 of 1 face"});
  // Too few vertex lines: the face is read as a vertex.
  expectFailure(readText(Format::Off, "OFF\n3 1 0\n0 0 0\n1 0 0\n3 0 1 2\n# padding\n"),
                {"ends after 0 of 1 face"});
  expectFailure(readText(Format::Off, "OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n"),
                {"line 4", "vertex has 2 coordinates"});
  // One vertex more than declared: it is read as a face.
  expectFailure(readText(Format::Off, "OFF\n2 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
                {"line 5", "face 0", "has 0 vertices"});
  // More faces than declared are noted, not dropped silently.
  const ReadResult extra = readText(Format::Off,
                                    "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n# c\n3 2 1 0\n");
  ASSERT_TRUE(extra.status.ok()) << extra.status.message;
  EXPECT_EQ(extra.complex.triangles, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_TRUE(extra.hasNote("ignored 1 line after the 1 face that")) << joined(extra.notes);
  EXPECT_TRUE(extra.hasNote("line 8")) << joined(extra.notes);
  expectFailure(readText(Format::Off, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"),
                {"line 6", "face 0", "index 3", "out of range"});
  expectFailure(readText(Format::Off, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -2\n"),
                {"line 6", "face 0", "'-2'"});
  expectFailure(readText(Format::Off, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n"),
                {"line 6", "face 0"});
  expectFailure(readText(Format::Off, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3.0 0 1 2\n"),
                {"line 6", "'3.0'"});
  expectFailure(readText(Format::Off, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n9999999 0 1 2\n"),
                {"line 6", "face 0"});
  expectFailure(readText(Format::Off, "OFF\n3 0 0\n0 0 0\n1 zero 0\n0 1 0\n"),
                {"line 4", "'zero'"});
  expectFailure(readText(Format::Off, "OFF\n3\n"), {"vertex and face counts"});
  expectFailure(readText(Format::Off, "OFF\n-3 0\n"), {"vertex and face counts"});
  expectFailure(readText(Format::Off, "4OFF\n1 0 0\n0 0 0 0\n"), {"line 1", "'4OFF'"});
  expectFailure(readText(Format::Off, "ply\n"), {"line 1", "not an OFF file"});
  expectFailure(readText(Format::Off, "# only a comment\n"), {"no header"});
  // Huge counts fail at once.
  expectFailure(readText(Format::Off, "OFF\n4294967296 0 0\n0 0 0\n"), {"32-bit"});
  expectFailure(readText(Format::Off, "OFF\n1000000000 1000000000 0\n0 0 0\n"),
                {"1000000000 vertices"});
}

// ---------------------------------------------------------------------------
// XYZ reader
// ---------------------------------------------------------------------------

TEST(IoXyz, ReadsCommasExtraColumnsCommentsAndCrlf) {
  const std::string text =
      "# x y z r g b\r\n"
      "1,2,3\r\n"
      "4, 5, 6, 255, 0, 0\r\n"
      "\r\n"
      "  7\t8   9 # comment\r\n"
      "-0.0 1e-45 3.4028235e+38 1 2\r\n"
      "0.1,0.2,0.3";
  const ReadResult r = readText(Format::Xyz, text);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  const std::vector<float> expected = {1, 2, 3, 4, 5, 6, 7, 8, 9, -0.0f, floatOf(1), FLT_MAX,
                                       0.1f, 0.2f, 0.3f};
  EXPECT_EQ(bitsOf(r.complex.positions), bitsOf(expected));
  EXPECT_TRUE(r.hasNote("ignored extra columns on 2 lines")) << joined(r.notes);
  EXPECT_FALSE(r.complex.hasSimplices());
}

TEST(IoXyz, BadLinesNameTheLine) {
  expectFailure(readText(Format::Xyz, "1 2 3\n4 5\n"), {"line 2", "2 coordinates"});
  expectFailure(readText(Format::Xyz, "1 2 3\n\n# c\n4 5 six\n"), {"line 4", "'six'"});
  expectFailure(readText(Format::Xyz, "x y z\n1 2 3\n"), {"line 1", "'x'"});
  expectFailure(readText(Format::Xyz, "1;2;3\n"), {"line 1"});
  expectFailure(readText(Format::Xyz, "1 2 3\n\x01\x02\x03\xff\n"), {"line 2"});
  // A very long token is shortened in the message.
  const ReadResult r = readText(Format::Xyz, "1 2 " + std::string(5000, 'q') + "\n");
  expectFailure(r, {"line 1", "..."});
  EXPECT_LT(r.status.message.size(), 200u);
}

// ---------------------------------------------------------------------------
// Numbers
// ---------------------------------------------------------------------------

float parsed(const std::string& text) {
  float value = -12345.0f;
  EXPECT_TRUE(io::detail::parseFloat(text, value)) << text;
  return value;
}

TEST(IoNumbers, FloatsAreRoundedOnceToNearestEven) {
  EXPECT_EQ(bitsOf(parsed("0.1")), bitsOf(0.1f));
  EXPECT_EQ(bitsOf(parsed("0.1")), 0x3dcccccdu);
  EXPECT_EQ(bitsOf(parsed("-0")), 0x80000000u);
  EXPECT_EQ(bitsOf(parsed("+1.5")), bitsOf(1.5f));
  EXPECT_EQ(bitsOf(parsed("1.")), bitsOf(1.0f));
  EXPECT_EQ(bitsOf(parsed(".5")), bitsOf(0.5f));
  EXPECT_EQ(bitsOf(parsed("1E+2")), bitsOf(100.0f));
  // Exactly halfway between 1 and its successor: ties to the even 1.
  EXPECT_EQ(bitsOf(parsed("1.000000059604644775390625")), 0x3f800000u);
  // Halfway between 1 + 2^-23 (odd) and 1 + 2^-22 (even): up to the even one.
  EXPECT_EQ(bitsOf(parsed("1.000000178813934326171875")), 0x3f800002u);
  // Halfway between 2^24 + 2 (odd mantissa) and 2^24 + 4: to the even one.
  EXPECT_EQ(bitsOf(parsed("16777219")), bitsOf(16777220.0f));
  EXPECT_EQ(bitsOf(parsed("16777217")), bitsOf(16777216.0f));
  // Just above the tie: a parser going through double first lands on the
  // tie and then rounds to even; rounding once gives the successor.
  EXPECT_EQ(bitsOf(parsed("1.00000005960464477539062500000001")), 0x3f800001u);
  EXPECT_EQ(bitsOf(parsed("1.0000000596046447753906249999999")), 0x3f800000u);
  EXPECT_EQ(bitsOf(parsed("16777217.000000000000000001")), bitsOf(16777218.0f));
  // Denormals and the ends of the range.
  EXPECT_EQ(bitsOf(parsed("1e-45")), 1u);
  EXPECT_EQ(bitsOf(parsed("1.4012984643248171e-45")), 1u);
  EXPECT_EQ(bitsOf(parsed("7.1e-46")), 1u);             // above half the denormal
  EXPECT_EQ(bitsOf(parsed("7e-46")), 0u);               // below: zero
  EXPECT_EQ(bitsOf(parsed("-1e-50")), 0x80000000u);     // signed zero
  EXPECT_EQ(bitsOf(parsed("0.000001e-50")), 0u);
  EXPECT_EQ(bitsOf(parsed("1e-99999999999999999999")), 0u);
  EXPECT_EQ(bitsOf(parsed("1.17549435e-38")), bitsOf(FLT_MIN));
  EXPECT_EQ(bitsOf(parsed("3.4028235e38")), bitsOf(FLT_MAX));
  EXPECT_EQ(bitsOf(parsed("3.40282356e38")), bitsOf(FLT_MAX));  // below the halfway point
  EXPECT_EQ(bitsOf(parsed("3.4028236e38")), bitsOf(INFINITY));  // past it
  EXPECT_EQ(bitsOf(parsed("-1e39")), bitsOf(-INFINITY));
  EXPECT_EQ(bitsOf(parsed("1e99999999999999999999")), bitsOf(INFINITY));
  EXPECT_EQ(bitsOf(parsed("1000000000000000000000000000000000000000")), bitsOf(INFINITY));
  EXPECT_EQ(bitsOf(parsed("0.00000000000000000000000000000000000000000000001")), 0u);
  // Every float read back from its shortest and its 9-digit form.
  std::mt19937 rng(7);
  for (int i = 0; i < 20000; ++i) {
    const float f = floatOf(static_cast<uint32_t>(rng()));
    if (std::isnan(f)) continue;
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.9g", static_cast<double>(f));
    ASSERT_EQ(bitsOf(parsed(buffer)), bitsOf(f)) << buffer;
  }
}

TEST(IoNumbers, NanAndInfinityParseAndOnlyTheGridRejectsThem) {
  EXPECT_TRUE(std::isnan(parsed("nan")));
  EXPECT_TRUE(std::isnan(parsed("NaN")));
  EXPECT_TRUE(std::isnan(parsed("-nan")));
  EXPECT_EQ(bitsOf(parsed("inf")), bitsOf(INFINITY));
  EXPECT_EQ(bitsOf(parsed("-Infinity")), bitsOf(-INFINITY));
  EXPECT_EQ(bitsOf(parsed("+inf")), bitsOf(INFINITY));

  const ReadResult r = readText(Format::Xyz, "0 0 0\n1 nan 2\n");
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  ASSERT_EQ(r.complex.vertexCount(), 2u);
  EXPECT_TRUE(std::isnan(r.complex.positions[4]));
  const EncodeResult encoded = encode(r.complex);
  EXPECT_EQ(encoded.status.code, ErrorCode::InvalidInput);
  EXPECT_NE(encoded.status.message.find("vertex 1"), std::string::npos)
      << encoded.status.message;
  EncodeOptions exact;
  exact.exact = true;
  EXPECT_TRUE(encode(r.complex, exact).status.ok());
}

TEST(IoNumbers, MalformedNumbersAreRejected) {
  for (const char* text : {"", "+", "-", ".", "e5", "1e", "1e+", "1.5x", "0x10", "1,5", "--1",
                           "+-1", "++1", " 1", "1 ", "nanx", "in", "1..2", "1e5.5"}) {
    float value = 0;
    EXPECT_FALSE(io::detail::parseFloat(text, value)) << "'" << text << "'";
  }
  int64_t integer = 0;
  EXPECT_TRUE(io::detail::parseInteger("-17", integer));
  EXPECT_EQ(integer, -17);
  EXPECT_TRUE(io::detail::parseInteger("+17", integer));
  EXPECT_EQ(integer, 17);
  for (const char* text : {"", "1.0", "1e3", "x", "99999999999999999999", "+-1", "0x1"}) {
    EXPECT_FALSE(io::detail::parseInteger(text, integer)) << "'" << text << "'";
  }
  uint64_t count = 0;
  EXPECT_TRUE(io::detail::parseCount("18446744073709551615", count));
  EXPECT_EQ(count, UINT64_MAX);
  for (const char* text : {"", "-1", "18446744073709551616", "1.0", "+-1"}) {
    EXPECT_FALSE(io::detail::parseCount(text, count)) << "'" << text << "'";
  }
}

// ---------------------------------------------------------------------------
// Bad input in general
// ---------------------------------------------------------------------------

TEST(IoBadInput, EmptyAndBlankFilesFailInEveryFormat) {
  for (Format format : {Format::Ply, Format::Obj, Format::Off, Format::Xyz}) {
    SCOPED_TRACE(io::formatName(format));
    for (const std::string& text : {std::string(), std::string(" \t\r\n\n  \r\n\f\v")}) {
      expectFailure(readText(format, text), {"empty"});
    }
    Complex out = smallMesh();  // replaced, not appended to
    io::Notes notes;
    EXPECT_FALSE(io::readMemory(format, nullptr, 0, out, notes).ok());
    EXPECT_EQ(out.vertexCount(), 0u);
  }
  Complex out;
  io::Notes notes;
  const std::vector<uint8_t> bytes = bytesOf("1 2 3\n");
  EXPECT_EQ(io::readMemory(Format::Unknown, bytes.data(), bytes.size(), out, notes).code,
            ErrorCode::InvalidArgument);
}

TEST(IoBadInput, ReadReplacesTheOutputAndClearsItOnError) {
  Complex out = smallMesh();
  io::Notes notes;
  const std::vector<uint8_t> good = bytesOf("1 2 3\n");
  ASSERT_TRUE(io::readMemory(Format::Xyz, good.data(), good.size(), out, notes).ok());
  EXPECT_EQ(out.vertexCount(), 1u);
  EXPECT_TRUE(out.triangles.empty());
  const std::vector<uint8_t> bad = bytesOf("1 2 3\n4 5 6\n7 8\n");
  EXPECT_FALSE(io::readMemory(Format::Xyz, bad.data(), bad.size(), out, notes).ok());
  EXPECT_EQ(out.vertexCount(), 0u);
}

std::vector<uint8_t> sampleMeshBytes(Format format, bool asciiPly) {
  Complex c = smallMesh();
  c.positions.insert(c.positions.end(), {0.25f, -0.5f, 1e-40f});
  if (format != Format::Off) c.edges = {6, 7, 7, 0};
  if (format == Format::Ply) c.tetrahedra = {0, 1, 2, 7};
  if (format == Format::Obj) c.points = {6};
  std::vector<uint8_t> bytes;
  io::WriteOptions options;
  options.asciiPly = asciiPly;
  EXPECT_TRUE(io::writeMemory(format, c, bytes, options).ok());
  return bytes;
}

TEST(IoBadInput, TruncationAtEveryLengthReadsOrFailsCleanly) {
  struct Case {
    const char* name;
    Format format;
    bool asciiPly;
    bool everyPrefixFails;  // binary data has an exact size
  };
  for (const Case& c : {Case{"ply binary", Format::Ply, false, true},
                        Case{"ply ascii", Format::Ply, true, false},
                        Case{"obj", Format::Obj, false, false},
                        Case{"off", Format::Off, false, false}}) {
    SCOPED_TRACE(c.name);
    const std::vector<uint8_t> full = sampleMeshBytes(c.format, c.asciiPly);
    const ReadResult whole = readBytes(c.format, full);
    ASSERT_TRUE(whole.status.ok()) << whole.status.message;
    size_t succeeded = 0;
    for (size_t length = 0; length < full.size(); ++length) {
      // A copy of exactly `length` bytes, so that reading past it is caught
      // by sanitizers.
      const std::vector<uint8_t> prefix(full.begin(), full.begin() + length);
      const ReadResult r = readBytes(c.format, prefix);
      if (r.status.ok()) {
        ++succeeded;
        EXPECT_FALSE(c.everyPrefixFails) << "length " << length;
        expectValidIndices(r.complex);
        EXPECT_LE(r.complex.vertexCount(), whole.complex.vertexCount());
      } else {
        EXPECT_EQ(r.status.code, ErrorCode::InvalidInput) << "length " << length;
        EXPECT_FALSE(r.status.message.empty()) << "length " << length;
        EXPECT_EQ(r.status.message.find('\n'), std::string::npos) << r.status.message;
        EXPECT_EQ(r.complex.vertexCount(), 0u);
      }
    }
    if (c.format == Format::Obj) {
      EXPECT_GT(succeeded, 0u);
    }
  }
}

TEST(IoBadInput, CorruptedBytesReadOrFailCleanly) {
  // Every byte of a binary PLY and an OBJ replaced by a few values; for the
  // PLY, also every pair of adjacent bytes with 0xff.
  for (Format format : {Format::Ply, Format::Obj}) {
    SCOPED_TRACE(io::formatName(format));
    const std::vector<uint8_t> full = sampleMeshBytes(format, false);
    for (size_t i = 0; i < full.size(); ++i) {
      for (uint8_t value : {0x00, 0x0a, 0x20, 0x2d, 0x39, 0xff}) {
        std::vector<uint8_t> bytes = full;
        bytes[i] = value;
        if (format == Format::Ply && i + 1 < bytes.size() && value == 0xff) bytes[i + 1] = 0xff;
        const ReadResult r = readBytes(format, bytes);
        if (r.status.ok()) {
          expectValidIndices(r.complex);
        } else {
          EXPECT_FALSE(r.status.message.empty());
          EXPECT_EQ(r.complex.vertexCount(), 0u);
        }
      }
    }
  }
}

// ---------------------------------------------------------------------------
// Formats by name
// ---------------------------------------------------------------------------

TEST(IoFormat, FromPathByExtensionCaseInsensitively) {
  const struct {
    const char* path;
    Format format;
  } cases[] = {
      {"a.ply", Format::Ply},
      {"A.PLY", Format::Ply},
      {"dir/model.Obj", Format::Obj},
      {"x.off", Format::Off},
      {"cloud.xyz", Format::Xyz},
      {"cloud.txt", Format::Xyz},
      {"cloud.PTS", Format::Xyz},
      {"/tmp/a.b.c.ply", Format::Ply},
      {"C:\\models\\bunny.OFF", Format::Off},
      {"relative/../x.ply", Format::Ply},
      {".ply", Format::Ply},
      {"", Format::Unknown},
      {"noextension", Format::Unknown},
      {"trailingdot.", Format::Unknown},
      {"model.ply.gz", Format::Unknown},
      {"model.kdm", Format::Unknown},
      {"model.3mf", Format::Unknown},
      {"model.plyx", Format::Unknown},
      {"model.pl", Format::Unknown},
      {"dir.ply/file", Format::Unknown},
      {"dir.obj\\file", Format::Unknown},
  };
  for (const auto& c : cases) {
    EXPECT_EQ(io::formatFromPath(c.path), c.format) << "'" << c.path << "'";
  }
  EXPECT_STREQ(io::formatName(Format::Ply), "ply");
  EXPECT_STREQ(io::formatName(Format::Obj), "obj");
  EXPECT_STREQ(io::formatName(Format::Off), "off");
  EXPECT_STREQ(io::formatName(Format::Xyz), "xyz");
  EXPECT_STREQ(io::formatName(Format::Unknown), "unknown");
}

}  // namespace
}  // namespace kdmesh::test
