// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320) of a byte range: the
// checksum that guards the stream header and every chunk payload.
#pragma once

#include <cstddef>
#include <cstdint>

namespace kdmesh {

// `previous`: the CRC of bytes that come before `data`, so that a range can
// be checksummed in pieces (0 for none).
uint32_t crc32(const uint8_t* data, size_t size, uint32_t previous = 0);

}  // namespace kdmesh
