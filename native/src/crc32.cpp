#include "crc32.h"

#include <array>

namespace kdmesh {
namespace {

// Slice-by-4 tables: four bytes per step keeps checksumming a small fraction
// of decode time.
struct Crc32Tables {
  std::array<std::array<uint32_t, 256>, 4> t{};
  Crc32Tables() {
    for (uint32_t i = 0; i < 256; ++i) {
      uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[0][i] = c;
    }
    for (uint32_t i = 0; i < 256; ++i)
      for (int s = 1; s < 4; ++s) t[s][i] = (t[s - 1][i] >> 8) ^ t[0][t[s - 1][i] & 0xff];
  }
};

}  // namespace

uint32_t crc32(const uint8_t* data, size_t size, uint32_t previous) {
  static const Crc32Tables tables;
  const auto& t = tables.t;
  uint32_t c = previous ^ 0xffffffffu;
  for (; size >= 4; size -= 4, data += 4) {
    c ^= uint32_t(data[0]) | uint32_t(data[1]) << 8 | uint32_t(data[2]) << 16 |
         uint32_t(data[3]) << 24;
    c = t[3][c & 0xff] ^ t[2][(c >> 8) & 0xff] ^ t[1][(c >> 16) & 0xff] ^ t[0][c >> 24];
  }
  for (; size > 0; --size) c = t[0][(c ^ *data++) & 0xff] ^ (c >> 8);
  return c ^ 0xffffffffu;
}

}  // namespace kdmesh
