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
