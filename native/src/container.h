// The stream container: a fixed header followed by length-prefixed chunks.
// See docs/FORMAT.md for the byte layout.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "kdmesh/kdmesh.h"

namespace kdmesh {

constexpr uint16_t kFormatVersion = 8;

void writeHeader(const Header& header, uint8_t* out /* kHeaderBytes */);
// Parses and validates a header: magic, version, checksum and every field's
// range. Limits are checked here so nothing is allocated for a hostile header.
Status readHeader(const uint8_t* in /* kHeaderBytes */, const DecoderLimits& limits,
                  Header& header);

// Upper bounds on the simplices of each dimension 1..3 that the complex can
// hold at any level (maximal ones and their faces): coarser levels never
// have more simplices of a dimension than the complete complex.
std::array<uint64_t, 4> simplexCaps(const Header& header);

struct ChunkFrame {
  uint32_t payloadBytes = 0;
  uint32_t splitCount = 0;
  uint32_t checksum = 0;
};

void writeChunkFrame(const ChunkFrame& frame, uint8_t* out /* kChunkFrameBytes */);
ChunkFrame readChunkFrame(const uint8_t* in /* kChunkFrameBytes */);

}  // namespace kdmesh
