// Accessors and buffers: bounds-checked reads, new buffer views, compaction.
#include <algorithm>
#include <cstring>
#include <limits>

#include "gltf_internal.h"

namespace kdmesh::gltf::detail {
namespace {

Status invalid(const std::string& message) { return Status::error(ErrorCode::InvalidInput, message); }

constexpr size_t alignedTo4(size_t n) { return (n + 3) & ~size_t{3}; }

// Copies `count` elements of `elementBytes`, `stride` apart from `offset`
// in a view of `size` bytes, after checking that they fit.
Status copyElements(const uint8_t* view, size_t size, size_t offset, size_t stride, size_t count,
                    size_t elementBytes, uint8_t* out, const std::string& what) {
  if (count == 0) return Status::success();
  if (offset > size || elementBytes > size - offset || (count - 1) > (size - offset - elementBytes) / stride)
    return invalid(what + " reaches past the end of its buffer view");
  for (size_t i = 0; i < count; ++i) std::memcpy(out + i * elementBytes, view + offset + i * stride, elementBytes);
  return Status::success();
}

}  // namespace

Status viewBytes(const tinygltf::Model& model, int index, const uint8_t*& data, size_t& size) {
  if (index < 0 || size_t(index) >= model.bufferViews.size())
    return invalid("buffer view " + std::to_string(index) + " does not exist");
  const tinygltf::BufferView& view = model.bufferViews[size_t(index)];
  if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size())
    return invalid("buffer view " + std::to_string(index) + " refers to a missing buffer");
  const std::vector<unsigned char>& buffer = model.buffers[size_t(view.buffer)].data;
  if (view.byteOffset > buffer.size() || view.byteLength > buffer.size() - view.byteOffset)
    return invalid("buffer view " + std::to_string(index) + " lies outside its buffer");
  data = buffer.data() + view.byteOffset;
  size = view.byteLength;
  return Status::success();
}

size_t componentBytes(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
  }
}

int typeComponents(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
  }
}

int vectorType(int components) {
  static const int kTypes[] = {TINYGLTF_TYPE_SCALAR, TINYGLTF_TYPE_VEC2, TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4};
  return components >= 1 && components <= 4 ? kTypes[components - 1] : -1;
}

Status readAccessor(const tinygltf::Model& model, int index, std::vector<uint8_t>& packed) {
  const std::string name = "accessor " + std::to_string(index);
  if (index < 0 || size_t(index) >= model.accessors.size()) return invalid(name + " does not exist");
  const tinygltf::Accessor& accessor = model.accessors[size_t(index)];
  const size_t elementBytes = componentBytes(accessor.componentType) * size_t(typeComponents(accessor.type));
  if (elementBytes == 0) return invalid(name + " has an invalid componentType or type");
  if (accessor.bufferView < 0)
    return Status::error(ErrorCode::Unsupported, name + " has no buffer view: its values are not in the file");
  const uint8_t* view = nullptr;
  size_t viewSize = 0;
  if (auto s = viewBytes(model, accessor.bufferView, view, viewSize); !s.ok()) return s;
  const size_t stride = model.bufferViews[size_t(accessor.bufferView)].byteStride
      ? model.bufferViews[size_t(accessor.bufferView)].byteStride : elementBytes;
  if (stride < elementBytes) return invalid(name + ": its buffer view's byteStride is smaller than an element");
  // The count is checked against the view before anything is allocated.
  if (accessor.count > viewSize / elementBytes + 1) return invalid(name + " counts more elements than its buffer view holds");
  packed.assign(accessor.count * elementBytes, 0);
  if (auto s = copyElements(view, viewSize, accessor.byteOffset, stride, accessor.count, elementBytes, packed.data(), name); !s.ok())
    return s;
  if (!accessor.sparse.isSparse) return Status::success();
  // Sparse: `count` indices, then as many values, replace elements.
  const auto& sparse = accessor.sparse;
  const size_t indexBytes = componentBytes(sparse.indices.componentType);
  const int indexType = sparse.indices.componentType;
  if (sparse.count < 0 || size_t(sparse.count) > accessor.count || sparse.indices.byteOffset < 0 ||
      sparse.values.byteOffset < 0 ||
      (indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
       indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
    return invalid(name + " has an invalid sparse description");
  const size_t count = size_t(sparse.count);
  const uint8_t* indexView = nullptr;
  const uint8_t* valueView = nullptr;
  size_t indexViewSize = 0, valueViewSize = 0;
  if (auto s = viewBytes(model, sparse.indices.bufferView, indexView, indexViewSize); !s.ok()) return s;
  if (auto s = viewBytes(model, sparse.values.bufferView, valueView, valueViewSize); !s.ok()) return s;
  std::vector<uint8_t> indices(count * indexBytes), values(count * elementBytes);
  if (auto s = copyElements(indexView, indexViewSize, size_t(sparse.indices.byteOffset), indexBytes, count, indexBytes,
                            indices.data(), name + "'s sparse indices"); !s.ok())
    return s;
  if (auto s = copyElements(valueView, valueViewSize, size_t(sparse.values.byteOffset), elementBytes, count,
                            elementBytes, values.data(), name + "'s sparse values"); !s.ok())
    return s;
  for (size_t i = 0; i < count; ++i) {
    uint32_t at = 0;
    if (indexBytes == 1) at = indices[i];
    else if (indexBytes == 2) { uint16_t v; std::memcpy(&v, &indices[2 * i], 2); at = v; }
    else std::memcpy(&at, &indices[4 * i], 4);
    if (at >= accessor.count) return invalid(name + ": sparse index " + std::to_string(at) + " is out of range");
    std::memcpy(&packed[size_t(at) * elementBytes], &values[i * elementBytes], elementBytes);
  }
  return Status::success();
}

Status readIndices(const tinygltf::Model& model, int index, size_t vertexCount, std::vector<uint32_t>& indices) {
  const std::string name = "index accessor " + std::to_string(index);
  if (index < 0 || size_t(index) >= model.accessors.size()) return invalid(name + " does not exist");
  const tinygltf::Accessor& accessor = model.accessors[size_t(index)];
  const int type = accessor.componentType;
  if (accessor.type != TINYGLTF_TYPE_SCALAR ||
      (type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
       type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
    return invalid(name + " is not a SCALAR of unsigned integers");
  std::vector<uint8_t> packed;
  if (auto s = readAccessor(model, index, packed); !s.ok()) return s;
  const size_t bytes = componentBytes(type);
  indices.resize(accessor.count);
  for (size_t i = 0; i < indices.size(); ++i) {
    uint32_t v = 0;
    if (bytes == 1) v = packed[i];
    else if (bytes == 2) { uint16_t w; std::memcpy(&w, &packed[2 * i], 2); v = w; }
    else std::memcpy(&v, &packed[4 * i], 4);
    if (v >= vertexCount)
      return invalid(name + ": index " + std::to_string(v) + " (element " + std::to_string(i) + ") is not below the " +
                     std::to_string(vertexCount) + " vertices");
    indices[i] = v;
  }
  return Status::success();
}

void setBounds(tinygltf::Accessor& accessor, const uint8_t* packed, size_t count) {
  const int components = typeComponents(accessor.type);
  const size_t bytes = componentBytes(accessor.componentType);
  accessor.minValues.assign(size_t(components), std::numeric_limits<double>::infinity());
  accessor.maxValues.assign(size_t(components), -std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < count * size_t(components); ++i) {
    const uint8_t* at = packed + i * bytes;
    double v = 0;
    switch (accessor.componentType) {
      case TINYGLTF_COMPONENT_TYPE_BYTE: v = double(int8_t(*at)); break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: v = double(*at); break;
      case TINYGLTF_COMPONENT_TYPE_SHORT: { int16_t x; std::memcpy(&x, at, 2); v = x; break; }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t x; std::memcpy(&x, at, 2); v = x; break; }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { uint32_t x; std::memcpy(&x, at, 4); v = x; break; }
      default: { float x; std::memcpy(&x, at, 4); v = x; break; }
    }
    const size_t c = i % size_t(components);
    accessor.minValues[c] = std::min(accessor.minValues[c], v);
    accessor.maxValues[c] = std::max(accessor.maxValues[c], v);
  }
}

BufferWriter::BufferWriter(tinygltf::Model& model) : model_(model) {}

int BufferWriter::add(const uint8_t* bytes, size_t size, int target) {
  if (model_.buffers.empty()) model_.buffers.emplace_back();
  std::vector<unsigned char>& data = model_.buffers[0].data;
  data.resize(alignedTo4(data.size()), 0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = data.size();
  view.byteLength = size;
  view.target = target;
  data.insert(data.end(), bytes, bytes + size);
  model_.bufferViews.push_back(view);
  return int(model_.bufferViews.size() - 1);
}

int BufferWriter::addVertexAttribute(const uint8_t* packed, size_t count, size_t elementBytes) {
  const size_t stride = alignedTo4(elementBytes);
  if (stride == elementBytes) return add(packed, count * elementBytes, TINYGLTF_TARGET_ARRAY_BUFFER);
  std::vector<uint8_t> padded(count * stride, 0);
  for (size_t i = 0; i < count; ++i) std::memcpy(&padded[i * stride], packed + i * elementBytes, elementBytes);
  const int view = add(padded.data(), padded.size(), TINYGLTF_TARGET_ARRAY_BUFFER);
  model_.bufferViews[size_t(view)].byteStride = stride;
  return view;
}

Status compactBuffers(tinygltf::Model& model, bool keepUnreferencedViews) {
  const size_t viewCount = model.bufferViews.size();
  std::vector<bool> used(viewCount, keepUnreferencedViews);
  const auto use = [&](int view) {
    if (view >= 0 && size_t(view) < viewCount) used[size_t(view)] = true;
  };
  for (const tinygltf::Accessor& accessor : model.accessors) {
    use(accessor.bufferView);
    if (accessor.sparse.isSparse) {
      use(accessor.sparse.indices.bufferView);
      use(accessor.sparse.values.bufferView);
    }
  }
  for (const tinygltf::Image& image : model.images) use(image.bufferView);
  for (const tinygltf::Mesh& mesh : model.meshes)
    for (const tinygltf::Primitive& primitive : mesh.primitives) {
      const auto it = primitive.extensions.find(kExtensionName);
      if (it != primitive.extensions.end() && it->second.Has("bufferView") && it->second.Get("bufferView").IsInt())
        use(it->second.Get("bufferView").GetNumberAsInt());
    }

  tinygltf::Buffer merged;
  if (!model.buffers.empty()) {
    merged.name = model.buffers[0].name;
    merged.extras = model.buffers[0].extras;
    merged.extensions = model.buffers[0].extensions;
  }
  std::vector<int> renumbered(viewCount, -1);
  std::vector<tinygltf::BufferView> views;
  for (size_t i = 0; i < viewCount; ++i) {
    if (!used[i]) continue;
    const uint8_t* bytes = nullptr;
    size_t size = 0;
    if (auto s = viewBytes(model, int(i), bytes, size); !s.ok()) return s;
    tinygltf::BufferView view = model.bufferViews[i];
    merged.data.resize(alignedTo4(merged.data.size()), 0);
    view.buffer = 0;
    view.byteOffset = merged.data.size();
    merged.data.insert(merged.data.end(), bytes, bytes + size);
    renumbered[i] = int(views.size());
    views.push_back(std::move(view));
  }
  const auto renumber = [&](int& view) {
    if (view >= 0) view = size_t(view) < viewCount ? renumbered[size_t(view)] : -1;
  };
  for (tinygltf::Accessor& accessor : model.accessors) {
    renumber(accessor.bufferView);
    if (accessor.sparse.isSparse) {
      renumber(accessor.sparse.indices.bufferView);
      renumber(accessor.sparse.values.bufferView);
    }
  }
  for (tinygltf::Image& image : model.images) renumber(image.bufferView);
  for (tinygltf::Mesh& mesh : model.meshes)
    for (tinygltf::Primitive& primitive : mesh.primitives) {
      const auto it = primitive.extensions.find(kExtensionName);
      if (it == primitive.extensions.end() || !it->second.Has("bufferView") || !it->second.Get("bufferView").IsInt())
        continue;
      tinygltf::Value::Object extension = it->second.Get<tinygltf::Value::Object>();
      int view = extension["bufferView"].GetNumberAsInt();
      renumber(view);
      extension["bufferView"] = tinygltf::Value(view);
      it->second = tinygltf::Value(std::move(extension));
    }
  model.bufferViews = std::move(views);
  model.buffers.clear();
  if (!model.bufferViews.empty()) model.buffers.push_back(std::move(merged));
  return Status::success();
}

}  // namespace kdmesh::gltf::detail
