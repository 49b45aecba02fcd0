// Helpers shared by the codec tests.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <unordered_map>
#include <vector>

#include "kdmesh/kdmesh.h"

namespace kdmesh::test {

using Bits3 = std::array<uint32_t, 3>;

inline std::vector<Bits3> sortedBitPatterns(const std::vector<float>& positions) {
  std::vector<Bits3> v(positions.size() / 3);
  for (size_t i = 0; i < v.size(); ++i) std::memcpy(v[i].data(), &positions[3 * i], 12);
  std::sort(v.begin(), v.end());
  return v;
}

inline Complex pointCloud(std::vector<float> positions) {
  Complex c;
  c.positions = std::move(positions);
  return c;
}

inline std::vector<uint8_t> encodeOrDie(const Complex& c, const EncodeOptions& o) {
  EncodeResult r = encode(c, o);
  EXPECT_TRUE(r.status.ok()) << r.status.message;
  return r.bytes;
}

// Largest distance from a point of `from` to its nearest point of `to`, or
// +inf if some point has no neighbour within `radius` (a hash grid of cell
// `radius` keeps this linear).
inline double maxNearestDistance(const std::vector<float>& from, const std::vector<float>& to,
                                 double radius) {
  if (radius <= 0 || !std::isfinite(radius)) radius = 1e-30;
  auto key = [radius](double x, double y, double z) {
    const int64_t i = int64_t(std::floor(x / radius)), j = int64_t(std::floor(y / radius)),
                  k = int64_t(std::floor(z / radius));
    return uint64_t(i * 73856093) ^ uint64_t(j * 19349663) ^ uint64_t(k * 83492791);
  };
  std::unordered_multimap<uint64_t, size_t> grid;
  grid.reserve(to.size() / 3);
  for (size_t i = 0; i < to.size() / 3; ++i) grid.emplace(key(to[3 * i], to[3 * i + 1], to[3 * i + 2]), i);
  double worst = 0;
  for (size_t i = 0; i < from.size() / 3; ++i) {
    const double x = from[3 * i], y = from[3 * i + 1], z = from[3 * i + 2];
    double best = INFINITY;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          auto range = grid.equal_range(key(x + dx * radius, y + dy * radius, z + dz * radius));
          for (auto it = range.first; it != range.second; ++it) {
            const size_t j = it->second;
            const double ex = x - to[3 * j], ey = y - to[3 * j + 1], ez = z - to[3 * j + 2];
            best = std::min(best, std::sqrt(ex * ex + ey * ey + ez * ez));
          }
        }
    if (best > radius) return INFINITY;
    worst = std::max(worst, best);
  }
  return worst;
}

}  // namespace kdmesh::test
