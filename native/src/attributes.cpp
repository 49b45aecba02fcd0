#include "attributes.h"

#include <cmath>
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

// Bits per component of uniform quantization, and per octahedral coordinate.
constexpr int kMinUniformBits = 1, kMaxUniformBits = 24;
constexpr int kMinOctahedralBits = 2, kMaxOctahedralBits = 16;

bool isNormal(const VertexAttribute& a) {
  return a.name == "normal" && a.type == AttributeType::Float32 && a.components == 3;
}

// The encoder's uniform step is at least this fraction of the largest
// magnitude of the values: then float32 rounding moves a dequantized input
// value by at most about a quarter step, and quantizing it again gives
// back its image.
constexpr double kLeastRelativeStep = 1.0 / (1 << 22);

// Whether a uniform quantization's parameters are valid: finite, and the
// step not negative.
bool validUniform(float minimum, float step) { return std::isfinite(minimum) && std::isfinite(step) && step >= 0; }

uint32_t topOf(const AttributeQuantization& q) {
  return isOctahedral(q.kind) ? (uint32_t(1) << q.bits) - 2 : uint32_t((uint64_t(1) << q.bits) - 1);
}

float floatAt(const uint8_t* values, int component) {
  float f;
  std::memcpy(&f, values + 4 * component, 4);
  return f;
}

}  // namespace

Status chooseQuantization(const Complex& complex, const EncodeOptions& options,
                          std::vector<AttributeQuantization>& out) {
  // Normals of a surface are predicted better by its triangles, once
  // decoded, than by the neighbours' normals when a vertex is created.
  const bool surface = !complex.triangles.empty();
  if (options.attributeBits != 0 && (options.attributeBits < kMinUniformBits || options.attributeBits > kMaxUniformBits))
    return Status::error(ErrorCode::InvalidArgument, "attribute bits must be 1 to 24, or 0 for exact values");
  if (options.normalBits != 0 && (options.normalBits < kMinOctahedralBits || options.normalBits > kMaxOctahedralBits))
    return Status::error(ErrorCode::InvalidArgument, "normal bits must be 2 to 16, or 0 for exact normals");
  out.assign(complex.attributes.size(), {});
  const size_t n = complex.vertexCount();
  for (size_t i = 0; i < complex.attributes.size(); ++i) {
    const VertexAttribute& a = complex.attributes[i];
    AttributeQuantization& q = out[i];
    if (a.type != AttributeType::Float32) continue;
    if (options.normalBits > 0 && isNormal(a)) {
      q.kind = surface ? AttributeQuantization::GeometricOctahedral : AttributeQuantization::Octahedral;
      q.bits = uint8_t(options.normalBits);
    } else if (options.attributeBits > 0) {
      q.kind = AttributeQuantization::Uniform;
      q.bits = uint8_t(options.attributeBits);
    } else {
      continue;
    }
    for (size_t v = 0; v < n; ++v)
      for (int c = 0; c < a.components; ++c)
        if (!std::isfinite(floatAt(&a.values[v * a.valueBytes()], c)))
          return Status::error(ErrorCode::InvalidInput, "attribute '" + a.name + "' of vertex " + std::to_string(v) +
                                                            " is not finite: only exact attributes keep NaN and "
                                                            "infinities");
    if (q.kind != AttributeQuantization::Uniform) continue;
    const uint32_t top = topOf(q);
    for (int c = 0; c < a.components; ++c) {
      float low = INFINITY, high = -INFINITY;
      for (size_t v = 0; v < n; ++v) {
        const float x = floatAt(&a.values[v * a.valueBytes()], c);
        low = std::min(low, x);
        high = std::max(high, x);
      }
      if (n == 0) low = high = 0;
      // The smallest float32 step that covers the range in `top` steps, and
      // no finer than kLeastRelativeStep allows.
      const double wanted = std::max((double(high) - double(low)) / double(top),
                                     std::max(std::fabs(double(low)), std::fabs(double(high))) * kLeastRelativeStep);
      float step = float(wanted);
      if (double(step) < wanted) step = std::nextafter(step, INFINITY);
      if (high == low) step = 0;
      q.minimum[size_t(c)] = low;
      q.step[size_t(c)] = step;
    }
  }
  return Status::success();
}

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

namespace {

void putFloat(std::vector<uint8_t>& out, float value) {
  uint32_t bits;
  std::memcpy(&bits, &value, 4);
  for (int i = 0; i < 4; ++i) out.push_back(uint8_t(bits >> (8 * i)));
}

float getFloat(const uint8_t* in) {
  const uint32_t bits = uint32_t(in[0]) | uint32_t(in[1]) << 8 | uint32_t(in[2]) << 16 | uint32_t(in[3]) << 24;
  float value;
  std::memcpy(&value, &bits, 4);
  return value;
}

}  // namespace

void writeAttributeTable(const std::vector<VertexAttribute>& attributes,
                         const std::vector<AttributeQuantization>& quantization, uint32_t root,
                         std::vector<uint8_t>& out) {
  const size_t start = out.size();
  for (size_t i = 0; i < attributes.size(); ++i) {
    const VertexAttribute& a = attributes[i];
    const AttributeQuantization& q = quantization[i];
    out.push_back(uint8_t(a.type));
    out.push_back(a.components);
    out.push_back(uint8_t(a.name.size()));
    out.insert(out.end(), a.name.begin(), a.name.end());
    out.push_back(uint8_t(q.kind));
    if (q.kind != AttributeQuantization::Exact) out.push_back(q.bits);
    if (q.kind == AttributeQuantization::Uniform)
      for (int c = 0; c < a.components; ++c) {
        putFloat(out, q.minimum[size_t(c)]);
        putFloat(out, q.step[size_t(c)]);
      }
    // The root's values as the decoder holds them: quantized values
    // dequantized.
    uint8_t value[16];
    const AttributeCoder::Layout layout = AttributeCoder::layoutOf(a, q, 0);
    uint32_t images[4];
    AttributeCoder::images(layout, a.values.data() + size_t(root) * a.valueBytes(), images);
    AttributeCoder::store(layout, value, images);
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
    if (available - at < nameBytes + 1) return Parsed::Incomplete;
    a.name.assign(reinterpret_cast<const char*>(in + at), nameBytes);
    at += nameBytes;
    if (!printableName(a.name)) return malformed("name is not printable ASCII");
    for (const VertexAttribute& other : table)
      if (other.name == a.name) return malformed("two attributes named '" + a.name + "'");
    AttributeQuantization& q = a.quantization;
    const uint8_t kind = in[at++];
    if (kind > AttributeQuantization::GeometricOctahedral) return malformed("unknown coding of '" + a.name + "'");
    q.kind = AttributeQuantization::Kind(kind);
    if (q.kind != AttributeQuantization::Exact) {
      if (available - at < 1) return Parsed::Incomplete;
      q.bits = in[at++];
      const bool uniform = q.kind == AttributeQuantization::Uniform;
      if (a.type != AttributeType::Float32 || (!uniform && a.components != 3) ||
          q.bits < (uniform ? kMinUniformBits : kMinOctahedralBits) ||
          q.bits > (uniform ? kMaxUniformBits : kMaxOctahedralBits))
        return malformed("bad quantization of '" + a.name + "'");
      if (uniform) {
        if (available - at < size_t(8) * a.components) return Parsed::Incomplete;
        for (int c = 0; c < a.components; ++c, at += 8) {
          q.minimum[size_t(c)] = getFloat(in + at);
          q.step[size_t(c)] = getFloat(in + at + 4);
          if (!validUniform(q.minimum[size_t(c)], q.step[size_t(c)]))
            return malformed("bad quantization range of '" + a.name + "'");
        }
      }
    }
    if (available - at < a.valueBytes()) return Parsed::Incomplete;
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

std::vector<std::vector<uint8_t>> heldValues(const std::vector<VertexAttribute>& attributes,
                                             const std::vector<AttributeQuantization>& quantization) {
  std::vector<std::vector<uint8_t>> held(attributes.size());
  for (size_t a = 0; a < attributes.size(); ++a) {
    if (quantization[a].kind == AttributeQuantization::Exact) continue;
    const AttributeCoder::Layout layout = AttributeCoder::layoutOf(attributes[a], quantization[a], 0);
    const size_t bytes = attributes[a].valueBytes();
    held[a].resize(attributes[a].values.size());
    for (size_t at = 0; at < held[a].size(); at += bytes) {
      uint32_t images[4];
      AttributeCoder::images(layout, attributes[a].values.data() + at, images);
      AttributeCoder::store(layout, held[a].data() + at, images);
    }
  }
  return held;
}

AttributeCoder::AttributeCoder(const std::vector<VertexAttribute>& attributes,
                               const std::vector<AttributeQuantization>* quantization) {
  size_t models = 0;
  for (size_t i = 0; i < attributes.size(); ++i) {
    layouts_.push_back(layoutOf(attributes[i], quantization ? (*quantization)[i] : attributes[i].quantization, models));
    models += size_t(layouts_.back().components) * kLengthClasses * kLengthClasses;
  }
  models_.resize(models);
}

AttributeCoder::Layout AttributeCoder::layoutOf(const VertexAttribute& a, const AttributeQuantization& q,
                                                size_t firstModels) {
  Layout layout{};
  layout.type = a.type;
  layout.kind = q.kind;
  layout.firstModels = firstModels;
  layout.bytes = int(attributeTypeBytes(a.type));
  if (q.kind == AttributeQuantization::Exact) {
    layout.components = a.components;
    layout.bits = 8 * layout.bytes;
  } else {
    layout.components = isOctahedral(q.kind) ? 2 : a.components;
    layout.bits = q.bits;
    layout.top = topOf(q);
    for (int c = 0; c < 4; ++c) layout.minimum[c] = q.minimum[size_t(c)], layout.step[c] = q.step[size_t(c)];
  }
  layout.mask = layout.bits == 32 ? 0xffffffffu : (uint32_t(1) << layout.bits) - 1;
  return layout;
}

namespace {

// Octahedral coordinates, as Draco and meshoptimizer use them: a direction
// (x, y, z) scaled to |x| + |y| + |z| = 1 lies on an octahedron, whose
// upper half maps to the diamond |u| + |v| <= 1 and whose lower half folds
// out onto the square's corners. Quantized to 0..top (top = 2^bits - 2, so
// that 0 has a value), the square's edges hold each direction twice (the
// edge v = ±1 is symmetric in u, u = ±1 in v, and all corners are
// (0, 0, -1)): images keep the twin with u >= 0 on v = ±1, v >= 0 on
// u = ±1, and (top, top) for the corners, so that mapping a dequantized
// normal back gives the image it came from.
double signOf(double x) { return x >= 0 ? 1.0 : -1.0; }

void encodeOctahedral(const double* d, uint32_t top, uint32_t* out) {
  const double l1 = std::fabs(d[0]) + std::fabs(d[1]) + std::fabs(d[2]);
  double u = 0, v = 0;
  if (l1 > 0 && std::isfinite(l1)) {
    u = d[0] / l1, v = d[1] / l1;
    if (d[2] < 0) {
      const double folded = (1 - std::fabs(v)) * signOf(u);
      v = (1 - std::fabs(u)) * signOf(v);
      u = folded;
    }
  }
  const double half = 0.5 * double(top);
  uint32_t q[2];
  for (int c = 0; c < 2; ++c) {
    const double x = std::nearbyint(((c == 0 ? u : v) + 1) * half);
    q[c] = x <= 0 ? 0 : x >= double(top) ? top : uint32_t(x);
  }
  const bool uEdge = q[0] == 0 || q[0] == top, vEdge = q[1] == 0 || q[1] == top;
  if (uEdge && vEdge) {
    q[0] = q[1] = top;
  } else if (uEdge) {
    q[1] = std::max(q[1], top - q[1]);
  } else if (vEdge) {
    q[0] = std::max(q[0], top - q[0]);
  }
  out[0] = q[0], out[1] = q[1];
}

void decodeOctahedral(const uint32_t* q, uint32_t top, float* out) {
  const double u = (2.0 * std::min(q[0], top) - top) / top, v = (2.0 * std::min(q[1], top) - top) / top;
  double d[3] = {u, v, 1 - std::fabs(u) - std::fabs(v)};
  if (d[2] < 0) {
    d[0] = (1 - std::fabs(v)) * signOf(u);
    d[1] = (1 - std::fabs(u)) * signOf(v);
  }
  const double length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  for (int c = 0; c < 3; ++c) out[c] = float(d[c] / length) + 0.0f;  // -0 becomes +0: twins give the same bits
}

}  // namespace

void AttributeCoder::addNormal(const uint8_t* values, double* sum) {
  for (int c = 0; c < 3; ++c) sum[c] += double(floatAt(values, c));
}

bool AttributeCoder::lowerHemisphere(const Layout& layout, const uint32_t* images) {
  const int64_t top = layout.top;
  const int64_t u = 2 * int64_t(std::min<uint32_t>(images[0], layout.top)) - top;
  const int64_t v = 2 * int64_t(std::min<uint32_t>(images[1], layout.top)) - top;
  return std::abs(u) + std::abs(v) > top;
}

// Negating z folds the diamond's triangles out onto the square's corners
// and back: in coordinates centred on the square (u, v in -top..top, even
// steps), (u, v) -> ((top - |v|) sign u, (top - |u|) sign v), sign 0 = +1.
// The diamond's edge (z = 0) stays; the corners' image (top, top) and the
// centre swap. Canonical images on the square's edges (u >= 0 on v = ±1,
// v >= 0 on u = ±1) map to the diamond and come back to themselves.
void AttributeCoder::mirrorOctahedral(const Layout& layout, uint32_t* images) {
  const int64_t top = layout.top;
  const int64_t u = 2 * int64_t(std::min<uint32_t>(images[0], layout.top)) - top;
  const int64_t v = 2 * int64_t(std::min<uint32_t>(images[1], layout.top)) - top;
  const int64_t mirroredU = (top - std::abs(v)) * (u >= 0 ? 1 : -1);
  const int64_t mirroredV = (top - std::abs(u)) * (v >= 0 ? 1 : -1);
  images[0] = uint32_t((mirroredU + top) / 2);
  images[1] = uint32_t((mirroredV + top) / 2);
}

void AttributeCoder::holdDirection(size_t a, const double* direction, uint8_t* values) const {
  uint32_t images[4];
  encodeOctahedral(direction, layouts_[a].top, images);
  store(layouts_[a], values, images);
}

void triangleNormals(const SimplexStore& store, const std::vector<float>& positions, std::vector<double>& out) {
  const size_t n = positions.size() / 3;
  out.assign(n * 4, 0.0);
  for (uint32_t vertex = 0; vertex < n; ++vertex) {
    double sum[3] = {0, 0, 0}, lengths = 0;
    const float* p = &positions[size_t(vertex) * 3];
    store.forEachIncident(2, vertex, [&](uint32_t triangle, uint32_t position) {
      // The two vertices that follow this one in the triangle's winding.
      const uint32_t* v = store.vertices(2, triangle);
      const bool flipped = (store.flags(2, triangle) & SimplexStore::kFlipped) != 0;
      const float* a = &positions[size_t(v[(position + (flipped ? 2 : 1)) % 3]) * 3];
      const float* b = &positions[size_t(v[(position + (flipped ? 1 : 2)) % 3]) * 3];
      const double u[3] = {double(a[0]) - p[0], double(a[1]) - p[1], double(a[2]) - p[2]};
      const double w[3] = {double(b[0]) - p[0], double(b[1]) - p[1], double(b[2]) - p[2]};
      const double area[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
      for (int c = 0; c < 3; ++c) sum[c] += area[c];
      lengths += std::sqrt(area[0] * area[0] + area[1] * area[1] + area[2] * area[2]);
    });
    const double length = std::sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
    double* normal = &out[size_t(vertex) * 4];
    for (int c = 0; c < 3; ++c) normal[c] = length > 0 ? sum[c] / length : 0.0;
    normal[3] = lengths > 0 ? length / lengths : 0.0;
  }
}

void earlierNeighbours(const SimplexStore& store, uint32_t vertex, std::vector<uint32_t>& out) {
  out.clear();
  store.forEachIncident(1, vertex, [&](uint32_t edge, uint32_t position) {
    const uint32_t other = store.vertices(1, edge)[1 - position];
    if (other < vertex) out.push_back(other);
  });
}

void AttributeCoder::octahedralImages(const Layout& layout, const double* direction, uint32_t* out) {
  encodeOctahedral(direction, layout.top, out);
}

void AttributeCoder::images(const Layout& layout, const uint8_t* values, uint32_t* out) {
  switch (layout.kind) {
    case AttributeQuantization::Exact:
      for (int c = 0; c < layout.components; ++c) {
        uint32_t v = 0;
        std::memcpy(&v, values + size_t(c) * size_t(layout.bytes), size_t(layout.bytes));  // little-endian, as WebAssembly and x86
        if (layout.type == AttributeType::Float32) v = v & 0x80000000u ? ~v : v | 0x80000000u;
        out[c] = v;
      }
      return;
    case AttributeQuantization::Uniform:
      for (int c = 0; c < layout.components; ++c) {
        const double x = layout.step[c] == 0 ? 0
                                             : std::nearbyint((double(floatAt(values, c)) - layout.minimum[c]) /
                                                              layout.step[c]);
        out[c] = x >= 0 ? (x <= double(layout.top) ? uint32_t(x) : layout.top) : 0;  // NaN: 0
      }
      return;
    case AttributeQuantization::Octahedral:
    case AttributeQuantization::GeometricOctahedral: {
      const double d[3] = {floatAt(values, 0), floatAt(values, 1), floatAt(values, 2)};
      encodeOctahedral(d, layout.top, out);
      return;
    }
  }
}

void AttributeCoder::store(const Layout& layout, uint8_t* values, const uint32_t* images) {
  switch (layout.kind) {
    case AttributeQuantization::Exact:
      for (int c = 0; c < layout.components; ++c) {
        uint32_t image = images[c];
        if (layout.type == AttributeType::Float32) image = image & 0x80000000u ? image & 0x7fffffffu : ~image;
        std::memcpy(values + size_t(c) * size_t(layout.bytes), &image, size_t(layout.bytes));
      }
      return;
    case AttributeQuantization::Uniform:
      for (int c = 0; c < layout.components; ++c) {
        const float x = float(layout.minimum[c] + double(std::min(images[c], layout.top)) * layout.step[c]);
        std::memcpy(values + 4 * c, &x, 4);
      }
      return;
    case AttributeQuantization::Octahedral:
    case AttributeQuantization::GeometricOctahedral: {
      float normal[3];
      decodeOctahedral(images, layout.top, normal);
      std::memcpy(values, normal, 12);
      return;
    }
  }
}

}  // namespace kdmesh
