// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320) of a byte range: the
// checksum that guards the stream header and every chunk payload.
#pragma once

#include <cstddef>
#include <cstdint>

namespace kdmesh {

uint32_t crc32(const uint8_t* data, size_t size);

}  // namespace kdmesh
