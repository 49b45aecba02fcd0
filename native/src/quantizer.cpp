#include "quantizer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <string>

namespace kdmesh {
namespace {

uint32_t floatBits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

float bitsToFloat(uint32_t u) {
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}

uint32_t orderedImage(float f) {
  const uint32_t u = floatBits(f);
  return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}

float fromOrderedImage(uint32_t image) {
  return bitsToFloat((image & 0x80000000u) ? (image ^ 0x80000000u) : ~image);
}

// Images of -FLT_MAX and FLT_MAX: below the first lie -infinity and the
// negative NaNs, above the second +infinity and the positive NaNs.
constexpr uint32_t kLowestFiniteImage = 0x00800000u;
constexpr uint32_t kHighestFiniteImage = 0xff7fffffu;

Status checkFinite(const std::vector<float>& positions) {
  for (size_t i = 0; i < positions.size(); ++i) {
    if (!std::isfinite(positions[i])) {
      static const char* kAxis = "xyz";
      return Status::error(ErrorCode::InvalidInput,
                           "vertex " + std::to_string(i / 3) + " has " +
                               (std::isnan(positions[i]) ? "a NaN" : "an infinite") + " " +
                               kAxis[i % 3] + " coordinate; exact mode (--exact) keeps it");
    }
  }
  return Status::success();
}

void quantizeFloat32(const std::vector<float>& positions, Header& header,
                     std::vector<uint32_t>& coords) {
  const size_t n = positions.size() / 3;
  std::array<uint32_t, 3> lo{0xffffffffu, 0xffffffffu, 0xffffffffu}, hi{0, 0, 0};
  for (size_t i = 0; i < n * 3; ++i) {
    const uint32_t image = orderedImage(positions[i]);
    lo[i % 3] = std::min(lo[i % 3], image);
    hi[i % 3] = std::max(hi[i % 3], image);
  }
  header.quantization = Quantization::Float32;
  header.bits = 32;
  for (int a = 0; a < 3; ++a) {
    header.floatImageMin[size_t(a)] = lo[size_t(a)];
    header.gridMax[size_t(a)] = hi[size_t(a)] - lo[size_t(a)];
  }
  coords.resize(n * 3);
  for (size_t i = 0; i < n * 3; ++i) coords[i] = orderedImage(positions[i]) - lo[i % 3];
}

void quantizeGrid(const std::vector<float>& positions, int bits, Header& header,
                  std::vector<uint32_t>& coords) {
  const size_t n = positions.size() / 3;
  std::array<float, 3> lo{positions[0], positions[1], positions[2]}, hi = lo;
  for (size_t i = 0; i < n * 3; ++i) {
    lo[i % 3] = std::min(lo[i % 3], positions[i]);
    hi[i % 3] = std::max(hi[i % 3], positions[i]);
  }
  // Differences of floats are computed in double the same way for the extent
  // and for every vertex, so rounding stays monotone and no coordinate can
  // exceed gridMax.
  std::array<double, 3> extent{};
  double longest = 0;
  for (int a = 0; a < 3; ++a) {
    extent[size_t(a)] = double(hi[size_t(a)]) - double(lo[size_t(a)]);
    longest = std::max(longest, extent[size_t(a)]);
  }
  double step = longest / double((uint32_t(1) << bits) - 1);
  if (longest > 0 && step == 0) step = longest;  // extent in the denormals
  header.quantization = Quantization::Grid;
  header.bits = uint8_t(bits);
  header.step = step;
  for (int a = 0; a < 3; ++a) {
    header.origin[size_t(a)] = lo[size_t(a)];
    header.gridMax[size_t(a)] = step > 0 ? uint32_t(std::llround(extent[size_t(a)] / step)) : 0;
  }
  coords.resize(n * 3);
  for (size_t i = 0; i < n * 3; ++i) {
    const double offset = double(positions[i]) - double(lo[i % 3]);
    coords[i] = step > 0 ? uint32_t(std::llround(offset / step)) : 0;
  }
}

}  // namespace

Status quantize(const std::vector<float>& positions, const EncodeOptions& options,
                Header& header, std::vector<uint32_t>& coords) {
  // Float32 mode codes bit patterns, so infinities and NaNs (with their
  // sign and payload) are values like any other; a grid has no place for them.
  if (options.exact) {
    quantizeFloat32(positions, header, coords);
    return Status::success();
  }
  if (Status s = checkFinite(positions); !s.ok()) return s;
  quantizeGrid(positions, options.bits, header, coords);
  return Status::success();
}

namespace {

// The bits of double(f), made by hand for NaNs: a conversion may change a
// NaN's payload (WebAssembly leaves it unspecified), and the decoder must
// widen exactly as the encoder did.
uint64_t widenedBits(float f) {
  const uint64_t u = floatBits(f);
  if (std::isnan(f)) return (u >> 31) << 63 | uint64_t(0x7ff) << 52 | (u & 0x7fffffu) << 29;
  const double d = f;
  uint64_t bits;
  std::memcpy(&bits, &d, 8);
  return bits;
}

}  // namespace

void splitFloat64(const std::vector<double>& positions64, std::vector<float>& positions,
                  VertexAttribute& low, VertexAttribute& high) {
  const size_t n = positions64.size();
  positions.resize(n);
  low = {kResidualNames[0], AttributeType::Int32, 3, std::vector<uint8_t>(n * 4), {}};
  high = {kResidualNames[1], AttributeType::Int32, 3, std::vector<uint8_t>(n * 4), {}};
  for (size_t i = 0; i < n; ++i) {
    const double x = positions64[i];
    positions[i] = float(x);
    uint64_t bits;
    std::memcpy(&bits, &x, 8);
    const uint64_t residual = bits - widenedBits(positions[i]);
    // The low part as a signed 32-bit value, so that small negative
    // residuals leave the high part 0.
    const uint32_t lowPart = uint32_t(residual);
    const uint32_t highPart = uint32_t((residual - uint64_t(int64_t(int32_t(lowPart)))) >> 32);
    std::memcpy(&low.values[i * 4], &lowPart, 4);
    std::memcpy(&high.values[i * 4], &highPart, 4);
  }
}

void joinFloat64(const std::vector<float>& positions, const VertexAttribute& low, const VertexAttribute& high,
                 std::vector<double>& positions64) {
  const size_t n = positions.size();
  positions64.resize(n);
  for (size_t i = 0; i < n; ++i) {
    uint32_t lowPart, highPart;
    std::memcpy(&lowPart, &low.values[i * 4], 4);
    std::memcpy(&highPart, &high.values[i * 4], 4);
    uint64_t bits = widenedBits(positions[i]);
    bits += uint64_t(int64_t(int32_t(lowPart))) + (uint64_t(highPart) << 32);
    std::memcpy(&positions64[i], &bits, 8);
  }
}

bool areResidualAttributes(const VertexAttribute& low, const VertexAttribute& high) {
  for (const VertexAttribute* a : {&low, &high})
    if (a->type != AttributeType::Int32 || a->components != 3) return false;
  return low.name == kResidualNames[0] && high.name == kResidualNames[1];
}

Dequantizer::Dequantizer(const Header& header) : header_(header) {}

float Dequantizer::position(int axis, uint32_t lo, uint32_t hi) const {
  const size_t a = size_t(axis);
  if (header_.quantization == Quantization::Float32) {
    const uint32_t base = header_.floatImageMin[a];
    uint32_t low = base + lo, high = base + hi;
    if (low == high) return fromOrderedImage(low);
    // A range that reaches infinities or NaNs stands for its finite part,
    // so that a coarse vertex gets a number; a range beyond the finite
    // floats stands for its end nearest to them (an infinity if it holds one).
    low = std::max(low, kLowestFiniteImage);
    high = std::min(high, kHighestFiniteImage);
    if (low > high) return fromOrderedImage(low > kHighestFiniteImage ? low : high);
    return float((double(fromOrderedImage(low)) + double(fromOrderedImage(high))) * 0.5);
  }
  const double centre = (double(lo) + double(hi)) * 0.5;
  return float(header_.origin[a] + centre * header_.step);
}

}  // namespace kdmesh
