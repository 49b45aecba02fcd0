// Vertex attributes through the file formats other than PLY (test_attributes.cpp
// covers PLY): what each reader makes of a file's per-vertex data, and files
// written and read back with every vertex's position and values bit-exact,
// up to vertex order.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "attribute_support.h"
#include "complexes.h"
#include "io_test_support.h"
#include "io/io_internal.h"
#include "kdmesh/io.h"
#include "test_support.h"

namespace kdmesh::test {
namespace {

using io::Format;

// A torus of rows x columns quads textured by its grid: the vertices of the
// closing column and row are copies of the first ones' positions with
// u = 1 or v = 1 (two seams), and every vertex has a unit normal.
Complex texturedTorus(int rows, int columns) {
  const Complex torus = torusMesh(rows, columns);
  Complex c;
  std::vector<float> uv, normal;
  auto id = [columns](int i, int j) { return uint32_t(j * (columns + 1) + i); };
  for (int j = 0; j <= rows; ++j)
    for (int i = 0; i <= columns; ++i) {
      const float* p = &torus.positions[3 * size_t((j % rows) * columns + i % columns)];
      c.positions.insert(c.positions.end(), p, p + 3);
      uv.insert(uv.end(), {float(i) / float(columns), float(j) / float(rows)});
      // The normal of the torus (R = 3, r = 1): from the tube's centre.
      const float a = std::atan2(p[1], p[0]);
      const float n[3] = {p[0] - 3.f * std::cos(a), p[1] - 3.f * std::sin(a), p[2]};
      const float length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      for (const float x : n) normal.push_back(x / length);
    }
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < columns; ++i) {
      const uint32_t a = id(i, j), b = id(i + 1, j), d = id(i, j + 1), e = id(i + 1, j + 1);
      c.triangles.insert(c.triangles.end(), {a, b, e, a, e, d});
    }
  c.attributes = {attribute("uv", AttributeType::Float32, 2, uv), attribute("normal", AttributeType::Float32, 3, normal)};
  return c;
}

// A vertex's key (position and values) of every simplex, each simplex
// rotated to start at its least key (triangles keep their orientation,
// edges are sorted), then sorted, plus every vertex as a point: the
// complex up to vertex order.
std::vector<std::vector<VertexKey>> keyedForm(const Complex& c) {
  const std::vector<VertexKey> keys = vertexKeys(c);
  std::vector<std::vector<VertexKey>> out;
  for (const VertexKey& key : keys) out.push_back({key});
  for (size_t i = 0; i < c.edges.size(); i += 2) {
    std::vector<VertexKey> e = {keys[c.edges[i]], keys[c.edges[i + 1]]};
    std::sort(e.begin(), e.end());
    out.push_back(e);
  }
  for (size_t i = 0; i < c.triangles.size(); i += 3) {
    std::vector<VertexKey> t = {keys[c.triangles[i]], keys[c.triangles[i + 1]], keys[c.triangles[i + 2]]};
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    out.push_back(t);
  }
  std::sort(out.begin(), out.end());
  return out;
}

// Written in `format` and read back: the same attributes and, up to vertex
// order, the same vertices with the same values and the same simplices.
void expectFileRoundTrip(Format format, const Complex& c) {
  const ReadResult back = writeThenRead(format, c);
  ASSERT_TRUE(back.status.ok()) << back.status.message;
  expectSameDescriptors(c, back.complex);
  EXPECT_EQ(back.complex.vertexCount(), c.vertexCount());
  EXPECT_TRUE(keyedForm(back.complex) == keyedForm(c)) << "the complex read back differs";
}

std::vector<float> floats(const VertexAttribute& a) {
  std::vector<float> out(a.values.size() / 4);
  std::memcpy(out.data(), a.values.data(), a.values.size());
  return out;
}

// ---------------------------------------------------------------------------
// OBJ
// ---------------------------------------------------------------------------

TEST(AttributeIoObj, EveryCornerTripleIsAVertexOfItsOwn) {
  const std::string text =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nv 1 1 0\n"
      "vt 0 0\nvt 1 0\nvt 0 1\nvt 0.5 0.5\nvt 9 9\n"
      "vn 0 0 1\nvn 0 0 -1\n"
      "f 1/1/1 2/2/1 3/3/1\n"
      "f 2/4/2 -1/2/2 3/3/2\n"   // vertex 2 again, with other values: a seam
      "f 1/1/1 2/2/1 5\n"        // a bare corner: values 0
      "l 3/3/1 5\n";
  const ReadResult r = readText(Format::Obj, text);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  // Positions used bare or by nothing come first in file order (4 and 5),
  // then the triples as they first appear.
  const std::vector<float> positions = {5, 5, 5, 1, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  EXPECT_EQ(bitsOf(r.complex.positions), bitsOf(positions));
  ASSERT_EQ(r.complex.attributes.size(), 2u);
  EXPECT_EQ(r.complex.attributes[0].name, "uv");
  EXPECT_EQ(r.complex.attributes[0].components, 2);
  EXPECT_EQ(floats(r.complex.attributes[0]), (std::vector<float>{0, 0, 0, 0, 0, 0, 1, 0, 0, 1, 0.5f, 0.5f, 1, 0, 0, 1}));
  EXPECT_EQ(r.complex.attributes[1].name, "normal");
  EXPECT_EQ(floats(r.complex.attributes[1]),
            (std::vector<float>{0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, -1, 0, 0, -1, 0, 0, -1}));
  EXPECT_EQ(r.complex.triangles, (std::vector<uint32_t>{2, 3, 4, 5, 6, 7, 2, 3, 1}));
  EXPECT_EQ(r.complex.edges, (std::vector<uint32_t>{4, 1}));
  EXPECT_TRUE(r.hasNote("ignored 1 texture coordinate (vt) that no corner names")) << joined(r.notes);
  EXPECT_EQ(r.notes.size(), 1u) << joined(r.notes);

  // w makes uv three components; a vt line with u alone has v = 0.
  const ReadResult w = readText(Format::Obj, "v 0 0 0\nv 1 0 0\nvt 0.25\nvt 1 2 3\nl 1/1 2/2\n");
  ASSERT_TRUE(w.status.ok()) << w.status.message;
  ASSERT_EQ(w.complex.attributes.size(), 1u);
  EXPECT_EQ(w.complex.attributes[0].components, 3);
  EXPECT_EQ(floats(w.complex.attributes[0]), (std::vector<float>{0.25f, 0, 0, 1, 2, 3}));

  // Without vt or vn corners the vertices are the v lines, as in any OBJ.
  const ReadResult plain = readText(Format::Obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 3 2 1\n");
  ASSERT_TRUE(plain.status.ok()) << plain.status.message;
  EXPECT_TRUE(plain.complex.attributes.empty());
  EXPECT_EQ(plain.complex.triangles, (std::vector<uint32_t>{2, 1, 0}));
  EXPECT_TRUE(plain.hasNote("ignored 1 normal (vn) that no corner names")) << joined(plain.notes);
}

TEST(AttributeIoObj, BadCornersAndValuesNameTheLine) {
  const std::string v3 = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n";
  expectFailure(readText(Format::Obj, v3 + "f 1/2 2/1 3/1\n"),
                {"line 6", "texture coordinate index 2 is out of range", "vt lines from 1", "1 defined so far"});
  expectFailure(readText(Format::Obj, v3 + "f 1//2 2//1 3//1\n"), {"line 6", "normal index 2", "vn lines"});
  expectFailure(readText(Format::Obj, v3 + "f 1/1/1/1 2 3\n"), {"line 6", "more than three indices"});
  expectFailure(readText(Format::Obj, v3 + "f 1/x 2 3\n"), {"line 6", "'1/x' is not a texture coordinate index"});
  expectFailure(readText(Format::Obj, v3 + "f 1/1/y 2 3\n"), {"line 6", "not a normal index"});
  expectFailure(readText(Format::Obj, "f 1/1/1 2 3\n" + v3), {"line 1", "vertex index 1 is out of range"});
  expectFailure(readText(Format::Obj, "vt\n"), {"line 1", "vt has 0 values, needs 1"});
  expectFailure(readText(Format::Obj, "vn 0 1\n"), {"line 1", "vn has 2 values, needs 3"});
  expectFailure(readText(Format::Obj, "vt 0 0 0 0\n"), {"line 1", "more than 3 values"});
  expectFailure(readText(Format::Obj, "vn 0 a 0\n"), {"line 1", "'a' is not a number"});
}

TEST(AttributeIoObj, SeamsNormalsAndUvRoundTripExactly) {
  expectFileRoundTrip(Format::Obj, texturedTorus(6, 9));
  // Without normals, and with three texture coordinates.
  Complex uvOnly = texturedTorus(3, 4);
  uvOnly.attributes.pop_back();
  expectFileRoundTrip(Format::Obj, uvOnly);
  Complex uvw = uvOnly;
  std::vector<float> w;
  for (size_t v = 0; v < uvw.vertexCount(); ++v) w.insert(w.end(), {float(v), -0.0f, 1e-40f});
  uvw.attributes = {attribute("uv", AttributeType::Float32, 3, w)};
  expectFileRoundTrip(Format::Obj, uvw);

  // Edges, listed and unlisted isolated vertices with values of their own,
  // and two vertices alike in position and values (they stay two).
  Complex mixed = pointCloud({0, 0, 0, 1, 0, 0, 1, 0, 0, 0, 1, 0, 2, 2, 2, 2, 2, 2, 3, 3, 3});
  mixed.points.clear();
  mixed.edges = {0, 1, 2, 3, 0, 3};
  mixed.triangles = {4, 0, 1};
  mixed.points = {5};
  mixed.attributes = {attribute("normal", AttributeType::Float32, 3,
                                std::vector<float>{0, 0, 1, 0, 0, 1, 0, 1, 0, 1, 0, 0, 0, 0, 1, 0, 0, 1, 0.5f, 0, 0})};
  expectFileRoundTrip(Format::Obj, mixed);

  // Through the codec: the decoded complex written as OBJ reads back the same.
  const Complex torus = texturedTorus(5, 7);
  EncodeOptions exact;
  exact.exact = true;
  expectRoundTrip(torus, exact);
  Complex decoded;
  const EncodeResult encoded = encode(torus, exact);
  ASSERT_TRUE(encoded.status.ok()) << encoded.status.message;
  ASSERT_TRUE(decode(encoded.bytes.data(), encoded.bytes.size(), decoded).ok());
  expectFileRoundTrip(Format::Obj, decoded);
}

TEST(AttributeIoObj, WritesSharedCornersOnceAndRefusesOtherAttributes) {
  const Complex torus = texturedTorus(2, 3);
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(io::writeMemory(Format::Obj, torus, bytes).ok());
  const std::string text(bytes.begin(), bytes.end());
  auto lines = [&text](const std::string& start) {
    size_t count = 0;
    for (size_t at = 0; (at = text.find("\n" + start + " ", at)) != std::string::npos; ++at) ++count;
    return count;
  };
  // 2 x 3 distinct positions; (3 + 1) x (2 + 1) texture coordinates; the
  // normals of the seam copies equal the originals'.
  EXPECT_EQ(lines("v"), 6u) << text;
  EXPECT_EQ(lines("vt"), 12u) << text;
  EXPECT_EQ(lines("vn"), 6u) << text;
  EXPECT_NE(text.find("\nf 1/1/1 2/2/2 "), std::string::npos) << text;

  Complex coloured = torus;
  coloured.attributes.push_back(attribute("color", AttributeType::UInt8, 3, std::vector<uint8_t>(3 * torus.vertexCount())));
  const Status refused = io::writeMemory(Format::Obj, coloured, bytes);
  EXPECT_EQ(refused.code, ErrorCode::InvalidArgument);
  EXPECT_NE(refused.message.find("cannot hold the vertex attributes color: write PLY"), std::string::npos)
      << refused.message;
}

// ---------------------------------------------------------------------------
// VTK
// ---------------------------------------------------------------------------

const std::string kVtkTriangle =
    "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 3 float\n0 0 0 1 0 0 0 1 0\n"
    "POLYGONS 1 4\n3 0 1 2\n";

TEST(AttributeIoVtk, PointDataArraysBecomeAttributes) {
  std::string tensor;  // 9 components per point
  for (int i = 0; i < 27; ++i) tensor += "0 ";
  const std::string text = kVtkTriangle +
                           "POINT_DATA 3\n"
                           "SCALARS temperature double\n"  // no component count, no lookup table
                           "1.5 2.5 1e300\n"
                           "SCALARS pair short 2\nLOOKUP_TABLE default\n-1 2 -3 4 -5 32767\n"
                           "COLOR_SCALARS rgb 3\n1 0 0.5 0 1 0 0.2 0.4 1\n"
                           "VECTORS velocity float\n1 2 3 4 5 6 7 8 9\n"
                           "NORMALS Normals float\n0 0 1 0 0 1 0 0 -1\n"
                           "TEXTURE_COORDINATES TCoords 2 float\n0 0 1 0 0 1\n"
                           "TENSORS stress float\n" + tensor + "\n" +
                           "LOOKUP_TABLE my_table 1\n0 0 0 1\n"
                           "GLOBAL_IDS ids vtkIdType\n0 70000 2\n"
                           "FIELD FieldData 2\nweight 1 3 unsigned_char\n7 8 9\ntoo_long 1 4 float\n1 2 3 4\n"
                           "CELL_DATA 1\nSCALARS region int\n5\n";
  const ReadResult r = readText(Format::Vtk, text);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  std::vector<std::string> names;
  for (const VertexAttribute& a : r.complex.attributes) names.push_back(a.name);
  EXPECT_EQ(names, (std::vector<std::string>{"temperature", "pair", "color", "velocity", "normal", "uv", "ids",
                                             "weight"}));
  ASSERT_EQ(r.complex.attributes.size(), 8u);
  const std::vector<VertexAttribute>& a = r.complex.attributes;
  EXPECT_EQ(floats(a[0]), (std::vector<float>{1.5f, 2.5f, std::numeric_limits<float>::infinity()}));
  EXPECT_EQ(a[1].type, AttributeType::Int16);
  EXPECT_EQ(a[1].components, 2);
  EXPECT_EQ(a[1].values, (std::vector<uint8_t>{0xff, 0xff, 2, 0, 0xfd, 0xff, 4, 0, 0xfb, 0xff, 0xff, 0x7f}));
  EXPECT_EQ(a[2].type, AttributeType::UInt8);
  EXPECT_EQ(a[2].values, (std::vector<uint8_t>{255, 0, 128, 0, 255, 0, 51, 102, 255}));
  EXPECT_EQ(a[3].components, 3);
  EXPECT_EQ(floats(a[4]), (std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, -1}));
  EXPECT_EQ(a[5].components, 2);
  EXPECT_EQ(a[6].type, AttributeType::UInt32);  // vtkIdType: the narrowest type that holds 70000
  EXPECT_EQ(a[7].type, AttributeType::UInt8);
  EXPECT_EQ(a[7].values, (std::vector<uint8_t>{7, 8, 9}));
  EXPECT_TRUE(r.hasNote("rounded the values of 1 double array to float32")) << joined(r.notes);
  // The tensor, the lookup table and the 4-tuple FIELD array; the integer
  // cell data labels the triangle.
  EXPECT_TRUE(r.hasNote("ignored 3 data arrays")) << joined(r.notes);
  EXPECT_TRUE(r.hasNote("kept the cell data array 'region' as simplex labels")) << joined(r.notes);
  EXPECT_EQ(r.complex.labels.triangles, (std::vector<int32_t>{5}));
}

TEST(AttributeIoVtk, BadPointDataNamesTheLine) {
  expectFailure(readText(Format::Vtk, kVtkTriangle + "POINT_DATA 4\n"),
                {"line 9", "POINT_DATA gives values for 4 points, the file has 3"});
  expectFailure(readText(Format::Vtk, kVtkTriangle + "POINT_DATA 3\nSCALARS s unsigned_char\n1 2 256\n"),
                {"line 11", "SCALARS 's' value 2: '256' is not a unsigned_char value"});
  expectFailure(readText(Format::Vtk, kVtkTriangle + "POINT_DATA 3\nCOLOR_SCALARS c 1\n0 1 1.5\n"),
                {"'1.5' is not a number from 0 to 1"});
  expectFailure(readText(Format::Vtk, kVtkTriangle + "POINT_DATA 3\nVECTORS v float\n1 2 3 4" + std::string(20, ' ')),
                {"the file ends inside VECTORS 'v'"});
  expectFailure(readText(Format::Vtk, kVtkTriangle + "POINT_DATA 3\nSCALARS s float 4000000000\n1\n"),
                {"more than the rest of the file can hold"});
  expectFailure(readText(Format::Vtk, kVtkTriangle + "POINT_DATA 3\nNORMALS n quaternion\n"),
                {"unknown data type 'quaternion'"});
}

TEST(AttributeIoVtk, EveryTypeRoundTripsExactly) {
  for (Complex c : {torusMesh(5, 8), tetrahedralBlock(3, 4), pointCloud({0, 0, 0, 1, 1, 1, 1, 1, 1})}) {
    c.attributes = everyKind(c, 3);
    expectFileRoundTrip(Format::Vtk, c);
  }
  // Colours of uint8 go through COLOR_SCALARS; of other types, SCALARS.
  Complex c = torusMesh(3, 4);
  std::vector<uint8_t> rgba;
  for (size_t i = 0; i < 4 * c.vertexCount(); ++i) rgba.push_back(uint8_t(i * 37));
  c.attributes = {attribute("color", AttributeType::UInt8, 4, rgba)};
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(io::writeMemory(Format::Vtk, c, bytes).ok());
  EXPECT_NE(std::string(bytes.begin(), bytes.end()).find("COLOR_SCALARS color 4\n"), std::string::npos);
  expectFileRoundTrip(Format::Vtk, c);
  c.attributes = {attribute("two words", AttributeType::UInt8, 4, rgba)};
  EXPECT_EQ(io::writeMemory(Format::Vtk, c, bytes).code, ErrorCode::InvalidArgument);
}

// ---------------------------------------------------------------------------
// TetGen and Medit
// ---------------------------------------------------------------------------

TEST(AttributeIoTetgen, AttributesAndMarkersRoundTripWithTheNarrowestMarkerType) {
  TempDir dir;
  writeWhole(dir / "m.node",
             "3 3 6 1\n1 0 0 0 1 2 3 4 5 6 -1\n2 1 0 0 1 2 3 4 5 6 300\n3 0 1 0 nan 2 3 4 5 -0 0\n");
  const ReadResult r = readPath(dir / "m.node");
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  ASSERT_EQ(r.complex.attributes.size(), 3u);
  // More than 4 attributes: groups of up to 4, named by their first column.
  EXPECT_EQ(r.complex.attributes[0].name, "attribute_0");
  EXPECT_EQ(r.complex.attributes[0].components, 4);
  EXPECT_EQ(r.complex.attributes[1].name, "attribute_4");
  EXPECT_EQ(r.complex.attributes[1].components, 2);
  EXPECT_EQ(r.complex.attributes[2].name, "marker");
  EXPECT_EQ(r.complex.attributes[2].type, AttributeType::Int16);  // -1 and 300
  expectFailure(readText(Format::TetGen, "2 3 1 1\n1 0 0 0 5 1\n2 1 0 0 5\n"),
                {"line 3", "point 1 lacks 1 of the attribute or marker values"});
  expectFailure(readText(Format::TetGen, "1 3 1 1\n1 0 0 0 5 x\n"), {"line 2", "'x' is not an integer boundary marker"});
  expectFailure(readText(Format::TetGen, "1 3 1 0\n1 0 0 0 y\n"), {"line 2", "'y' is not a number"});

  Complex block = tetrahedralBlock(3, 5);
  std::vector<float> values;
  std::vector<uint16_t> markers;
  for (size_t v = 0; v < block.vertexCount(); ++v) {
    values.insert(values.end(), {block.positions[3 * v] * 0.3f, float(v) * -1e-3f, 1e30f});
    markers.push_back(uint16_t(v * 997 % 40000));
  }
  block.attributes = {attribute("attribute", AttributeType::Float32, 3, values),
                      attribute("marker", AttributeType::UInt16, 1, markers)};
  ASSERT_TRUE(io::writeFile((dir / "block.node").string(), block).ok());
  const ReadResult back = readPath(dir / "block.node");
  ASSERT_TRUE(back.status.ok()) << back.status.message;
  expectSameDescriptors(block, back.complex);
  EXPECT_TRUE(keyedForm(back.complex) == keyedForm(block));
  block.attributes.push_back(attribute("other", AttributeType::UInt8, 1, std::vector<uint8_t>(block.vertexCount())));
  EXPECT_EQ(io::writeFile((dir / "block.node").string(), block).code, ErrorCode::InvalidArgument);
}

TEST(AttributeIoTetgen, EveryColumnMarkerAndRegionSurviveEncodeAndDecode) {
  // Nine point attribute columns (attribute_0 and attribute_4 of 4, attribute_8
  // of 1), boundary markers and region labels.
  Complex block = tetrahedralBlock(3, 7);
  const size_t n = block.vertexCount();
  std::vector<float> first, second, third;
  std::vector<int32_t> markers;
  for (size_t v = 0; v < n; ++v) {
    const float* p = &block.positions[3 * v];
    first.insert(first.end(), {p[0] * 0.3f, float(v) * -1e-3f, 1e30f, -0.0f});
    second.insert(second.end(), {p[1] + p[2], 1.0f / float(v + 1), float(v % 3), INFINITY});
    third.push_back(float(v) * 7.25f);
    markers.push_back(int32_t(v * 997 % 70000) - 1000);
  }
  block.attributes = {attribute("attribute_0", AttributeType::Float32, 4, first),
                      attribute("attribute_4", AttributeType::Float32, 4, second),
                      attribute("attribute_8", AttributeType::Float32, 1, third),
                      attribute("marker", AttributeType::Int32, 1, markers)};
  for (size_t t = 0; t < block.tetrahedra.size() / 4; ++t) block.labels.tetrahedra.push_back(int32_t(t % 5) - 2);

  TempDir dir;
  ASSERT_TRUE(io::writeFile((dir / "block.ele").string(), block).ok());
  const ReadResult read = readPath(dir / "block.node");
  ASSERT_TRUE(read.status.ok()) << read.status.message;
  EXPECT_TRUE(read.notes.empty()) << joined(read.notes);
  expectSameDescriptors(block, read.complex);
  EXPECT_EQ(bitsOf(read.complex.positions), bitsOf(block.positions));
  EXPECT_EQ(vertexKeys(read.complex), vertexKeys(block));
  EXPECT_EQ(read.complex.tetrahedra, block.tetrahedra);
  EXPECT_EQ(read.complex.labels.tetrahedra, block.labels.tetrahedra);

  // Through the codec and back to files: the same vertices, values,
  // tetrahedra and labels, up to vertex order.
  EncodeOptions exact;
  exact.exact = true;
  expectRoundTrip(read.complex, exact);
  const EncodeResult encoded = encode(read.complex, exact);
  ASSERT_TRUE(encoded.status.ok()) << encoded.status.message;
  Complex decoded;
  ASSERT_TRUE(decode(encoded.bytes.data(), encoded.bytes.size(), decoded).ok());
  ASSERT_TRUE(io::writeFile((dir / "decoded.node").string(), decoded).ok());
  const ReadResult back = readPath(dir / "decoded.ele");
  ASSERT_TRUE(back.status.ok()) << back.status.message;
  expectSameDescriptors(block, back.complex);
  EXPECT_EQ(vertexKeys(back.complex), vertexKeys(decoded));
  EXPECT_EQ(back.complex.tetrahedra, decoded.tetrahedra);
  EXPECT_EQ(back.complex.labels.tetrahedra, decoded.labels.tetrahedra);
  EXPECT_EQ(canonicalForm(back.complex), canonicalForm(block));

  // Columns the reader would name otherwise are refused, not renamed.
  Complex gap = block;
  gap.attributes.erase(gap.attributes.begin() + 1);  // attribute_0, attribute_8
  EXPECT_EQ(io::writeFile((dir / "gap.node").string(), gap).code, ErrorCode::InvalidArgument);
  Complex short0 = block;
  short0.attributes.erase(short0.attributes.begin() + 1, short0.attributes.begin() + 3);  // attribute_0 alone
  EXPECT_EQ(io::writeFile((dir / "short.node").string(), short0).code, ErrorCode::InvalidArgument);
  Complex misnamed = block;
  misnamed.attributes[2].name = "attribute_9";
  EXPECT_EQ(io::writeFile((dir / "misnamed.node").string(), misnamed).code, ErrorCode::InvalidArgument);
}

TEST(AttributeIoMedit, VertexReferencesRoundTrip) {
  for (const int64_t largest : {int64_t{200}, int64_t{-5}, int64_t{70000}, int64_t{3000000000}}) {
    Complex block = tetrahedralBlock(3, 6);
    std::vector<int64_t> references(block.vertexCount(), 0);
    references[1] = largest;
    references[2] = 1;
    AttributeType type;
    ASSERT_TRUE(io::detail::narrowestIntegerType(references, type));
    block.attributes = {io::detail::integerAttribute("ref", type, references)};
    expectFileRoundTrip(Format::Medit, block);
  }
  expectFailure(readText(Format::Medit, "MeshVersionFormatted 1\nDimension 3\nVertices\n1\n0 0 0 5000000000\n"),
                {"vertex references beyond the 32-bit range"});
}

}  // namespace
}  // namespace kdmesh::test
