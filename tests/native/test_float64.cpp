// Float64 streams: exact encoding of Complex::positions64 keeps every
// double bit (subnormals, huge and tiny magnitudes, infinities, NaN
// payloads, -0.0), float32 values cost about nothing extra, prefixes
// decode, and hostile float64 headers and tables are refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "complexes.h"
#include "container.h"
#include "io_test_support.h"
#include "kdmesh/io.h"
#include "kdmesh/kdmesh.h"
#include "quantizer.h"
#include "test_support.h"

namespace kdmesh::test {
namespace {

uint64_t doubleBits(double d) {
  uint64_t u;
  std::memcpy(&u, &d, 8);
  return u;
}

double doubleOf(uint64_t u) {
  double d;
  std::memcpy(&d, &u, 8);
  return d;
}

// Doubles of every kind: plain ones, float32 values, subnormals, values
// beyond the float32 range either way, infinities, NaNs with payloads.
std::vector<double> awkwardDoubles(size_t n, uint32_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<double> out(n);
  for (size_t i = 0; i < n; ++i) {
    switch (rng() % 12) {
      case 0: out[i] = double(float(unit(rng))); break;
      case 1: out[i] = doubleOf(rng() % 0x000fffffffffffffull); break;  // subnormal
      case 2: out[i] = unit(rng) * 1e300; break;
      case 3: out[i] = unit(rng) * 1e-300; break;
      case 4: out[i] = rng() % 2 ? INFINITY : -INFINITY; break;
      case 5: out[i] = doubleOf(0x7ff0000000000000ull | (rng() & 0x000fffffffffffffull) | 1); break;  // NaN
      case 6: out[i] = doubleOf(0xfff8000000000000ull | (rng() & 0xffff)); break;  // negative quiet NaN
      case 7: out[i] = -0.0; break;
      case 8: out[i] = unit(rng) * 1e-40; break;  // a float32 subnormal's range
      default: out[i] = unit(rng) * 10; break;
    }
  }
  return out;
}

using Bits64 = std::array<uint64_t, 3>;
std::vector<Bits64> sortedDoubleBits(const std::vector<double>& positions) {
  std::vector<Bits64> v(positions.size() / 3);
  for (size_t i = 0; i < v.size(); ++i)
    for (size_t a = 0; a < 3; ++a) v[i][a] = doubleBits(positions[3 * i + a]);
  std::sort(v.begin(), v.end());
  return v;
}

// `c` with positions64 set from `doubles` and positions their roundings.
Complex withDoubles(Complex c, const std::vector<double>& doubles) {
  c.positions64 = doubles;
  c.positions.assign(doubles.begin(), doubles.end());
  return c;
}

EncodeOptions exactOptions() {
  EncodeOptions options;
  options.exact = true;
  options.chunkBytes = 1024;
  return options;
}

// Encodes exactly, decodes, and checks every double bit (up to vertex
// order) and that every chunk boundary's prefix decodes.
void expectExactDoubles(const Complex& input) {
  const EncodeResult encoded = encode(input, exactOptions());
  ASSERT_TRUE(encoded.status.ok()) << encoded.status.message;
  Decoder decoder;
  ASSERT_TRUE(decoder.push(encoded.bytes.data(), encoded.bytes.size()).ok());
  ASSERT_TRUE(decoder.finish().ok());
  EXPECT_TRUE(decoder.header().float64());
  const Complex decoded = decoder.snapshot();
  EXPECT_EQ(decoded.attributes.size(), input.attributes.size());
  ASSERT_EQ(decoded.positions64.size(), decoded.positions.size());
  EXPECT_EQ(sortedDoubleBits(decoded.positions64), sortedDoubleBits(input.positions64));
  EXPECT_EQ(decoded.triangles.size(), input.triangles.size());
  EXPECT_EQ(decoded.tetrahedra.size(), input.tetrahedra.size());
  EXPECT_EQ(decoder.cost().attributeBits.size(), input.attributes.size());
  EXPECT_EQ(encoded.cost.attributeBits.size(), input.attributes.size());
  for (const ChunkInfo& chunk : decoder.chunks()) {
    Decoder prefix;
    ASSERT_TRUE(prefix.push(encoded.bytes.data(), size_t(chunk.offset) + 3).ok());
    const Complex coarse = prefix.snapshot();
    EXPECT_EQ(coarse.positions64.size(), coarse.positions.size());
    EXPECT_EQ(coarse.attributes.size(), input.attributes.size());
    for (const VertexAttribute& a : coarse.attributes)
      EXPECT_EQ(a.values.size(), coarse.vertexCount() * a.valueBytes()) << a.name;
  }
}

TEST(Float64, RandomDoublesOfEveryKindKeepTheirBits) {
  const std::vector<double> doubles = awkwardDoubles(3 * 400, 7);
  Complex cloud;
  expectExactDoubles(withDoubles(cloud, doubles));
  Complex block = tetrahedralBlock(4, 3);
  std::vector<double> blockDoubles(block.positions.begin(), block.positions.end());
  const std::vector<double> noise = awkwardDoubles(blockDoubles.size(), 8);
  for (size_t i = 0; i < blockDoubles.size(); i += 7) blockDoubles[i] = noise[i];
  expectExactDoubles(withDoubles(block, blockDoubles));
  // A single vertex: the stream is the header and the attribute table.
  expectExactDoubles(withDoubles(Complex{}, {doubleOf(1), -1e300, std::nextafter(0.1, 1.0)}));
}

TEST(Float64, UserAttributesAndLabelsStayAsTheyAre) {
  Complex c = sphereMesh(12, 16);
  std::vector<double> doubles;
  for (const float x : c.positions) doubles.push_back(double(x) * (1 + 1e-12));
  c = withDoubles(c, doubles);
  std::vector<uint8_t> values(c.vertexCount());
  for (size_t v = 0; v < values.size(); ++v) values[v] = uint8_t(v * 7);
  c.attributes.push_back({"shade", AttributeType::UInt8, 1, values, {}});
  c.labels.triangles.assign(c.triangles.size() / 3, 4);
  expectExactDoubles(c);
}

TEST(Float64, Float32ValuesCostAlmostNothingMore) {
  const Complex mesh = sphereMesh(60, 80);
  const EncodeResult float32 = encode(mesh, exactOptions());
  ASSERT_TRUE(float32.status.ok());
  const Complex widened = withDoubles(mesh, std::vector<double>(mesh.positions.begin(), mesh.positions.end()));
  const EncodeResult float64 = encode(widened, exactOptions());
  ASSERT_TRUE(float64.status.ok()) << float64.status.message;
  // The residual table (about 50 bytes) and zero residuals: well under a
  // tenth of a bit per vertex plus the table.
  const double extraBits = 8.0 * (double(float64.bytes.size()) - double(float32.bytes.size()));
  EXPECT_LT(extraBits, 8.0 * 80 + 0.1 * double(mesh.vertexCount())) << extraBits;
  // Without positions64, exact streams are float32 streams as before.
  Header h;
  size_t size = 0;
  ASSERT_TRUE(headerSize(float32.bytes.data(), size).ok());
  ASSERT_TRUE(readHeader(float32.bytes.data(), size, DecoderLimits{}, h).ok());
  EXPECT_FALSE(h.float64());
  EXPECT_EQ(h.bits, 32);
}

TEST(Float64, BadInputIsRefused) {
  Complex c = withDoubles(Complex{}, {1, 2, 3, 4, 5, 6});
  c.positions64.pop_back();
  EXPECT_EQ(encode(c, exactOptions()).status.code, ErrorCode::InvalidArgument);
  c = withDoubles(Complex{}, {1, 2, 3, 4, 5, 6});
  c.attributes.push_back({kResidualNames[0], AttributeType::Int32, 3, std::vector<uint8_t>(24), {}});
  EXPECT_EQ(encode(c, exactOptions()).status.code, ErrorCode::InvalidInput);
  c.attributes.clear();
  for (size_t a = 0; a < kMaxAttributes - 1; ++a)
    c.attributes.push_back({"a" + std::to_string(a), AttributeType::UInt8, 1, std::vector<uint8_t>(2), {}});
  const EncodeResult many = encode(c, exactOptions());
  EXPECT_EQ(many.status.code, ErrorCode::InvalidInput);
  EXPECT_NE(many.status.message.find("at most 13 attributes"), std::string::npos) << many.status.message;
  // A grid ignores positions64 (and its note is the reader's business).
  c.attributes.clear();
  EXPECT_TRUE(encode(c, EncodeOptions{}).status.ok());
  // The memory limit counts the copy that exact encoding makes, and refuses
  // before making it.
  EncodeOptions limited = exactOptions();
  limited.maxMemoryBytes = encodeMemoryEstimate(c) - 1;
  EXPECT_EQ(encode(c, limited).status.code, ErrorCode::LimitExceeded);
}

// Rewrites the header of `bytes` with `edit` applied (a valid checksum).
std::vector<uint8_t> withHeader(const std::vector<uint8_t>& bytes, void (*edit)(Header&)) {
  Header h;
  size_t size = 0;
  EXPECT_TRUE(headerSize(bytes.data(), size).ok());
  EXPECT_TRUE(readHeader(bytes.data(), size, DecoderLimits{}, h).ok());
  edit(h);
  uint8_t header[kMaxHeaderBytes];
  const size_t written = writeHeader(h, header);
  std::vector<uint8_t> out(header, header + written);
  out.insert(out.end(), bytes.begin() + std::ptrdiff_t(size), bytes.end());
  return out;
}

TEST(Float64, HostileHeadersAndTablesAreRefused) {
  // Bits other than 32 or 64 in float mode, and float64 without its two
  // residual attributes.
  const Complex points = withDoubles(Complex{}, {1, 2, 3, 4, 5, 6.5});
  const std::vector<uint8_t> float32 = encodeOrDie(pointCloud({1, 2, 3, 4, 5, 6}), exactOptions());
  for (const auto edit : {+[](Header& h) { h.bits = 48; }, +[](Header& h) { h.bits = 64; }}) {
    const std::vector<uint8_t> bad = withHeader(float32, edit);
    Decoder decoder;
    EXPECT_EQ(decoder.push(bad.data(), bad.size()).code, ErrorCode::CorruptHeader);
  }
  // A float32 stream with two int32 × 3 attributes of other names, relabelled
  // float64: its table does not end with the residuals.
  Complex impostor = pointCloud({1, 2, 3, 4, 5, 6});
  for (const char* name : {"low", "high"})
    impostor.attributes.push_back({name, AttributeType::Int32, 3, std::vector<uint8_t>(24), {}});
  const std::vector<uint8_t> relabelled =
      withHeader(encodeOrDie(impostor, exactOptions()), +[](Header& h) { h.bits = 64; });
  Decoder decoder;
  const Status s = decoder.push(relabelled.data(), relabelled.size());
  EXPECT_EQ(s.code, ErrorCode::CorruptHeader);
  EXPECT_NE(s.message.find("residuals"), std::string::npos) << s.message;
  // The real thing decodes.
  const std::vector<uint8_t> good = encodeOrDie(points, exactOptions());
  Complex out;
  EXPECT_TRUE(decode(good.data(), good.size(), out).ok());
  EXPECT_EQ(out.positions64.back(), 6.5);
}

// ---------------------------------------------------------------------------
// Files: PLY double, Medit version 2, text decimals beyond float32
// ---------------------------------------------------------------------------

// Reads `bytes` keeping doubles.
ReadResult readDoubles(io::Format format, const std::vector<uint8_t>& bytes) {
  ReadResult result;
  io::ReadOptions options;
  options.keepDoubles = true;
  result.status = io::readMemory(format, bytes.data(), bytes.size(), result.complex, result.notes, options);
  return result;
}

// A tetrahedral block (a closed surface of it for formats without
// tetrahedra) whose coordinates are doubles of every kind; NaNs only where
// the format keeps their payloads (binary PLY).
Complex doubleBlock(bool nans, bool tetrahedra) {
  Complex block = tetrahedralBlock(3, 5);
  std::vector<double> doubles(block.positions.begin(), block.positions.end());
  const std::vector<double> noise = awkwardDoubles(doubles.size(), 9);
  for (size_t i = 0; i < doubles.size(); ++i) {
    if (i % 3 == 0 && (nans || !std::isnan(noise[i]))) doubles[i] = noise[i];
    else doubles[i] += 1e-12 * double(i);  // below float32 precision
  }
  if (!tetrahedra) {
    block.triangles = {0, 1, 2, 0, 2, 3, 0, 3, 1, 1, 3, 2};
    block.tetrahedra.clear();
  }
  return withDoubles(block, doubles);
}

// Written, read back with doubles, encoded exactly, decoded, written and
// read again: every double bit survives each step.
void expectFileRoundTrip(io::Format format, const Complex& complex, const io::WriteOptions& options = {}) {
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(io::writeMemory(format, complex, bytes, options).ok());
  const ReadResult read = readDoubles(format, bytes);
  ASSERT_TRUE(read.status.ok()) << read.status.message;
  EXPECT_TRUE(read.notes.empty()) << joined(read.notes);
  ASSERT_EQ(read.complex.positions64.size(), complex.positions64.size());
  for (size_t i = 0; i < complex.positions64.size(); ++i)
    ASSERT_EQ(doubleBits(read.complex.positions64[i]), doubleBits(complex.positions64[i])) << i;
  const EncodeResult encoded = encode(read.complex, exactOptions());
  ASSERT_TRUE(encoded.status.ok()) << encoded.status.message;
  Complex decoded;
  ASSERT_TRUE(decode(encoded.bytes.data(), encoded.bytes.size(), decoded).ok());
  EXPECT_EQ(sortedDoubleBits(decoded.positions64), sortedDoubleBits(complex.positions64));
  bytes.clear();
  ASSERT_TRUE(io::writeMemory(format, decoded, bytes, options).ok());
  const ReadResult again = readDoubles(format, bytes);
  ASSERT_TRUE(again.status.ok()) << again.status.message;
  EXPECT_EQ(sortedDoubleBits(again.complex.positions64), sortedDoubleBits(complex.positions64));
  // Without keepDoubles the reader rounds them, with a note.
  const ReadResult rounded = readBytes(format, bytes);
  ASSERT_TRUE(rounded.status.ok());
  EXPECT_TRUE(rounded.complex.positions64.empty());
  EXPECT_TRUE(rounded.hasNote("rounded to float32")) << joined(rounded.notes);
}

TEST(Float64Files, PlyDoublesBinaryAndAscii) {
  expectFileRoundTrip(io::Format::Ply, doubleBlock(true, true));
  io::WriteOptions ascii;
  ascii.asciiPly = true;
  expectFileRoundTrip(io::Format::Ply, doubleBlock(false, true), ascii);
}

TEST(Float64Files, MeditVersion2) { expectFileRoundTrip(io::Format::Medit, doubleBlock(false, true)); }

TEST(Float64Files, TextDecimalsBeyondFloat32) {
  expectFileRoundTrip(io::Format::Obj, doubleBlock(false, false));
  expectFileRoundTrip(io::Format::Off, doubleBlock(false, false));
  expectFileRoundTrip(io::Format::Vtk, doubleBlock(false, true));
  Complex cloud = doubleBlock(false, false);
  cloud.triangles.clear();
  expectFileRoundTrip(io::Format::Xyz, cloud);
  expectFileRoundTrip(io::Format::TetGen, cloud);  // the .node file alone
}

TEST(Float64Files, Float32FilesStayFloat32) {
  // Shortest float32 decimals ("0.1") are float32 coordinates, and a
  // float32 PLY or Medit version 1 file has none of another kind.
  const ReadResult obj = readDoubles(io::Format::Obj, bytesOf("v 0.1 0.2 0.3\nv 1e-45 -0 3.4028235e38\nv nan inf -inf\n"));
  ASSERT_TRUE(obj.status.ok()) << obj.status.message;
  EXPECT_TRUE(obj.complex.positions64.empty());
  EXPECT_TRUE(obj.notes.empty()) << joined(obj.notes);
  const ReadResult roundedObj = readBytes(io::Format::Obj, bytesOf("v 0.1 0.2 0.3\nv 0.1000000001 0 0\n"));
  ASSERT_TRUE(roundedObj.status.ok());
  EXPECT_TRUE(roundedObj.complex.positions64.empty());
  EXPECT_TRUE(roundedObj.hasNote("rounded to float32")) << joined(roundedObj.notes);
  const ReadResult longer = readDoubles(io::Format::Obj, bytesOf("v 0.1 0.2 0.3\nv 0.10000000000000001 0 0\nv 0.1000000001 0 0\n"));
  ASSERT_TRUE(longer.status.ok());
  ASSERT_EQ(longer.complex.positions64.size(), 9u);
  EXPECT_EQ(longer.complex.positions64[0], 0.1);  // the decimal's double, not 0.1f
  EXPECT_EQ(longer.complex.positions64[6], 0.1000000001);
  EXPECT_EQ(longer.complex.positions[6], float(0.1000000001));
  const Complex floats = sphereMesh(6, 8);
  // VTK declares its POINTS double or float, but writes decimals: a double
  // array of float32 values is a float32 file.
  const ReadResult vtk = readDoubles(
      io::Format::Vtk, bytesOf("# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 2 double\n"
                               "0.1 0.2 0.3 1e-45 -0 3.4028235e38\n"));
  ASSERT_TRUE(vtk.status.ok()) << vtk.status.message;
  EXPECT_TRUE(vtk.complex.positions64.empty());
  EXPECT_TRUE(vtk.notes.empty()) << joined(vtk.notes);
  for (const io::Format format : {io::Format::Ply, io::Format::Medit, io::Format::Obj, io::Format::Off,
                                  io::Format::Vtk}) {
    std::vector<uint8_t> bytes;
    ASSERT_TRUE(io::writeMemory(format, floats, bytes).ok());
    const ReadResult read = readDoubles(format, bytes);
    ASSERT_TRUE(read.status.ok());
    EXPECT_TRUE(read.complex.positions64.empty()) << io::formatName(format);
  }
}

}  // namespace
}  // namespace kdmesh::test
