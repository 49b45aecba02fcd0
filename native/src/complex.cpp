// Small definitions of the public data types in kdmesh.h.
#include <algorithm>

#include "kdmesh/kdmesh.h"

namespace kdmesh {

size_t Complex::simplexCount(int dimension) const {
  switch (dimension) {
    case 0: return points.size();
    case 1: return edges.size() / 2;
    case 2: return triangles.size() / 3;
    case 3: return tetrahedra.size() / 4;
    default: return 0;
  }
}

size_t attributeTypeBytes(AttributeType type) {
  switch (type) {
    case AttributeType::UInt8:
    case AttributeType::Int8: return 1;
    case AttributeType::UInt16:
    case AttributeType::Int16: return 2;
    case AttributeType::UInt32:
    case AttributeType::Int32:
    case AttributeType::Float32: return 4;
  }
  return 0;
}

const char* attributeTypeName(AttributeType type) {
  switch (type) {
    case AttributeType::UInt8: return "uint8";
    case AttributeType::Int8: return "int8";
    case AttributeType::UInt16: return "uint16";
    case AttributeType::Int16: return "int16";
    case AttributeType::UInt32: return "uint32";
    case AttributeType::Int32: return "int32";
    case AttributeType::Float32: return "float32";
  }
  return "unknown";
}

const char* errorCodeName(ErrorCode code) {
  switch (code) {
    case ErrorCode::Ok: return "ok";
    case ErrorCode::InvalidArgument: return "invalid-argument";
    case ErrorCode::InvalidInput: return "invalid-input";
    case ErrorCode::Unsupported: return "unsupported";
    case ErrorCode::BadMagic: return "bad-magic";
    case ErrorCode::UnsupportedVersion: return "unsupported-version";
    case ErrorCode::CorruptHeader: return "corrupt-header";
    case ErrorCode::CorruptChunk: return "corrupt-chunk";
    case ErrorCode::Truncated: return "truncated";
    case ErrorCode::TrailingBytes: return "trailing-bytes";
    case ErrorCode::LimitExceeded: return "limit-exceeded";
  }
  return "unknown";
}

int Header::axisBits(int axis) const {
  uint32_t v = gridMax[size_t(axis)];
  int bits = 0;
  for (; v != 0; v >>= 1) ++bits;
  return bits;
}

int Header::depth() const { return axisBits(0) + axisBits(1) + axisBits(2); }

uint64_t Header::totalBytes() const { return headerBytes + bodyBytes; }

}  // namespace kdmesh
