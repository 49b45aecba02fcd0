// encodeFile and decodeFile: every primitive of a scene to a kdmesh stream
// in the KDMESH_progressive_compression extension, and back.
#include <algorithm>
#include <fstream>

#include "gltf_internal.h"

namespace kdmesh::gltf {
namespace {

using detail::PrimitiveGeometry;

std::string where(size_t mesh, size_t primitive) {
  return "mesh " + std::to_string(mesh) + " primitive " + std::to_string(primitive);
}

bool uses(const tinygltf::Model& model, const std::string& extension) {
  return std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), extension) != model.extensionsUsed.end();
}

// Whether buffer views that no accessor, image or stream refers to must
// stay: an extension the scene uses may refer to buffer views by index,
// unless it is one of those known not to.
bool keepUnreferencedViews(const tinygltf::Model& model, io::Notes& notes) {
  static const char* const kNoBufferViews[] = {
      "KHR_texture_transform", "KHR_lights_punctual", "KHR_texture_basisu", "EXT_texture_webp", "EXT_texture_avif",
      "KHR_mesh_quantization", "KHR_materials_variants", "KHR_xmp_json_ld", "KHR_animation_pointer", kExtensionName};
  for (const std::string& name : model.extensionsUsed) {
    if (name.rfind("KHR_materials_", 0) == 0) continue;
    if (std::find(std::begin(kNoBufferViews), std::end(kNoBufferViews), name) != std::end(kNoBufferViews)) continue;
    notes.push_back("kept every buffer view: the extension " + name + " may refer to them");
    return true;
  }
  return false;
}

void removeName(std::vector<std::string>& names, const std::string& name) {
  names.erase(std::remove(names.begin(), names.end(), name), names.end());
}

void addName(std::vector<std::string>& names, const std::string& name) {
  if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
}

// A primitive's geometry and its stream, before the scene is rewritten.
struct Encoded {
  size_t mesh = 0, primitive = 0;
  PrimitiveGeometry geometry;
  std::vector<uint8_t> bytes;
};

// Encodes one primitive; false (with a note) when it stays uncompressed.
bool encodePrimitive(const tinygltf::Model& model, size_t m, size_t p, const EncodeOptions& options, io::Notes& notes,
                     Encoded& out, Status& error) {
  const tinygltf::Primitive& primitive = model.meshes[m].primitives[p];
  const std::string kept = where(m, p) + ": kept uncompressed: ";
  Status s = detail::primitiveGeometry(model, primitive, out.geometry);
  if (s.code == ErrorCode::Unsupported) {
    notes.push_back(kept + s.message);
    return false;
  }
  if (!s.ok()) {
    error = Status::error(s.code, where(m, p) + ": " + s.message);
    return false;
  }
  const PrimitiveGeometry& geometry = out.geometry;
  if (options.fallback && (!geometry.allVerticesKept || geometry.mode != primitive.mode || geometry.dropped > 0 ||
                           (primitive.indices < 0 && geometry.mode != TINYGLTF_MODE_POINTS))) {
    notes.push_back(kept + "a fallback keeps its accessors, so only indexed lists that draw every vertex once are encoded");
    return false;
  }
  EncodeResult result = encode(geometry.complex, options.stream);
  if (!result.status.ok()) {
    notes.push_back(kept + result.status.message);
    return false;
  }
  uint64_t repaired = 0;
  for (int d = 0; d < 4; ++d)
    repaired += result.repairs.degenerate[size_t(d)] + result.repairs.duplicate[size_t(d)] + result.repairs.redundant[size_t(d)];
  if (repaired > 0) {
    notes.push_back(kept + std::to_string(repaired) +
                    " of its simplices repeat a vertex or another simplex, which a kdmesh stream holds once");
    return false;
  }
  if (geometry.dropped > 0)
    notes.push_back(where(m, p) + ": left out " + std::to_string(geometry.dropped) +
                    " degenerate pieces or repeated points, which draw nothing");
  out.mesh = m;
  out.primitive = p;
  out.bytes = std::move(result.bytes);
  return true;
}

// How many references each accessor has from parts of the scene that
// stay as they are (`compressed` marks the primitives that do not).
std::vector<int> otherUses(const tinygltf::Model& model, const std::vector<std::vector<bool>>& compressed) {
  std::vector<int> count(model.accessors.size(), 0);
  const auto use = [&](int index) {
    if (index >= 0 && size_t(index) < count.size()) ++count[size_t(index)];
  };
  for (size_t m = 0; m < model.meshes.size(); ++m)
    for (size_t p = 0; p < model.meshes[m].primitives.size(); ++p) {
      const tinygltf::Primitive& primitive = model.meshes[m].primitives[p];
      for (const auto& target : primitive.targets)
        for (const auto& entry : target) use(entry.second);
      if (compressed[m][p]) continue;
      for (const auto& entry : primitive.attributes) use(entry.second);
      use(primitive.indices);
    }
  for (const tinygltf::Animation& animation : model.animations)
    for (const tinygltf::AnimationSampler& sampler : animation.samplers) {
      use(sampler.input);
      use(sampler.output);
    }
  for (const tinygltf::Skin& skin : model.skins) use(skin.inverseBindMatrices);
  return count;
}

// <output without its extensions>.<mesh>-<primitive>.kdm
std::string streamPath(const std::string& output, size_t m, size_t p) {
  const size_t slash = output.find_last_of('/');
  const size_t dot = output.find('.', slash == std::string::npos ? 0 : slash + 1);
  return output.substr(0, dot) + "." + std::to_string(m) + "-" + std::to_string(p) + ".kdm";
}

}  // namespace

Status encodeFile(const std::string& input, const std::string& output, const EncodeOptions& options, io::Notes& notes,
                  Summary* summary) {
  tinygltf::Model model;
  if (auto s = detail::loadScene(input, model, notes); !s.ok()) return s;
  for (const char* compressed : {"KHR_draco_mesh_compression", "EXT_meshopt_compression", kExtensionName})
    if (uses(model, compressed))
      return Status::error(ErrorCode::Unsupported,
                           input + ": its geometry is compressed with " + compressed + " already; decode it first");
  Summary done;
  std::vector<Encoded> encoded;
  std::vector<std::vector<bool>> compressed(model.meshes.size());
  for (size_t m = 0; m < model.meshes.size(); ++m) {
    compressed[m].assign(model.meshes[m].primitives.size(), false);
    for (size_t p = 0; p < model.meshes[m].primitives.size(); ++p) {
      ++done.primitives;
      Encoded item;
      Status error;
      if (encodePrimitive(model, m, p, options, notes, item, error)) {
        compressed[m][p] = true;
        encoded.push_back(std::move(item));
      } else if (!error.ok()) {
        return Status::error(error.code, input + ": " + error.message);
      }
    }
  }

  // The stream's accessors describe its values and hold none (unless they
  // are a fallback): an accessor nothing else uses loses its data, one
  // shared with the rest of the scene is copied.
  std::vector<int> shared = otherUses(model, compressed);
  std::vector<bool> claimed(model.accessors.size(), false);
  const auto streamAccessor = [&](int index, size_t count) {
    if (shared[size_t(index)] > 0 || claimed[size_t(index)]) {
      model.accessors.push_back(model.accessors[size_t(index)]);
      index = int(model.accessors.size() - 1);
      shared.push_back(0);
      claimed.push_back(true);
    }
    claimed[size_t(index)] = true;
    tinygltf::Accessor& accessor = model.accessors[size_t(index)];
    accessor.bufferView = -1;
    accessor.byteOffset = 0;
    accessor.sparse.isSparse = false;
    accessor.count = count;
    return index;
  };
  detail::BufferWriter writer(model);
  for (const Encoded& item : encoded) {
    tinygltf::Primitive& primitive = model.meshes[item.mesh].primitives[item.primitive];
    const Complex& complex = item.geometry.complex;
    const size_t vertexCount = complex.vertexCount();
    tinygltf::Value::Object names;
    for (const VertexAttribute& attribute : complex.attributes) names[attribute.name] = tinygltf::Value(attribute.name);
    if (!options.fallback) {
      for (auto& [semantic, index] : primitive.attributes) {
        index = streamAccessor(index, vertexCount);
        tinygltf::Accessor& accessor = model.accessors[size_t(index)];
        if (semantic == "POSITION") {
          detail::setBounds(accessor, reinterpret_cast<const uint8_t*>(complex.positions.data()), vertexCount);
        } else if (!accessor.minValues.empty()) {
          const auto& attribute = *std::find_if(complex.attributes.begin(), complex.attributes.end(),
                                                [&name = semantic](const VertexAttribute& a) { return a.name == name; });
          detail::setBounds(accessor, attribute.values.data(), vertexCount);
        }
      }
      const std::vector<uint32_t>& list = item.geometry.mode == TINYGLTF_MODE_TRIANGLES ? complex.triangles : complex.edges;
      if (item.geometry.mode == TINYGLTF_MODE_POINTS) {
        primitive.indices = -1;
      } else {
        if (primitive.indices < 0) {
          tinygltf::Accessor indices;
          indices.type = TINYGLTF_TYPE_SCALAR;
          indices.componentType = vertexCount <= 0x10000 ? TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT
                                                         : TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
          model.accessors.push_back(indices);
          shared.push_back(0);
          claimed.push_back(false);
          primitive.indices = int(model.accessors.size() - 1);
        }
        primitive.indices = streamAccessor(primitive.indices, list.size());
        model.accessors[size_t(primitive.indices)].minValues.clear();
        model.accessors[size_t(primitive.indices)].maxValues.clear();
      }
      primitive.mode = item.geometry.mode;
    }
    tinygltf::Value::Object extension;
    if (options.separateStreams) {
      const std::string path = streamPath(output, item.mesh, item.primitive);
      std::ofstream file(path, std::ios::binary);
      file.write(reinterpret_cast<const char*>(item.bytes.data()), std::streamsize(item.bytes.size()));
      file.close();
      if (!file) return Status::error(ErrorCode::InvalidArgument, "cannot write " + path);
      extension["uri"] = tinygltf::Value(path.substr(path.find_last_of('/') + 1));
    } else {
      extension["bufferView"] = tinygltf::Value(writer.add(item.bytes.data(), item.bytes.size()));
    }
    extension["attributes"] = tinygltf::Value(std::move(names));
    primitive.extensions[kExtensionName] = tinygltf::Value(std::move(extension));
    ++done.streams;
    done.streamBytes += item.bytes.size();
    done.vertices += vertexCount;
  }
  if (!encoded.empty()) {
    addName(model.extensionsUsed, kExtensionName);
    if (!options.fallback) addName(model.extensionsRequired, kExtensionName);
  }
  if (auto s = detail::compactBuffers(model, keepUnreferencedViews(model, notes)); !s.ok())
    return Status::error(s.code, input + ": " + s.message);
  if (auto s = detail::saveScene(output, model); !s.ok()) return s;
  if (summary) *summary = done;
  return Status::success();
}

Status decodeFile(const std::string& input, const std::string& output, io::Notes& notes, Summary* summary) {
  tinygltf::Model model;
  if (auto s = detail::loadScene(input, model, notes); !s.ok()) return s;
  Summary done;
  detail::BufferWriter writer(model);
  std::vector<bool> accessorWritten(model.accessors.size(), false);
  for (size_t m = 0; m < model.meshes.size(); ++m)
    for (size_t p = 0; p < model.meshes[m].primitives.size(); ++p) {
      ++done.primitives;
      tinygltf::Primitive& primitive = model.meshes[m].primitives[p];
      const auto found = primitive.extensions.find(kExtensionName);
      if (found == primitive.extensions.end()) continue;
      const tinygltf::Value extension = found->second;
      const std::string context = input + ": " + where(m, p);
      if (!extension.IsObject()) return Status::error(ErrorCode::InvalidInput, context + ": the extension is not an object");
      std::vector<uint8_t> stream;
      if (extension.Get("bufferView").IsInt()) {
        const uint8_t* bytes = nullptr;
        size_t size = 0;
        if (auto s = detail::viewBytes(model, extension.Get("bufferView").GetNumberAsInt(), bytes, size); !s.ok())
          return Status::error(s.code, context + ": " + s.message);
        stream.assign(bytes, bytes + size);
      } else if (extension.Get("uri").IsString()) {
        if (auto s = detail::readRelativeFile(detail::folderOf(input), extension.Get("uri").Get<std::string>(), stream); !s.ok())
          return Status::error(s.code, context + ": " + s.message);
      } else {
        return Status::error(ErrorCode::InvalidInput, context + ": the extension has neither a bufferView nor a uri");
      }
      Complex complex;
      if (auto s = decode(stream.data(), stream.size(), complex); !s.ok())
        return Status::error(s.code, context + ": " + s.message);
      if (auto s = detail::writeDecodedPrimitive(model, primitive, extension, complex, writer, accessorWritten); !s.ok())
        return Status::error(s.code, context + ": " + s.message);
      primitive.extensions.erase(kExtensionName);
      ++done.streams;
      done.streamBytes += stream.size();
      done.vertices += complex.vertexCount();
    }
  removeName(model.extensionsUsed, kExtensionName);
  removeName(model.extensionsRequired, kExtensionName);
  if (auto s = detail::compactBuffers(model, keepUnreferencedViews(model, notes)); !s.ok())
    return Status::error(s.code, input + ": " + s.message);
  if (auto s = detail::saveScene(output, model); !s.ok()) return s;
  if (summary) *summary = done;
  return Status::success();
}

}  // namespace kdmesh::gltf
