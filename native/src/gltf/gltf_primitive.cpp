// Primitives: a glTF primitive's geometry as a complex, and back.
#include <algorithm>
#include <cstring>
#include <limits>

#include "gltf_internal.h"

namespace kdmesh::gltf::detail {
namespace {

Status invalid(const std::string& message) { return Status::error(ErrorCode::InvalidInput, message); }
Status unsupported(const std::string& message) { return Status::error(ErrorCode::Unsupported, message); }

// glTF component types and kdmesh attribute types name the same integer
// and float types (glTF has no 32-bit signed integer).
bool attributeTypeOf(int componentType, AttributeType& type) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: type = AttributeType::Int8; return true;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: type = AttributeType::UInt8; return true;
    case TINYGLTF_COMPONENT_TYPE_SHORT: type = AttributeType::Int16; return true;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: type = AttributeType::UInt16; return true;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: type = AttributeType::UInt32; return true;
    case TINYGLTF_COMPONENT_TYPE_FLOAT: type = AttributeType::Float32; return true;
    default: return false;
  }
}

bool isPrintableName(const std::string& name) {
  if (name.empty() || name.size() > kMaxAttributeNameBytes) return false;
  return std::all_of(name.begin(), name.end(), [](char c) { return c >= 0x20 && c < 0x7f; });
}

// The simplices a primitive draws, as lists: strips, fans and loops are
// unrolled as the glTF specification orders their vertices, and their
// degenerate pieces (a repeated vertex: nothing drawn) dropped and counted.
Status simplicesOf(int mode, const std::vector<uint32_t>& order, std::vector<uint32_t>& out, size_t& dropped) {
  const size_t n = order.size();
  const auto add = [&](std::initializer_list<uint32_t> simplex) {
    for (auto a = simplex.begin(); a != simplex.end(); ++a)
      for (auto b = a + 1; b != simplex.end(); ++b)
        if (*a == *b) {
          ++dropped;
          return;
        }
    out.insert(out.end(), simplex);
  };
  switch (mode) {
    case TINYGLTF_MODE_POINTS: return Status::success();
    case TINYGLTF_MODE_LINE:
      if (n % 2) return unsupported("its LINES count " + std::to_string(n) + " is not even");
      out = order;
      return Status::success();
    case TINYGLTF_MODE_LINE_STRIP:
    case TINYGLTF_MODE_LINE_LOOP:
      for (size_t i = 0; i + 1 < n; ++i) add({order[i], order[i + 1]});
      if (mode == TINYGLTF_MODE_LINE_LOOP && n > 2) add({order[n - 1], order[0]});
      return Status::success();
    case TINYGLTF_MODE_TRIANGLES:
      if (n % 3) return unsupported("its TRIANGLES count " + std::to_string(n) + " is not a multiple of 3");
      out = order;
      return Status::success();
    case TINYGLTF_MODE_TRIANGLE_STRIP:
      for (size_t i = 0; i + 2 < n; ++i)
        add({order[i], order[i + 1 + i % 2], order[i + 2 - i % 2]});
      return Status::success();
    case TINYGLTF_MODE_TRIANGLE_FAN:
      for (size_t i = 0; i + 2 < n; ++i) add({order[i + 1], order[i + 2], order[0]});
      return Status::success();
    default: return unsupported("its mode " + std::to_string(mode) + " is not a glTF primitive mode");
  }
}

int listModeOf(int mode) {
  if (mode == TINYGLTF_MODE_POINTS) return TINYGLTF_MODE_POINTS;
  if (mode == TINYGLTF_MODE_LINE || mode == TINYGLTF_MODE_LINE_STRIP || mode == TINYGLTF_MODE_LINE_LOOP)
    return TINYGLTF_MODE_LINE;
  return TINYGLTF_MODE_TRIANGLES;
}

// Gathers the elements of `packed` (`bytes` each) listed in `keep`.
std::vector<uint8_t> gathered(const std::vector<uint8_t>& packed, size_t bytes, const std::vector<uint32_t>& keep) {
  std::vector<uint8_t> out(keep.size() * bytes);
  for (size_t i = 0; i < keep.size(); ++i) std::memcpy(&out[i * bytes], &packed[size_t(keep[i]) * bytes], bytes);
  return out;
}

// The accessor `slot` of a primitive refers to, made its own: a second
// primitive decoded onto the same accessor gets a copy of it.
int ownAccessor(tinygltf::Model& model, int accessor, std::vector<bool>& written) {
  if (written.size() < model.accessors.size()) written.resize(model.accessors.size(), false);
  if (!written[size_t(accessor)]) {
    written[size_t(accessor)] = true;
    return accessor;
  }
  model.accessors.push_back(model.accessors[size_t(accessor)]);
  written.push_back(true);
  return int(model.accessors.size() - 1);
}

void pointAt(tinygltf::Accessor& accessor, int view, size_t count) {
  accessor.bufferView = view;
  accessor.byteOffset = 0;
  accessor.count = count;
  accessor.sparse.isSparse = false;
  accessor.sparse.count = 0;
}

}  // namespace

bool isListMode(int mode) {
  return mode == TINYGLTF_MODE_POINTS || mode == TINYGLTF_MODE_LINE || mode == TINYGLTF_MODE_TRIANGLES;
}

Status primitiveGeometry(const tinygltf::Model& model, const tinygltf::Primitive& primitive, PrimitiveGeometry& out) {
  if (!primitive.targets.empty()) return unsupported("it has morph targets, whose vertices would need the same order");
  const auto position = primitive.attributes.find("POSITION");
  if (position == primitive.attributes.end()) return unsupported("it has no POSITION");
  if (position->second < 0 || size_t(position->second) >= model.accessors.size())
    return invalid("its POSITION accessor " + std::to_string(position->second) + " does not exist");
  const tinygltf::Accessor& positionAccessor = model.accessors[size_t(position->second)];
  if (positionAccessor.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || positionAccessor.type != TINYGLTF_TYPE_VEC3)
    return unsupported("its POSITION is not float VEC3 (quantized positions)");
  std::vector<uint8_t> positions;
  if (auto s = readAccessor(model, position->second, positions); !s.ok()) return s;
  const size_t vertexCount = positionAccessor.count;
  if (vertexCount == 0) return unsupported("it has no vertices");
  if (primitive.attributes.size() - 1 > kMaxAttributes)
    return unsupported("it has more than " + std::to_string(kMaxAttributes) + " attributes besides POSITION");

  // Which vertices it draws, in drawing order.
  std::vector<uint32_t> order;
  if (primitive.indices >= 0) {
    if (auto s = readIndices(model, primitive.indices, vertexCount, order); !s.ok()) return s;
  } else {
    order.resize(vertexCount);
    for (uint32_t v = 0; v < vertexCount; ++v) order[v] = v;
  }
  std::vector<uint32_t> simplices;
  size_t dropped = 0;
  if (auto s = simplicesOf(primitive.mode, order, simplices, dropped); !s.ok()) return s;
  const int mode = listModeOf(primitive.mode);
  // The vertices drawn, each once, in order of first use.
  std::vector<uint32_t> renumbered(vertexCount, UINT32_MAX), keep;
  for (const uint32_t v : mode == TINYGLTF_MODE_POINTS ? order : simplices) {
    if (renumbered[v] != UINT32_MAX) {
      dropped += mode == TINYGLTF_MODE_POINTS;  // a point drawn twice
      continue;
    }
    renumbered[v] = uint32_t(keep.size());
    keep.push_back(v);
  }
  if (keep.empty()) return unsupported("it draws nothing");
  for (uint32_t& v : simplices) v = renumbered[v];

  out = PrimitiveGeometry();
  out.mode = mode;
  out.dropped = dropped;
  out.allVerticesKept = keep.size() == vertexCount;
  std::vector<uint8_t> kept = gathered(positions, 12, keep);
  out.complex.positions.resize(keep.size() * 3);
  std::memcpy(out.complex.positions.data(), kept.data(), kept.size());
  (mode == TINYGLTF_MODE_TRIANGLES ? out.complex.triangles : out.complex.edges) = std::move(simplices);
  for (const auto& [semantic, index] : primitive.attributes) {
    if (semantic == "POSITION") continue;
    if (index < 0 || size_t(index) >= model.accessors.size())
      return invalid("its " + semantic + " accessor " + std::to_string(index) + " does not exist");
    const tinygltf::Accessor& accessor = model.accessors[size_t(index)];
    VertexAttribute attribute;
    attribute.name = semantic;
    const int components = typeComponents(accessor.type);
    if (!isPrintableName(semantic)) return unsupported("its attribute name \"" + semantic + "\" is not 1-64 printable ASCII characters");
    if (!attributeTypeOf(accessor.componentType, attribute.type) || accessor.type == TINYGLTF_TYPE_MAT2 || components < 1 ||
        components > 4)
      return unsupported("its " + semantic + " is not a scalar or vector of a glTF component type");
    if (accessor.count != vertexCount)
      return invalid("its " + semantic + " counts " + std::to_string(accessor.count) + " elements for " +
                     std::to_string(vertexCount) + " vertices");
    attribute.components = uint8_t(components);
    std::vector<uint8_t> packed;
    if (auto s = readAccessor(model, index, packed); !s.ok()) return s;
    attribute.values = gathered(packed, attribute.valueBytes(), keep);
    out.complex.attributes.push_back(std::move(attribute));
  }
  return Status::success();
}

Status writeDecodedPrimitive(tinygltf::Model& model, tinygltf::Primitive& primitive, const tinygltf::Value& extension,
                             const Complex& complex, BufferWriter& writer, std::vector<bool>& accessorWritten) {
  if (!isListMode(primitive.mode)) return invalid("a compressed primitive must be POINTS, LINES or TRIANGLES");
  const size_t vertexCount = complex.vertexCount();
  const auto accessorOf = [&](int index, const std::string& what, tinygltf::Accessor*& out) {
    if (index < 0 || size_t(index) >= model.accessors.size())
      return invalid("its " + what + " accessor " + std::to_string(index) + " does not exist");
    out = &model.accessors[size_t(index)];
    return Status::success();
  };
  const tinygltf::Value& names = extension.Get("attributes");
  if (extension.Has("attributes") && !names.IsObject()) return invalid("the extension's attributes is not an object");

  // Check everything before writing anything.
  std::vector<std::pair<std::string, const VertexAttribute*>> attributes;
  for (const auto& [semantic, index] : primitive.attributes) {
    tinygltf::Accessor* accessor = nullptr;
    if (auto s = accessorOf(index, semantic, accessor); !s.ok()) return s;
    if (accessor->count != vertexCount)
      return invalid("its " + semantic + " accessor counts " + std::to_string(accessor->count) + " vertices, the stream " +
                     std::to_string(vertexCount));
    if (semantic == "POSITION") {
      if (accessor->componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || accessor->type != TINYGLTF_TYPE_VEC3)
        return invalid("its POSITION accessor is not float VEC3");
      continue;
    }
    static const tinygltf::Value kNone;
    const tinygltf::Value& name = names.IsObject() ? names.Get(semantic) : kNone;
    if (!name.IsString()) return invalid("the extension names no stream attribute for " + semantic);
    const auto found = std::find_if(complex.attributes.begin(), complex.attributes.end(),
                                    [&](const VertexAttribute& a) { return a.name == name.Get<std::string>(); });
    if (found == complex.attributes.end()) return invalid("the stream has no attribute \"" + name.Get<std::string>() + "\"");
    AttributeType type;
    if (!attributeTypeOf(accessor->componentType, type) || type != found->type ||
        typeComponents(accessor->type) != found->components)
      return invalid("the stream's attribute \"" + found->name + "\" does not match the " + semantic + " accessor's type");
    attributes.emplace_back(semantic, &*found);
  }
  if (primitive.attributes.find("POSITION") == primitive.attributes.end()) return invalid("it has no POSITION");
  if (!complex.tetrahedra.empty()) return invalid("the stream holds tetrahedra");
  const std::vector<uint32_t>* list = nullptr;
  if (primitive.mode == TINYGLTF_MODE_TRIANGLES) {
    if (!complex.edges.empty()) return invalid("the stream of a TRIANGLES primitive holds edges");
    list = &complex.triangles;
  } else if (primitive.mode == TINYGLTF_MODE_LINE) {
    if (!complex.triangles.empty()) return invalid("the stream of a LINES primitive holds triangles");
    list = &complex.edges;
  } else if (complex.hasSimplices()) {
    return invalid("the stream of a POINTS primitive holds simplices");
  }
  tinygltf::Accessor* indexAccessor = nullptr;
  if (list) {
    if (auto s = accessorOf(primitive.indices, "indices", indexAccessor); !s.ok()) return s;
    if (indexAccessor->count != list->size())
      return invalid("its indices accessor counts " + std::to_string(indexAccessor->count) + " indices, the stream " +
                     std::to_string(list->size()));
  } else if (primitive.indices >= 0) {
    return invalid("a compressed POINTS primitive has indices");
  }

  // Vertices, then simplices, into new buffer views.
  for (auto& [semantic, index] : primitive.attributes) {
    index = ownAccessor(model, index, accessorWritten);
    tinygltf::Accessor& accessor = model.accessors[size_t(index)];
    if (semantic == "POSITION") {
      const auto* bytes = reinterpret_cast<const uint8_t*>(complex.positions.data());
      pointAt(accessor, writer.addVertexAttribute(bytes, vertexCount, 12), vertexCount);
      setBounds(accessor, bytes, vertexCount);
      continue;
    }
    const VertexAttribute* attribute =
        std::find_if(attributes.begin(), attributes.end(), [&name = semantic](const auto& a) { return a.first == name; })->second;
    pointAt(accessor, writer.addVertexAttribute(attribute->values.data(), vertexCount, attribute->valueBytes()),
            vertexCount);
    if (!accessor.minValues.empty()) setBounds(accessor, attribute->values.data(), vertexCount);
  }
  if (list) {
    primitive.indices = ownAccessor(model, primitive.indices, accessorWritten);
    tinygltf::Accessor& accessor = model.accessors[size_t(primitive.indices)];
    // The accessor's own index type when the stream's vertices fit it.
    const size_t bytes = componentBytes(accessor.componentType);
    const bool fits = accessor.type == TINYGLTF_TYPE_SCALAR &&
        (accessor.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT ||
         (accessor.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT && vertexCount <= 0x10000) ||
         (accessor.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && vertexCount <= 0x100));
    const size_t width = fits ? bytes : 4;
    accessor.type = TINYGLTF_TYPE_SCALAR;
    if (!fits) accessor.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    std::vector<uint8_t> packed(list->size() * width);
    for (size_t i = 0; i < list->size(); ++i) {
      const uint32_t v = (*list)[i];
      if (width == 1) packed[i] = uint8_t(v);
      else if (width == 2) { const uint16_t w = uint16_t(v); std::memcpy(&packed[2 * i], &w, 2); }
      else std::memcpy(&packed[4 * i], &v, 4);
    }
    accessor.minValues.clear();
    accessor.maxValues.clear();
    pointAt(accessor, writer.add(packed.data(), packed.size(), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER), list->size());
  }
  return Status::success();
}

}  // namespace kdmesh::gltf::detail
