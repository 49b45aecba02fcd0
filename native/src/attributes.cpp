#include "attributes.h"

#include <cstring>
#include <set>

#include "crc32.h"

namespace kdmesh {
namespace {

bool knownType(AttributeType type) { return uint8_t(type) < kAttributeTypeCount; }

bool printableName(const std::string& name) {
  if (name.empty() || name.size() > kMaxAttributeNameBytes) return false;
  for (const char c : name)
    if (c < 0x20 || c > 0x7e) return false;
  return true;
}

}  // namespace

Status checkAttributes(const Complex& complex) {
  if (complex.attributes.size() > kMaxAttributes)
    return Status::error(ErrorCode::Unsupported, std::to_string(complex.attributes.size()) +
                                                     " vertex attributes: a stream carries at most " +
                                                     std::to_string(kMaxAttributes));
  std::set<std::string> names;
  for (const VertexAttribute& a : complex.attributes) {
    if (!printableName(a.name))
      return Status::error(ErrorCode::InvalidInput, "an attribute name must have 1 to " +
                                                        std::to_string(kMaxAttributeNameBytes) +
                                                        " printable ASCII characters");
    if (!names.insert(a.name).second)
      return Status::error(ErrorCode::InvalidInput, "two attributes named '" + a.name + "'");
    if (!knownType(a.type) || a.components < 1 || a.components > 4)
      return Status::error(ErrorCode::InvalidInput,
                           "attribute '" + a.name + "' must have 1 to 4 components of a known type");
    if (a.values.size() != complex.vertexCount() * a.valueBytes())
      return Status::error(ErrorCode::InvalidInput, "attribute '" + a.name + "' has " +
                                                        std::to_string(a.values.size()) + " bytes of values, " +
                                                        std::to_string(complex.vertexCount() * a.valueBytes()) +
                                                        " expected (" + std::to_string(a.components) + " " +
                                                        attributeTypeName(a.type) + " per vertex)");
  }
  return Status::success();
}

void writeAttributeTable(const std::vector<VertexAttribute>& attributes, uint32_t root, std::vector<uint8_t>& out) {
  const size_t start = out.size();
  for (const VertexAttribute& a : attributes) {
    out.push_back(uint8_t(a.type));
    out.push_back(a.components);
    out.push_back(uint8_t(a.name.size()));
    out.insert(out.end(), a.name.begin(), a.name.end());
    const uint8_t* value = a.values.data() + size_t(root) * a.valueBytes();
    out.insert(out.end(), value, value + a.valueBytes());
  }
  const uint32_t crc = crc32(out.data() + start, out.size() - start);
  for (int i = 0; i < 4; ++i) out.push_back(uint8_t(crc >> (8 * i)));
}

Parsed readAttributeTable(const uint8_t* in, size_t available, uint8_t count, std::vector<VertexAttribute>& out,
                          size_t& size, Status& error) {
  auto malformed = [&error](const std::string& what) {
    error = Status::error(ErrorCode::CorruptHeader, "corrupt attribute table: " + what);
    return Parsed::Malformed;
  };
  std::vector<VertexAttribute> table;
  size_t at = 0;
  for (uint8_t i = 0; i < count; ++i) {
    if (available - at < 3) return Parsed::Incomplete;
    VertexAttribute a;
    a.type = AttributeType(in[at]);
    a.components = in[at + 1];
    const size_t nameBytes = in[at + 2];
    at += 3;
    if (!knownType(a.type) || a.components < 1 || a.components > 4) return malformed("unknown attribute type");
    if (nameBytes < 1 || nameBytes > kMaxAttributeNameBytes) return malformed("bad name length");
    if (available - at < nameBytes + a.valueBytes()) return Parsed::Incomplete;
    a.name.assign(reinterpret_cast<const char*>(in + at), nameBytes);
    at += nameBytes;
    if (!printableName(a.name)) return malformed("name is not printable ASCII");
    for (const VertexAttribute& other : table)
      if (other.name == a.name) return malformed("two attributes named '" + a.name + "'");
    a.values.assign(in + at, in + at + a.valueBytes());
    at += a.valueBytes();
    table.push_back(std::move(a));
  }
  if (available - at < 4) return Parsed::Incomplete;
  const uint32_t stored = uint32_t(in[at]) | uint32_t(in[at + 1]) << 8 | uint32_t(in[at + 2]) << 16 |
                          uint32_t(in[at + 3]) << 24;
  if (crc32(in, at) != stored) return malformed("checksum mismatch");
  size = at + 4;
  out = std::move(table);
  return Parsed::Complete;
}

AttributeCoder::AttributeCoder(const std::vector<VertexAttribute>& attributes) {
  size_t models = 0;
  for (const VertexAttribute& a : attributes) {
    const int bytes = int(attributeTypeBytes(a.type));
    layouts_.push_back({a.type, a.components, bytes, 8 * bytes,
                        bytes == 4 ? 0xffffffffu : (uint32_t(1) << (8 * bytes)) - 1, models});
    models += size_t(a.components) * kLengthClasses * kLengthClasses;
  }
  models_.resize(models);
}

uint32_t AttributeCoder::image(const Layout& layout, const uint8_t* values, int component) {
  const uint8_t* at = values + size_t(component) * size_t(layout.bytes);
  uint32_t v = 0;
  std::memcpy(&v, at, size_t(layout.bytes));  // little-endian, as WebAssembly and x86
  if (layout.type == AttributeType::Float32) v = v & 0x80000000u ? ~v : v | 0x80000000u;
  return v;
}

void AttributeCoder::store(const Layout& layout, uint8_t* values, int component, uint32_t image) {
  if (layout.type == AttributeType::Float32) image = image & 0x80000000u ? image & 0x7fffffffu : ~image;
  std::memcpy(values + size_t(component) * size_t(layout.bytes), &image, size_t(layout.bytes));
}

}  // namespace kdmesh
