#include "container.h"

#include <cmath>
#include <cstring>
#include <string>

#include "crc32.h"

namespace kdmesh {
namespace {

constexpr uint8_t kMagic[4] = {0x89, 'K', 'D', 'M'};

// Field offsets of the header (docs/FORMAT.md).
enum : size_t {
  kOffMagic = 0,
  kOffVersion = 4,
  kOffHeaderBytes = 6,
  kOffQuantization = 8,
  kOffBits = 9,
  kOffMaxDimension = 10,
  kOffReserved = 11,
  kOffFlags = 12,
  kOffVertexCount = 16,
  kOffSimplexCounts = 20,
  kOffGridMax = 36,
  kOffQuantParams = 48,
  kOffBodyBytes = 80,
  kOffChunkCount = 88,
  kOffChecksum = 92,
};
static_assert(kOffChecksum + 4 == kHeaderBytes, "header layout");

void put16(uint8_t* p, uint16_t v) {
  p[0] = uint8_t(v);
  p[1] = uint8_t(v >> 8);
}
void put32(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = uint8_t(v >> (8 * i));
}
void put64(uint8_t* p, uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = uint8_t(v >> (8 * i));
}
void putDouble(uint8_t* p, double d) {
  uint64_t v;
  std::memcpy(&v, &d, 8);
  put64(p, v);
}
uint16_t get16(const uint8_t* p) { return uint16_t(p[0] | p[1] << 8); }
uint32_t get32(const uint8_t* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}
uint64_t get64(const uint8_t* p) { return uint64_t(get32(p)) | uint64_t(get32(p + 4)) << 32; }
double getDouble(const uint8_t* p) {
  const uint64_t v = get64(p);
  double d;
  std::memcpy(&d, &v, 8);
  return d;
}

Status corrupt(const std::string& what) {
  return Status::error(ErrorCode::CorruptHeader, "corrupt header: " + what);
}

Status validate(const Header& h, const DecoderLimits& limits) {
  if (h.quantization == Quantization::Grid) {
    if (h.bits < 1 || h.bits > 30) return corrupt("grid bits out of range");
    for (int a = 0; a < 3; ++a) {
      if (h.gridMax[size_t(a)] >= (uint32_t(1) << h.bits))
        return corrupt("grid extent exceeds the grid bits");
      if (!std::isfinite(h.origin[size_t(a)])) return corrupt("origin is not finite");
    }
    if (!std::isfinite(h.step) || h.step < 0) return corrupt("grid step is not finite");
  } else if (h.quantization == Quantization::Float32) {
    if (h.bits != 32) return corrupt("float32 mode must have 32 bits");
    for (int a = 0; a < 3; ++a) {
      // Both ends of the coded range must be images of finite floats.
      const uint64_t low = h.floatImageMin[size_t(a)];
      const uint64_t high = low + h.gridMax[size_t(a)];
      if (low < 0x00800000u || high > 0xff7fffffu) return corrupt("float range is not finite");
    }
  } else {
    return corrupt("unknown quantization mode");
  }
  if (h.vertexCount == 0 || h.vertexCount >= (1u << 31)) return corrupt("bad vertex count");
  if (h.vertexCount > limits.maxVertices)
    return Status::error(ErrorCode::LimitExceeded,
                         "stream has " + std::to_string(h.vertexCount) +
                             " vertices, more than the decoder limit of " +
                             std::to_string(limits.maxVertices));
  if (h.maxDimension > 3) return corrupt("simplex dimension above 3");
  for (size_t d = size_t(h.maxDimension) + 1; d <= 3; ++d)
    if (h.simplexCounts[d] != 0) return corrupt("simplices above the maximum dimension");
  if (h.maxDimension > 0 && h.simplexCounts[h.maxDimension] == 0)
    return corrupt("no simplex of the maximum dimension");
  if (h.simplexCounts[0] > h.vertexCount) return corrupt("more isolated points than vertices");
  if (h.maxDimension == 0 && h.simplexCounts[0] != h.vertexCount)
    return corrupt("a point cloud must count every vertex as a point");
  const uint64_t simplices = uint64_t(h.simplexCounts[1]) + h.simplexCounts[2] + h.simplexCounts[3];
  if (simplices > limits.maxSimplices)
    return Status::error(ErrorCode::LimitExceeded,
                         "stream has " + std::to_string(simplices) +
                             " simplices, more than the decoder limit of " +
                             std::to_string(limits.maxSimplices));
  if (h.bodyBytes < uint64_t(h.chunkCount) * kChunkFrameBytes ||
      (h.chunkCount == 0) != (h.bodyBytes == 0))
    return corrupt("chunk count does not fit the body size");
  if (h.chunkCount == 0 && h.depth() != 0) return corrupt("stream has no chunks");
  return Status::success();
}

}  // namespace

void writeHeader(const Header& h, uint8_t* out) {
  std::memset(out, 0, kHeaderBytes);
  std::memcpy(out + kOffMagic, kMagic, 4);
  put16(out + kOffVersion, kFormatVersion);
  put16(out + kOffHeaderBytes, uint16_t(kHeaderBytes));
  out[kOffQuantization] = uint8_t(h.quantization);
  out[kOffBits] = h.bits;
  out[kOffMaxDimension] = h.maxDimension;
  put32(out + kOffVertexCount, h.vertexCount);
  for (size_t d = 0; d < 4; ++d) put32(out + kOffSimplexCounts + 4 * d, h.simplexCounts[d]);
  for (size_t a = 0; a < 3; ++a) put32(out + kOffGridMax + 4 * a, h.gridMax[a]);
  if (h.quantization == Quantization::Grid) {
    for (size_t a = 0; a < 3; ++a) putDouble(out + kOffQuantParams + 8 * a, h.origin[a]);
    putDouble(out + kOffQuantParams + 24, h.step);
  } else {
    for (size_t a = 0; a < 3; ++a) put32(out + kOffQuantParams + 4 * a, h.floatImageMin[a]);
  }
  put64(out + kOffBodyBytes, h.bodyBytes);
  put32(out + kOffChunkCount, h.chunkCount);
  put32(out + kOffChecksum, crc32(out, kOffChecksum));
}

Status readHeader(const uint8_t* in, const DecoderLimits& limits, Header& h) {
  if (std::memcmp(in + kOffMagic, kMagic, 4) != 0)
    return Status::error(ErrorCode::BadMagic, "not a kdmesh stream (bad magic bytes)");
  h = Header{};
  h.version = get16(in + kOffVersion);
  if (h.version != kFormatVersion)
    return Status::error(ErrorCode::UnsupportedVersion,
                         "stream format version " + std::to_string(h.version) +
                             " is not supported (this decoder reads version " +
                             std::to_string(kFormatVersion) + ")");
  if (get16(in + kOffHeaderBytes) != kHeaderBytes) return corrupt("unexpected header size");
  if (crc32(in, kOffChecksum) != get32(in + kOffChecksum)) return corrupt("checksum mismatch");
  if (in[kOffReserved] != 0 || get32(in + kOffFlags) != 0) return corrupt("unknown flags");
  h.quantization = Quantization(in[kOffQuantization]);
  h.bits = in[kOffBits];
  h.maxDimension = in[kOffMaxDimension];
  h.vertexCount = get32(in + kOffVertexCount);
  for (size_t d = 0; d < 4; ++d) h.simplexCounts[d] = get32(in + kOffSimplexCounts + 4 * d);
  for (size_t a = 0; a < 3; ++a) h.gridMax[a] = get32(in + kOffGridMax + 4 * a);
  if (h.quantization == Quantization::Grid) {
    for (size_t a = 0; a < 3; ++a) h.origin[a] = getDouble(in + kOffQuantParams + 8 * a);
    h.step = getDouble(in + kOffQuantParams + 24);
  } else {
    for (size_t a = 0; a < 3; ++a) h.floatImageMin[a] = get32(in + kOffQuantParams + 4 * a);
  }
  h.bodyBytes = get64(in + kOffBodyBytes);
  h.chunkCount = get32(in + kOffChunkCount);
  return validate(h, limits);
}

std::array<uint64_t, 4> simplexCaps(const Header& h) {
  const uint64_t edges = h.simplexCounts[1], triangles = h.simplexCounts[2],
                 tetrahedra = h.simplexCounts[3];
  return {0, edges + 3 * triangles + 6 * tetrahedra, triangles + 4 * tetrahedra, tetrahedra};
}

void writeChunkFrame(const ChunkFrame& frame, uint8_t* out) {
  put32(out, frame.payloadBytes);
  put32(out + 4, frame.splitCount);
  put32(out + 8, frame.checksum);
}

ChunkFrame readChunkFrame(const uint8_t* in) {
  return {get32(in), get32(in + 4), get32(in + 8)};
}

}  // namespace kdmesh
