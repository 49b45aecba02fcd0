// The stream container: a header followed by length-prefixed, checksummed
// chunks. Counts and sizes are variable-length integers, so the container
// costs a small model tens of bytes, not hundreds. See docs/FORMAT.md for
// the byte layout.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "kdmesh/kdmesh.h"

namespace kdmesh {

constexpr uint16_t kFormatVersion = 26;

// What a read of bytes that may not all have arrived found.
enum class Parsed { Complete, Incomplete, Malformed };

// Unsigned LEB128: seven bits per byte, low first, the high bit set on every
// byte but the last. Writes at most 10 bytes and returns how many.
size_t putVarint(uint8_t* p, uint64_t v);
// Reads a varint of at most `maxBytes` bytes from [at, end): Incomplete if
// `end` comes first, Malformed if it is longer or above `limit`.
Parsed readVarint(const uint8_t*& at, const uint8_t* end, size_t maxBytes, uint64_t limit, uint64_t& v);

// Writes the header (its headerBytes field is ignored) and returns its size.
size_t writeHeader(const Header& header, uint8_t* out /* kMaxHeaderBytes */);
// The size of the header that starts with these bytes, after checking its
// magic bytes and version.
Status headerSize(const uint8_t* in /* kHeaderPrefixBytes */, size_t& size);
// Parses and validates a header of `size` bytes: checksum, layout and every
// field's range. Limits are checked here so nothing is allocated for a
// hostile header.
Status readHeader(const uint8_t* in, size_t size, const DecoderLimits& limits, Header& header);

// Upper bounds on the simplices of each dimension 1..3 that the complex can
// hold at any level (maximal ones and their faces): coarser levels never
// have more simplices of a dimension than the complete complex.
std::array<uint64_t, 4> simplexCaps(const Header& header);

// A chunk is its frame (the two counts below), its payload, and a CRC-32 of
// both.
struct ChunkFrame {
  uint32_t payloadBytes = 0;
  uint32_t splitCount = 0;
};
constexpr size_t kMaxChunkFrameBytes = 10;
constexpr size_t kChunkChecksumBytes = 4;

// Writes the frame and returns its size.
size_t writeChunkFrame(const ChunkFrame& frame, uint8_t* out /* kMaxChunkFrameBytes */);
// The checksum after a chunk's first `checked` bytes (frame and payload):
// a CRC-32 of the chunk's index in the stream (4 bytes, little-endian) and
// those bytes, so that a chunk moved, dropped or repeated fails it.
void writeChunkChecksum(const uint8_t* chunk, size_t checked, uint32_t index, uint8_t* out /* kChunkChecksumBytes */);
bool chunkChecksumMatches(const uint8_t* chunk, size_t checked, uint32_t index);
// Reads the frame at the start of in[0..available); `size` gets its size.
Parsed readChunkFrame(const uint8_t* in, size_t available, ChunkFrame& frame, size_t& size);

}  // namespace kdmesh
