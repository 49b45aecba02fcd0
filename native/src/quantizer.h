// Float positions <-> integer grid coordinates.
//
// Grid mode maps the bounding box onto an isotropic grid whose longest axis
// has 2^bits - 1 steps. Float32 mode maps every float to its order-preserving
// 32-bit integer image (negative floats bit-inverted, positive ones with the
// sign bit set), offset by the smallest image per axis, so that the kd-tree
// codes the exact bits and a cell is an interval of consecutive floats.
#pragma once

#include <cstdint>
#include <vector>

#include "kdmesh/kdmesh.h"

namespace kdmesh {

// Fills the quantization fields of `header` (quantization, bits, gridMax,
// origin, step, floatImageMin) and writes 3 integer coordinates per vertex.
// Float32 mode keeps NaN and infinite coordinates (every bit pattern has an
// image); grid mode fails on them, naming the first such vertex.
Status quantize(const std::vector<float>& positions, const EncodeOptions& options,
                Header& header, std::vector<uint32_t>& coords);

// Float64 streams (Header::float64()): each double x is coded as its
// float32 rounding f, in the kd-tree, and the residual bits(x) −
// bits(double(f)) modulo 2^64 (zero when x is a float32; x and f have the
// same sign, so it is small unless x is beyond the float32 range or a NaN
// with a payload float32 cannot hold), split into an int32 low part and the
// int32 rest: two hidden attributes of 3 components at the end of the
// table, named kResidualNames.
constexpr const char* kResidualNames[2] = {"kdmesh:float64-low", "kdmesh:float64-high"};
// `positions64` as float32 roundings and residual attributes.
void splitFloat64(const std::vector<double>& positions64, std::vector<float>& positions,
                  VertexAttribute& low, VertexAttribute& high);
// The doubles back from the roundings and the residual attributes' values.
void joinFloat64(const std::vector<float>& positions, const VertexAttribute& low, const VertexAttribute& high,
                 std::vector<double>& positions64);
// Whether `low` and `high` are residual attributes (names, types, components).
bool areResidualAttributes(const VertexAttribute& low, const VertexAttribute& high);

class Dequantizer {
 public:
  explicit Dequantizer(const Header& header);
  // Position of the integer coordinate range [lo, hi] along `axis`: the
  // coordinate itself when lo == hi, the centre of the range otherwise
  // (in float32 mode, of the range's finite floats: see position()).
  float position(int axis, uint32_t lo, uint32_t hi) const;

 private:
  Header header_;
};

}  // namespace kdmesh
