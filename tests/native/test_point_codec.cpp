// Point clouds through encode and decode: exact in float32 mode, within half
// a grid step in grid mode, on many shapes and sizes.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "kd_order.h"
#include "shapes.h"
#include "split_schedule.h"
#include "test_support.h"

namespace kdmesh::test {
namespace {

struct Shape {
  const char* name;
  std::vector<float> positions;
};

std::vector<Shape> shapes() {
  return {
      {"single point", {1.5f, -2.25f, 3.0f}},
      {"two points", {0.f, 0.f, 0.f, 1.f, 2.f, 3.f}},
      {"two coincident points", {7.f, 7.f, 7.f, 7.f, 7.f, 7.f}},
      {"uniform 5000", uniformCloud(5000, 11)},
      {"uniform tiny scale", uniformCloud(3000, 12, 1e-30f)},
      {"uniform huge scale", uniformCloud(3000, 13, 1e30f)},
      {"clustered 20000", clusteredCloud(20000, 14)},
      {"sphere 20000", sphereSurface(20000, 15)},
      {"torus 20000", torusSurface(20000, 16)},
      {"coincident 10000", coincidentCloud(10000, 17)},
      {"collinear", [] {
         std::vector<float> p;
         for (int i = 0; i < 500; ++i) p.insert(p.end(), {float(i) * 0.37f, 2.f, -1.f});
         return p;
       }()},
  };
}

void expectWithinHalfStep(const std::vector<float>& input, const Complex& decoded, const Header& h) {
  ASSERT_EQ(decoded.vertexCount(), input.size() / 3);
  // What the format promises: coordinate q * step from the origin, q the
  // nearest grid line.
  std::vector<float> expected(input.size());
  for (size_t i = 0; i < input.size(); ++i) {
    const size_t a = i % 3;
    const double q = h.step > 0 ? std::llround((double(input[i]) - h.origin[a]) / h.step) : 0;
    expected[i] = float(h.origin[a] + q * h.step);
    const double tolerance = h.step * 0.5 * (1 + 1e-9) + std::abs(double(input[i])) * 1.2e-7;
    ASSERT_LE(std::abs(double(expected[i]) - input[i]), tolerance);
  }
  EXPECT_EQ(sortedBitPatterns(expected), sortedBitPatterns(decoded.positions));
}

TEST(PointCodec, Float32ModeIsBitExactOnEveryShape) {
  for (const Shape& shape : shapes()) {
    SCOPED_TRACE(shape.name);
    EncodeOptions options;
    options.exact = true;
    const std::vector<uint8_t> bytes = encodeOrDie(pointCloud(shape.positions), options);
    Complex decoded;
    ASSERT_TRUE(decode(bytes.data(), bytes.size(), decoded).ok());
    EXPECT_EQ(sortedBitPatterns(shape.positions), sortedBitPatterns(decoded.positions));
    EXPECT_EQ(decoded.points.size(), decoded.vertexCount());
  }
}

TEST(PointCodec, GridModeIsWithinHalfAStepOnEveryShapeAndBitDepth) {
  for (const Shape& shape : shapes()) {
    for (int bits : {1, 4, 12, 16, 30}) {
      SCOPED_TRACE(std::string(shape.name) + " bits " + std::to_string(bits));
      EncodeOptions options;
      options.bits = bits;
      const std::vector<uint8_t> bytes = encodeOrDie(pointCloud(shape.positions), options);
      Decoder decoder;
      ASSERT_TRUE(decoder.push(bytes.data(), bytes.size()).ok());
      ASSERT_TRUE(decoder.finish().ok());
      EXPECT_EQ(decoder.header().bits, bits);
      expectWithinHalfStep(shape.positions, decoder.snapshot(), decoder.header());
    }
  }
}

TEST(PointCodec, SpecialFloatsSurviveExactMode) {
  const float denormal = std::numeric_limits<float>::denorm_min();
  const float big = std::numeric_limits<float>::max();
  std::vector<float> p = {0.f, -0.f, 1.f, denormal, -denormal, 0.f, big, -big, 1e-38f,
                          -0.f, -0.f, -0.f, 0.f, 0.f, 0.f, 3.f, 3.f, 3.f};
  EncodeOptions options;
  options.exact = true;
  const std::vector<uint8_t> bytes = encodeOrDie(pointCloud(p), options);
  Complex decoded;
  ASSERT_TRUE(decode(bytes.data(), bytes.size(), decoded).ok());
  EXPECT_EQ(sortedBitPatterns(p), sortedBitPatterns(decoded.positions));
  // Extremes in grid mode too: the extent max - (-max) overflows float, not double.
  const std::vector<uint8_t> grid = encodeOrDie(pointCloud(p), EncodeOptions{});
  Decoder decoder;
  ASSERT_TRUE(decoder.push(grid.data(), grid.size()).ok());
  expectWithinHalfStep(p, decoder.snapshot(), decoder.header());
}

TEST(PointCodec, AMillionPointsRoundTrip) {
  const std::vector<float> p = clusteredCloud(1000000, 99);
  EncodeOptions options;
  options.exact = true;
  const std::vector<uint8_t> bytes = encodeOrDie(pointCloud(p), options);
  Complex decoded;
  ASSERT_TRUE(decode(bytes.data(), bytes.size(), decoded).ok());
  EXPECT_EQ(sortedBitPatterns(p), sortedBitPatterns(decoded.positions));
  options.exact = false;
  options.bits = 12;
  const std::vector<uint8_t> grid = encodeOrDie(pointCloud(p), options);
  Decoder decoder;
  ASSERT_TRUE(decoder.push(grid.data(), grid.size()).ok());
  expectWithinHalfStep(p, decoder.snapshot(), decoder.header());
}

TEST(PointCodec, StructureCompressesBelowRawCoordinates) {
  // 12-bit grid: raw coordinates cost 36 bits per point, a uniform code of
  // each kd-tree count about 20.5 on this sphere. Adaptive contexts must do
  // better than both.
  const std::vector<float> p = sphereSurface(50000, 3);
  EncodeOptions options;
  options.bits = 12;
  const EncodeResult r = encode(pointCloud(p), options);
  ASSERT_TRUE(r.status.ok());
  const double bitsPerPoint = 8.0 * double(r.bytes.size()) / 50000;
  EXPECT_LT(bitsPerPoint, 20.0);
  // The measured information content accounts for nearly all of the payload.
  EXPECT_NEAR(r.cost.geometryBits, 8.0 * double(r.bytes.size()), 8.0 * double(r.bytes.size()) * 0.01);
}

TEST(PointCodec, RejectsNonFiniteCoordinatesNamingTheVertex) {
  std::vector<float> p = uniformCloud(10, 1);
  p[3 * 6 + 1] = std::numeric_limits<float>::quiet_NaN();
  EncodeResult r = encode(pointCloud(p), EncodeOptions{});
  EXPECT_EQ(r.status.code, ErrorCode::InvalidInput);
  EXPECT_NE(r.status.message.find("vertex 6"), std::string::npos) << r.status.message;
  EXPECT_NE(r.status.message.find("NaN y"), std::string::npos) << r.status.message;
  p[3 * 6 + 1] = 0;
  p[3 * 2 + 2] = -std::numeric_limits<float>::infinity();
  r = encode(pointCloud(p), EncodeOptions{});
  EXPECT_NE(r.status.message.find("vertex 2 has an infinite z"), std::string::npos) << r.status.message;
}

TEST(PointCodec, RejectsBadOptionsAndEmptyInput) {
  EncodeOptions options;
  options.bits = 31;
  EXPECT_EQ(encode(pointCloud({1, 2, 3}), options).status.code, ErrorCode::InvalidArgument);
  options.bits = 0;
  EXPECT_EQ(encode(pointCloud({1, 2, 3}), options).status.code, ErrorCode::InvalidArgument);
  options = {};
  options.chunkBytes = 10;
  EXPECT_EQ(encode(pointCloud({1, 2, 3}), options).status.code, ErrorCode::InvalidArgument);
  EXPECT_EQ(encode(pointCloud({}), EncodeOptions{}).status.code, ErrorCode::InvalidInput);
  EXPECT_EQ(encode(pointCloud({1, 2}), EncodeOptions{}).status.code, ErrorCode::InvalidArgument);
}

TEST(PointCodec, EncodingIsDeterministic) {
  const std::vector<float> p = clusteredCloud(5000, 4);
  EXPECT_EQ(encodeOrDie(pointCloud(p), EncodeOptions{}), encodeOrDie(pointCloud(p), EncodeOptions{}));
}

// The encoder lists cells in the order of kdOrder() (kd_order.h); the
// decoder keeps its cells in an order of its own making (children after
// their parents' earlier siblings, one-vertex cells merged in). A complete
// point cloud without coincident points comes out in the decoder's cell
// order, which must be the encoder's: sorted by kdOrder() it stays as it is.
TEST(PointCodec, DecodedCellsFollowTheEncodersKdOrder) {
  for (const uint32_t seed : {31u, 32u}) {
    EncodeOptions options;
    options.bits = 16;
    const std::vector<float> input = seed == 31 ? uniformCloud(3000, seed) : sphereSurface(3000, seed);
    const std::vector<uint8_t> bytes = encodeOrDie(pointCloud(input), options);
    Decoder decoder;
    ASSERT_TRUE(decoder.push(bytes.data(), bytes.size()).ok());
    ASSERT_TRUE(decoder.complete());
    const Header& h = decoder.header();
    const Complex decoded = decoder.snapshot();
    std::vector<uint32_t> coords(decoded.positions.size());
    for (size_t i = 0; i < coords.size(); ++i)
      coords[i] = uint32_t(std::llround((double(decoded.positions[i]) - h.origin[i % 3]) / h.step));
    const KdOrder order = kdOrder(coords, SplitSchedule(h));
    ASSERT_EQ(std::adjacent_find(order.keys.begin(), order.keys.end()), order.keys.end()) << "coincident points";
    for (uint32_t i = 0; i < order.vertices.size(); ++i) ASSERT_EQ(order.vertices[i], i) << "seed " << seed;
  }
}

}  // namespace
}  // namespace kdmesh::test
