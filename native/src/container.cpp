#include "container.h"

#include <cmath>
#include <cstring>
#include <string>

#include "crc32.h"

namespace kdmesh {
namespace {

constexpr uint8_t kMagic[4] = {0x89, 'K', 'D', 'M'};
constexpr size_t kOffVersion = 4, kOffHeaderBytes = 6;
static_assert(kHeaderPrefixBytes == kOffHeaderBytes + 1, "header prefix");
// The fixed bytes, ten 32-bit varints (the body size's has at most 9 bytes),
// grid parameters (float32 mode's are three 32-bit varints) and checksum.
static_assert(kMaxHeaderBytes == kHeaderPrefixBytes + 3 + 9 * 5 + 9 + 20 + 4, "header size");
// The mode byte: quantization in bit 0, whether simplices carry labels in
// bit 1, the highest dimension in bits 2-3, the number of vertex attributes
// in bits 4-7. The coding byte: bit 0 set for a stream coded for fast
// decoding; the other bits are 0.
static_assert(kMaxAttributes == 15, "the attribute count has four bits");
constexpr uint8_t kFastDecodeBit = 1;

void put16(uint8_t* p, uint16_t v) {
  p[0] = uint8_t(v);
  p[1] = uint8_t(v >> 8);
}
void put32(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = uint8_t(v >> (8 * i));
}
uint16_t get16(const uint8_t* p) { return uint16_t(p[0] | p[1] << 8); }
uint32_t get32(const uint8_t* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

// IEEE-754 values as the little-endian bytes of their bit patterns.
void putFloat32(uint8_t*& p, float f) {
  uint32_t bits;
  std::memcpy(&bits, &f, 4);
  put32(p, bits);
  p += 4;
}
void putFloat64(uint8_t*& p, double d) {
  uint64_t bits;
  std::memcpy(&bits, &d, 8);
  put32(p, uint32_t(bits));
  put32(p + 4, uint32_t(bits >> 32));
  p += 8;
}
float getFloat32(const uint8_t*& p) {
  const uint32_t bits = get32(p);
  p += 4;
  float f;
  std::memcpy(&f, &bits, 4);
  return f;
}
double getFloat64(const uint8_t*& p) {
  const uint64_t bits = uint64_t(get32(p)) | uint64_t(get32(p + 4)) << 32;
  p += 8;
  double d;
  std::memcpy(&d, &bits, 8);
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
    // Every decoded coordinate lies between the origin and its far end,
    // which must be a finite float32 too.
    for (int a = 0; a < 3; ++a)
      if (!std::isfinite(float(double(h.origin[size_t(a)]) + double(h.gridMax[size_t(a)]) * h.step)))
        return corrupt("the grid's far corner is not a finite float32");
  } else if (h.quantization == Quantization::Float32) {
    if (h.bits != 32 && h.bits != 64) return corrupt("float mode must have 32 or 64 bits");
    // A float64 stream's residuals are two attributes.
    if (h.float64() && h.attributeCount < 2) return corrupt("float64 mode without its residual attributes");
    for (int a = 0; a < 3; ++a) {
      // Every 32-bit image is a float (infinities and NaNs included); the
      // coded range must not run past the last one.
      const uint64_t low = h.floatImageMin[size_t(a)];
      const uint64_t high = low + h.gridMax[size_t(a)];
      if (high > 0xffffffffu) return corrupt("float range runs past the largest float image");
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
  if (h.labelled && h.maxDimension == 0) return corrupt("labels without simplices");
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
  // A body without chunks holds the attribute table alone, if any.
  if (h.bodyBytes < uint64_t(h.chunkCount) * (2 + kChunkChecksumBytes) ||
      (h.chunkCount == 0 && h.attributeCount == 0) != (h.bodyBytes == 0))
    return corrupt("chunk count does not fit the body size");
  // What a stream decodes to is bounded by its size: a complete decode
  // needs every byte the header announces.
  const uint64_t bytes = h.headerBytes + h.bodyBytes;
  // count <= perByte · bytes, without overflow.
  auto beyond = [bytes](uint64_t count, uint64_t perByte) {
    return perByte == 0 ? count > 0 : count / perByte + (count % perByte != 0) > bytes;
  };
  if (beyond(h.vertexCount, limits.maxVerticesPerByte))
    return Status::error(ErrorCode::LimitExceeded,
                         "a stream of " + std::to_string(bytes) + " bytes with " + std::to_string(h.vertexCount) +
                             " vertices: more than the decoder limit of " +
                             std::to_string(limits.maxVerticesPerByte) + " vertices per byte");
  if (beyond(simplices, limits.maxSimplicesPerByte))
    return Status::error(ErrorCode::LimitExceeded,
                         "a stream of " + std::to_string(bytes) + " bytes with " + std::to_string(simplices) +
                             " simplices: more than the decoder limit of " +
                             std::to_string(limits.maxSimplicesPerByte) + " simplices per byte");
  if (h.chunkCount == 0 && h.depth() != 0) return corrupt("stream has no chunks");
  // Vertices of a stream with attributes are told apart by splits, also
  // coincident ones; each attribute takes at least 5 bytes of the table.
  if (h.attributeCount > 0 && h.vertexCount > 1 && h.chunkCount == 0) return corrupt("stream has no chunks");
  // Labels need simplices, which need splits.
  if (h.labelled && h.chunkCount == 0) return corrupt("stream has no chunks");
  if (h.bodyBytes < uint64_t(h.attributeCount) * 5 + (h.attributeCount > 0 ? 4 : 0))
    return corrupt("the body cannot hold the attribute table");
  return Status::success();
}

}  // namespace

// Unsigned LEB128: seven bits per byte, low first, the high bit set on every
// byte but the last.
size_t putVarint(uint8_t* p, uint64_t v) {
  size_t n = 0;
  for (; v >= 0x80; v >>= 7) p[n++] = uint8_t(v | 0x80);
  p[n++] = uint8_t(v);
  return n;
}

Parsed readVarint(const uint8_t*& at, const uint8_t* end, size_t maxBytes, uint64_t limit, uint64_t& v) {
  v = 0;
  for (size_t i = 0; i < maxBytes; ++i) {
    if (at == end) return Parsed::Incomplete;
    const uint8_t byte = *at++;
    v |= uint64_t(byte & 0x7f) << (7 * i);
    if (!(byte & 0x80)) return v <= limit ? Parsed::Complete : Parsed::Malformed;
  }
  return Parsed::Malformed;
}

size_t writeHeader(const Header& h, uint8_t* out) {
  std::memcpy(out, kMagic, 4);
  put16(out + kOffVersion, kFormatVersion);
  uint8_t* at = out + kHeaderPrefixBytes;
  *at++ = uint8_t(uint8_t(h.quantization) | h.labelled << 1 | h.maxDimension << 2 | h.attributeCount << 4);
  *at++ = h.bits;
  *at++ = h.fastDecode ? kFastDecodeBit : 0;
  at += putVarint(at, h.vertexCount);
  for (const uint32_t count : h.simplexCounts) at += putVarint(at, count);
  for (const uint32_t max : h.gridMax) at += putVarint(at, max);
  at += putVarint(at, h.bodyBytes);
  at += putVarint(at, h.chunkCount);
  if (h.quantization == Quantization::Grid) {
    // The origin is a corner of the input's bounding box: floats.
    for (const double origin : h.origin) putFloat32(at, float(origin));
    putFloat64(at, h.step);
  } else {
    for (const uint32_t image : h.floatImageMin) at += putVarint(at, image);
  }
  const size_t size = size_t(at - out) + 4;
  out[kOffHeaderBytes] = uint8_t(size);
  put32(at, crc32(out, size - 4));
  return size;
}

Status headerSize(const uint8_t* in, size_t& size) {
  if (std::memcmp(in, kMagic, 4) != 0)
    return Status::error(ErrorCode::BadMagic, "not a kdmesh stream (bad magic bytes)");
  const uint16_t version = get16(in + kOffVersion);
  if (version != kFormatVersion)
    return Status::error(ErrorCode::UnsupportedVersion,
                         "stream format version " + std::to_string(version) +
                             " is not supported (this decoder reads version " +
                             std::to_string(kFormatVersion) + ")");
  size = in[kOffHeaderBytes];
  if (size < kHeaderPrefixBytes + 4 || size > kMaxHeaderBytes) return corrupt("bad header size");
  return Status::success();
}

Status readHeader(const uint8_t* in, size_t size, const DecoderLimits& limits, Header& h) {
  if (Status s = headerSize(in, size); !s.ok()) return s;
  if (size != in[kOffHeaderBytes]) return corrupt("header size mismatch");
  if (crc32(in, size - 4) != get32(in + size - 4)) return corrupt("checksum mismatch");
  h = Header{};
  h.version = kFormatVersion;
  h.headerBytes = uint8_t(size);
  const uint8_t* at = in + kHeaderPrefixBytes;
  const uint8_t* const end = in + size - 4;
  if (end - at < 3) return corrupt("truncated fields");
  const uint8_t mode = *at++;
  h.quantization = Quantization(mode & 1);
  h.labelled = mode >> 1 & 1;
  h.maxDimension = uint8_t(mode >> 2 & 3);
  h.attributeCount = uint8_t(mode >> 4);
  h.bits = *at++;
  const uint8_t coding = *at++;
  if (coding & ~kFastDecodeBit) return corrupt("unknown coding flags");
  h.fastDecode = coding & kFastDecodeBit;
  bool ok = true;
  auto u32 = [&](uint32_t& field) {
    uint64_t v = 0;
    ok = ok && readVarint(at, end, 5, 0xffffffffu, v) == Parsed::Complete;
    field = uint32_t(v);
  };
  u32(h.vertexCount);
  for (uint32_t& count : h.simplexCounts) u32(count);
  for (uint32_t& max : h.gridMax) u32(max);
  ok = ok && readVarint(at, end, 9, uint64_t(1) << 62, h.bodyBytes) == Parsed::Complete;
  u32(h.chunkCount);
  if (h.quantization == Quantization::Grid) {
    if (end - at < 20) return corrupt("truncated fields");
    for (double& origin : h.origin) origin = getFloat32(at);
    h.step = getFloat64(at);
  } else {
    for (uint32_t& image : h.floatImageMin) u32(image);
  }
  if (!ok || at != end) return corrupt("malformed fields");
  return validate(h, limits);
}

std::array<uint64_t, 4> simplexCaps(const Header& h) {
  const uint64_t edges = h.simplexCounts[1], triangles = h.simplexCounts[2],
                 tetrahedra = h.simplexCounts[3];
  return {0, edges + 3 * triangles + 6 * tetrahedra, triangles + 4 * tetrahedra, tetrahedra};
}

size_t writeChunkFrame(const ChunkFrame& frame, uint8_t* out) {
  const size_t n = putVarint(out, frame.payloadBytes);
  return n + putVarint(out + n, frame.splitCount);
}

namespace {
uint32_t chunkChecksum(const uint8_t* chunk, size_t checked, uint32_t index) {
  uint8_t position[4];
  put32(position, index);
  return crc32(chunk, checked, crc32(position, 4));
}
}  // namespace

void writeChunkChecksum(const uint8_t* chunk, size_t checked, uint32_t index, uint8_t* out) {
  put32(out, chunkChecksum(chunk, checked, index));
}

bool chunkChecksumMatches(const uint8_t* chunk, size_t checked, uint32_t index) {
  return chunkChecksum(chunk, checked, index) == get32(chunk + checked);
}

Parsed readChunkFrame(const uint8_t* in, size_t available, ChunkFrame& frame, size_t& size) {
  const uint8_t* at = in;
  uint32_t* const fields[2] = {&frame.payloadBytes, &frame.splitCount};
  for (uint32_t* field : fields) {
    uint64_t value = 0;
    if (const Parsed parsed = readVarint(at, in + available, 5, 0xffffffffu, value); parsed != Parsed::Complete)
      return parsed;
    *field = uint32_t(value);
  }
  size = size_t(at - in);
  return Parsed::Complete;
}

}  // namespace kdmesh
