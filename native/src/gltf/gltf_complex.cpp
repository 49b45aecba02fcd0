// A complex as a glTF scene of one mesh (kdmesh decode x.kdm -o x.glb).
#include <cctype>
#include <map>

#include "gltf_internal.h"

namespace kdmesh::gltf {
namespace {

using detail::BufferWriter;

int componentTypeOf(AttributeType type) {
  switch (type) {
    case AttributeType::Int8: return TINYGLTF_COMPONENT_TYPE_BYTE;
    case AttributeType::UInt8: return TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    case AttributeType::Int16: return TINYGLTF_COMPONENT_TYPE_SHORT;
    case AttributeType::UInt16: return TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    case AttributeType::UInt32: return TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    case AttributeType::Float32: return TINYGLTF_COMPONENT_TYPE_FLOAT;
    default: return -1;  // Int32: no glTF type
  }
}

// The semantic of a kdmesh attribute as PLY readers name them (color,
// normal, uv), else an application-specific "_NAME"; whether its integers
// are normalized (colours).
std::string semanticOf(const VertexAttribute& a, bool& normalized) {
  normalized = false;
  const bool integer8or16 = a.type == AttributeType::UInt8 || a.type == AttributeType::UInt16;
  if (a.name == "color" && a.components >= 3 && (integer8or16 || a.type == AttributeType::Float32)) {
    normalized = integer8or16;
    return "COLOR_0";
  }
  if (a.name == "normal" && a.components == 3 && a.type == AttributeType::Float32) return "NORMAL";
  if (a.name == "uv" && a.components == 2 && a.type == AttributeType::Float32) return "TEXCOORD_0";
  std::string semantic = "_";
  for (const char c : a.name) semantic += std::isalnum(static_cast<unsigned char>(c)) ? char(std::toupper(c)) : '_';
  return semantic;
}

int addIndices(tinygltf::Model& model, BufferWriter& writer, const std::vector<uint32_t>& list, size_t vertexCount) {
  tinygltf::Accessor accessor;
  accessor.type = TINYGLTF_TYPE_SCALAR;
  accessor.count = list.size();
  if (vertexCount <= 0x10000) {
    std::vector<uint16_t> narrow(list.begin(), list.end());
    accessor.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    accessor.bufferView = writer.add(reinterpret_cast<const uint8_t*>(narrow.data()), narrow.size() * 2,
                                     TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  } else {
    accessor.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    accessor.bufferView = writer.add(reinterpret_cast<const uint8_t*>(list.data()), list.size() * 4,
                                     TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  }
  model.accessors.push_back(accessor);
  return int(model.accessors.size() - 1);
}

}  // namespace

Status writeComplexScene(const std::string& path, const Complex& complex, io::Notes& notes) {
  if (!complex.tetrahedra.empty()) return Status::error(ErrorCode::InvalidArgument, "glTF cannot hold tetrahedra");
  const size_t vertexCount = complex.vertexCount();
  if (vertexCount == 0) return Status::error(ErrorCode::InvalidArgument, "glTF cannot hold a complex without vertices");
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "kdmesh";
  BufferWriter writer(model);
  std::map<std::string, int> attributes;
  tinygltf::Accessor position;
  position.type = TINYGLTF_TYPE_VEC3;
  position.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  position.count = vertexCount;
  const auto* xyz = reinterpret_cast<const uint8_t*>(complex.positions.data());
  position.bufferView = writer.addVertexAttribute(xyz, vertexCount, 12);
  detail::setBounds(position, xyz, vertexCount);
  model.accessors.push_back(position);
  attributes["POSITION"] = 0;
  for (const VertexAttribute& a : complex.attributes) {
    tinygltf::Accessor accessor;
    accessor.componentType = componentTypeOf(a.type);
    // glTF vertex attributes have no 32-bit integers.
    if (accessor.componentType < 0 || accessor.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
      notes.push_back("left out the vertex attribute " + a.name + ": glTF has no 32-bit integer vertex attributes");
      continue;
    }
    const std::string semantic = semanticOf(a, accessor.normalized);
    accessor.type = detail::vectorType(a.components);
    accessor.count = vertexCount;
    accessor.bufferView = writer.addVertexAttribute(a.values.data(), vertexCount, a.valueBytes());
    model.accessors.push_back(accessor);
    attributes[semantic] = int(model.accessors.size() - 1);
  }
  // One primitive per kind of simplex, sharing the vertices.
  tinygltf::Mesh mesh;
  const auto primitive = [&](int mode, const std::vector<uint32_t>& list) {
    if (list.empty()) return;
    tinygltf::Primitive p;
    p.mode = mode;
    p.attributes = attributes;
    p.indices = addIndices(model, writer, list, vertexCount);
    mesh.primitives.push_back(p);
  };
  primitive(TINYGLTF_MODE_TRIANGLES, complex.triangles);
  primitive(TINYGLTF_MODE_LINE, complex.edges);
  // The isolated vertices: those in no edge or triangle.
  std::vector<bool> used(vertexCount, false);
  for (const auto* list : {&complex.edges, &complex.triangles})
    for (const uint32_t v : *list) used[v] = true;
  std::vector<uint32_t> isolated;
  for (uint32_t v = 0; v < vertexCount; ++v)
    if (!used[v]) isolated.push_back(v);
  primitive(TINYGLTF_MODE_POINTS, isolated);
  model.meshes.push_back(mesh);
  tinygltf::Node node;
  node.mesh = 0;
  model.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes = {0};
  model.scenes.push_back(scene);
  model.defaultScene = 0;
  return detail::saveScene(path, model);
}

}  // namespace kdmesh::gltf
