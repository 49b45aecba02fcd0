// The stream container: a fixed header followed by length-prefixed chunks.
// See docs/FORMAT.md for the byte layout.
#pragma once

#include <cstdint>
#include <vector>

#include "kdmesh/kdmesh.h"

namespace kdmesh {

constexpr uint16_t kFormatVersion = 1;

void writeHeader(const Header& header, uint8_t* out /* kHeaderBytes */);
// Parses and validates a header: magic, version, checksum and every field's
// range. Limits are checked here so nothing is allocated for a hostile header.
Status readHeader(const uint8_t* in /* kHeaderBytes */, const DecoderLimits& limits,
                  Header& header);

struct ChunkFrame {
  uint32_t payloadBytes = 0;
  uint32_t splitCount = 0;
  uint32_t checksum = 0;
};

void writeChunkFrame(const ChunkFrame& frame, uint8_t* out /* kChunkFrameBytes */);
ChunkFrame readChunkFrame(const uint8_t* in /* kChunkFrameBytes */);

}  // namespace kdmesh
