// Odd and hostile inputs for the readers and the encoder: each gets a clear
// error or a correct result (ctest gives every test a time limit).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "complexes.h"
#include "io_test_support.h"
#include "kdmesh/io.h"
#include "kdmesh/kdmesh.h"
#include "shapes.h"
#include "test_support.h"

namespace kdmesh::test {
namespace {

TEST(HostileInputs, ByteOrderMarksAreSkipped) {
  const ReadResult obj = readText(io::Format::Obj, "\xEF\xBB\xBFv 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n");
  ASSERT_TRUE(obj.status.ok());
  EXPECT_EQ(obj.complex.simplexCount(2), 1u);
  const ReadResult xyz = readText(io::Format::Xyz, "\xEF\xBB\xBF" "1 2 3\n");
  ASSERT_TRUE(xyz.status.ok());
  EXPECT_EQ(xyz.complex.vertexCount(), 1u);
}

TEST(HostileInputs, HugeObjLinesAndNegativeIndicesOutOfRange) {
  std::string line = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf";
  for (int i = 0; i < 200000; ++i) line += " 1 2 3";
  line += "\n";
  EXPECT_TRUE(readText(io::Format::Obj, line).status.ok());  // a huge polygon, fan-split
  const Status s = readText(io::Format::Obj, "v 0 0 0\nf -1 -2 -3\n").status;
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message.find("line 2"), std::string::npos) << s.message;
}

TEST(HostileInputs, NegativeAndHugeCountsInHeaders) {
  EXPECT_FALSE(readText(io::Format::Off, "OFF\n-3 1 0\n").status.ok());
  EXPECT_FALSE(readText(io::Format::Off, "OFF\n2147483648 1 0\n0 0 0\n").status.ok());
  EXPECT_FALSE(readText(io::Format::Ply, "ply\nformat ascii 1.0\nelement vertex -1\nproperty float x\nend_header\n").status.ok());
}

TEST(HostileInputs, ASingleTriangleRoundTrips) {
  Complex c;
  c.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  c.triangles = {0, 2, 1};
  EncodeOptions o;
  o.exact = true;
  const EncodeResult r = encode(c, o);
  ASSERT_TRUE(r.status.ok());
  Complex d;
  ASSERT_TRUE(decode(r.bytes.data(), r.bytes.size(), d).ok());
  EXPECT_EQ(canonicalForm(d), canonicalForm(c));
}

TEST(HostileInputs, AMillionCoincidentVertices) {
  Complex cloud;
  cloud.positions.assign(3 * 1000000, 0.5f);
  const EncodeResult r = encode(cloud, EncodeOptions{});
  ASSERT_TRUE(r.status.ok());
  EXPECT_LT(r.bytes.size(), 2048u);  // nothing to say but the count
  // More vertices per byte than DecoderLimits allows by default: refused,
  // as a decompression bomb would be; a decoder that expects such clouds
  // raises the limit.
  Complex d;
  EXPECT_EQ(decode(r.bytes.data(), r.bytes.size(), d).code, ErrorCode::LimitExceeded);
  DecoderOptions coincidentClouds;
  coincidentClouds.limits.maxVerticesPerByte = 1u << 20;
  ASSERT_TRUE(decode(r.bytes.data(), r.bytes.size(), d, false, coincidentClouds).ok());
  EXPECT_EQ(d.vertexCount(), 1000000u);
  // With connectivity, coincident vertices are told apart by their simplices.
  Complex fan;
  fan.positions.assign(3 * 20001, 1.f);
  for (uint32_t i = 1; i + 1 < 20001; i += 2) fan.triangles.insert(fan.triangles.end(), {0, i, i + 1});
  const EncodeResult f = encode(fan, EncodeOptions{});
  ASSERT_TRUE(f.status.ok()) << f.status.message;
  ASSERT_TRUE(decode(f.bytes.data(), f.bytes.size(), d).ok());
  EXPECT_EQ(d.simplexCount(2), 10000u);
  EXPECT_EQ(canonicalForm(d).size(), canonicalForm(fan).size());
}

// maxMemoryBytes refuses a complex by its estimate, before encoding.
TEST(HostileInputs, TheEncoderMemoryLimitComparesTheEstimate) {
  Complex soup;
  for (uint32_t t = 0; t < 1000; ++t) {
    soup.positions.insert(soup.positions.end(), {float(t), 0, 0, float(t), 1, 0, float(t), 0, 1});
    soup.triangles.insert(soup.triangles.end(), {3 * t, 3 * t + 1, 3 * t + 2});
  }
  const uint64_t estimate = encodeMemoryEstimate(soup);
  Complex point;
  point.positions = {0, 0, 0};
  EXPECT_GT(estimate, encodeMemoryEstimate(point));
  EncodeOptions options;
  options.maxMemoryBytes = estimate - 1;
  const EncodeResult refused = encode(soup, options);
  EXPECT_EQ(refused.status.code, ErrorCode::LimitExceeded);
  EXPECT_NE(refused.status.message.find("3000 vertices and 1000 simplices"), std::string::npos)
      << refused.status.message;
  EXPECT_TRUE(refused.bytes.empty());
  options.maxMemoryBytes = estimate;
  EXPECT_TRUE(encode(soup, options).status.ok());
}

TEST(HostileInputs, TenMillionPoints) {
  Complex cloud;
  cloud.positions = uniformCloud(10000000, 77);
  EncodeOptions o;
  o.bits = 12;
  const EncodeResult r = encode(cloud, o);
  ASSERT_TRUE(r.status.ok());
  Complex d;
  ASSERT_TRUE(decode(r.bytes.data(), r.bytes.size(), d).ok());
  EXPECT_EQ(d.vertexCount(), 10000000u);
}

TEST(HostileInputs, ZeroVerticesAndOutOfRangeIndicesAreErrors) {
  EXPECT_EQ(encode(Complex{}, EncodeOptions{}).status.code, ErrorCode::InvalidInput);
  Complex c;
  c.positions = {0, 0, 0};
  c.tetrahedra = {0, 0, 0, 4000000000u};
  const EncodeResult r = encode(c, EncodeOptions{});
  EXPECT_EQ(r.status.code, ErrorCode::InvalidInput);
  EXPECT_NE(r.status.message.find("tetrahedron 0"), std::string::npos) << r.status.message;
}

// The decoder fuzzer's committed seed streams (scripts/fuzz-seeds.sh) are
// of the current format and, together, reach every table and coding path
// the fuzzer should mutate.
TEST(FuzzSeeds, DecoderSeedsDecodeAndCoverEveryTable) {
  std::vector<std::filesystem::path> streams;
  for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::path(KDMESH_FUZZ_SEEDS) / "decoder"))
    if (entry.path().extension() == ".kdm") streams.push_back(entry.path());
  std::sort(streams.begin(), streams.end());
  ASSERT_GE(streams.size(), 8u);
  bool grid = false, connectivity = false, exactAttribute = false, uniform = false, octahedral = false,
       geometricOctahedral = false, labelled = false, nonFinite = false, float64 = false, fastDecode = false,
       fanExpansions = false;
  for (const std::filesystem::path& path : streams) {
    SCOPED_TRACE(path.filename().string());
    std::vector<uint8_t> bytes;
    ASSERT_TRUE(io::readBytes(path.string(), bytes).ok());
    Decoder decoder;
    const Status pushed = decoder.push(bytes.data(), bytes.size());
    ASSERT_TRUE(pushed.ok() && decoder.finish().ok())
        << pushed.message << " (regenerate the seeds: sh scripts/fuzz-seeds.sh)";
    const Complex c = decoder.snapshot();
    grid |= decoder.header().quantization == Quantization::Grid;
    connectivity |= c.hasSimplices();
    labelled |= decoder.header().labelled;
    fastDecode |= c.hasSimplices() && decoder.header().fastDecode;
    fanExpansions |= decoder.statistics().fanExpansions > 0;
    float64 |= decoder.header().float64() && !c.positions64.empty();
    for (const VertexAttribute& a : c.attributes) {
      exactAttribute |= a.quantization.kind == AttributeQuantization::Exact;
      uniform |= a.quantization.kind == AttributeQuantization::Uniform;
      octahedral |= a.quantization.kind == AttributeQuantization::Octahedral;
      geometricOctahedral |= a.quantization.kind == AttributeQuantization::GeometricOctahedral;
    }
    nonFinite |= std::any_of(c.positions.begin(), c.positions.end(), [](float x) { return !std::isfinite(x); });
  }
  EXPECT_TRUE(grid && connectivity && exactAttribute && uniform && octahedral && geometricOctahedral && labelled &&
              nonFinite && float64 && fastDecode && fanExpansions);
}

}  // namespace
}  // namespace kdmesh::test
