// The order in which the kd-tree halves cells: the same on both sides.
//
// Every cell of one level is split along the same axis: the axis with the
// most integer-coordinate bits left, ties going to x, then y, then z. With
// equal bits this cycles x, y, z; on a flat bounding box it first refines the
// long axes, so that cells stay close to cubes in space.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "kdmesh/kdmesh.h"

namespace kdmesh {

struct SplitSchedule {
  explicit SplitSchedule(const Header& header) {
    std::array<int, 3> left{header.axisBits(0), header.axisBits(1), header.axisBits(2)};
    bits = left;
    levels = left[0] + left[1] + left[2];
    axis.resize(size_t(levels));
    consumed.resize(size_t(levels) + 1);
    std::array<uint8_t, 3> done{0, 0, 0};
    for (int level = 0; level < levels; ++level) {
      int a = 0;
      if (left[1] > left[a]) a = 1;
      if (left[2] > left[a]) a = 2;
      consumed[size_t(level)] = done;
      axis[size_t(level)] = uint8_t(a);
      --left[size_t(a)];
      ++done[size_t(a)];
    }
    consumed[size_t(levels)] = done;
  }

  // Bit position (from the least significant bit) of the coordinate bit that
  // the split at `level` decides.
  int splitBit(int level) const {
    const int a = axis[size_t(level)];
    return bits[size_t(a)] - 1 - consumed[size_t(level)][size_t(a)];
  }

  int levels = 0;
  std::array<int, 3> bits{};
  std::vector<uint8_t> axis;                      // split axis per level
  std::vector<std::array<uint8_t, 3>> consumed;   // bits fixed before level
};

// Splits a coder's running cost by kd-tree level (CodingCost::levels): the
// encoder and the decoder close each level after its last split.
class LevelCostTally {
 public:
  // `cells`: how many the level split; `bits`, `connectivityBits`: the
  // coder's running totals.
  void close(const SplitSchedule& schedule, int level, uint32_t cells, double bits, double connectivityBits,
             std::vector<LevelCost>& out) {
    const double levelConnectivityBits = connectivityBits - startConnectivityBits_;
    out.push_back({level < schedule.levels ? int(schedule.axis[size_t(level)]) : -1, cells,
                   bits - startBits_ - levelConnectivityBits, levelConnectivityBits});
    startBits_ = bits;
    startConnectivityBits_ = connectivityBits;
  }

 private:
  double startBits_ = 0, startConnectivityBits_ = 0;
};

}  // namespace kdmesh
