#include "kd_order.h"

#include <array>
#include <utility>

namespace kdmesh {
namespace {

// Contribution to the key of each byte of each coordinate: the key is the OR
// of twelve table entries instead of a loop over every level.
class KeyTables {
 public:
  explicit KeyTables(const SplitSchedule& schedule) : table_(3 * 4 * 256, 0) {
    std::array<KdKey, 3 * 32> keyBitOfCoordinateBit{};
    for (int level = 0; level < schedule.levels; ++level) {
      const int axis = schedule.axis[size_t(level)];
      keyBitOfCoordinateBit[size_t(axis * 32 + schedule.splitBit(level))] =
          KdKey(1) << (schedule.levels - 1 - level);
    }
    for (int axis = 0; axis < 3; ++axis)
      for (int byte = 0; byte < 4; ++byte)
        for (uint32_t value = 0; value < 256; ++value) {
          KdKey bits = 0;
          for (int b = 0; b < 8; ++b)
            if (value >> b & 1) bits |= keyBitOfCoordinateBit[size_t(axis * 32 + byte * 8 + b)];
          table_[size_t((axis * 4 + byte) * 256) + value] = bits;
        }
  }

  KdKey key(const uint32_t* xyz) const {
    KdKey key = 0;
    for (int axis = 0; axis < 3; ++axis)
      for (int byte = 0; byte < 4; ++byte)
        key |= table_[size_t((axis * 4 + byte) * 256) + (xyz[axis] >> (8 * byte) & 0xff)];
    return key;
  }

 private:
  std::vector<KdKey> table_;
};

constexpr int kDigitBits = 11;
constexpr uint32_t kDigits = 1u << kDigitBits;

}  // namespace

// Least-significant-digit radix sort: linear in the vertex count, stable, and
// a pass is skipped when every key has the same digit.
KdOrder kdOrder(const std::vector<uint32_t>& coords, const SplitSchedule& schedule) {
  const size_t n = coords.size() / 3;
  const KeyTables tables(schedule);
  KdOrder order;
  order.keys.resize(n);
  order.vertices.resize(n);
  for (size_t i = 0; i < n; ++i) {
    order.keys[i] = tables.key(&coords[3 * i]);
    order.vertices[i] = uint32_t(i);
  }
  std::vector<KdKey> keys(n);
  std::vector<uint32_t> vertices(n);
  std::vector<uint32_t> start(kDigits);
  for (int shift = 0; shift < schedule.levels; shift += kDigitBits) {
    std::fill(start.begin(), start.end(), 0);
    for (const KdKey key : order.keys) ++start[size_t(key >> shift) & (kDigits - 1)];
    if (n > 0 && start[size_t(order.keys[0] >> shift) & (kDigits - 1)] == n) continue;
    uint32_t sum = 0;
    for (uint32_t& s : start) sum += std::exchange(s, sum);
    for (size_t i = 0; i < n; ++i) {
      const uint32_t at = start[size_t(order.keys[i] >> shift) & (kDigits - 1)]++;
      keys[at] = order.keys[i];
      vertices[at] = order.vertices[i];
    }
    order.keys.swap(keys);
    order.vertices.swap(vertices);
  }
  return order;
}

}  // namespace kdmesh
