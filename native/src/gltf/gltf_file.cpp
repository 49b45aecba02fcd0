// Scene files: .glb and .gltf through tinygltf, images kept as their bytes.
#include <algorithm>
#include <cctype>
#include <fstream>
#include <cstring>
#include <iterator>

#include <nlohmann/json.hpp>

#include "gltf_internal.h"

namespace kdmesh::gltf {

bool isGltfPath(const std::string& path) {
  const size_t dot = path.rfind('.');
  if (dot == std::string::npos) return false;
  std::string extension = path.substr(dot);
  for (char& c : extension) c = char(std::tolower(static_cast<unsigned char>(c)));
  return extension == ".glb" || extension == ".gltf";
}

namespace detail {
namespace {

Status invalid(const std::string& message) { return Status::error(ErrorCode::InvalidInput, message); }

// tinygltf's messages end in line breaks and may hold several lines: one
// line, "; " between them.
std::string joinedLines(const std::string& text) {
  std::string out;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (!line.empty()) out += (out.empty() ? "" : "; ") + line;
    start = end + 1;
  }
  return out;
}

// Keeps an image's encoded bytes instead of decoding its pixels. tinygltf
// calls this for every image it could read: an image in a buffer view or a
// file keeps its reference, so only a data URI's bytes (no bufferView, no
// uri) need keeping, in image->image, until loadScene() moves them.
bool keepEncodedImage(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                      const unsigned char* bytes, int size, void*) {
  if (image->bufferView < 0 && image->uri.empty()) image->image.assign(bytes, bytes + size);
  return true;
}

// Writes no image files: every image keeps its buffer view or URI.
bool keepImageReference(const std::string*, const std::string*, const tinygltf::Image*, bool, std::string*, void*) {
  return false;
}

// JSON arrays and objects nest at most this deep in a scene (glTF needs
// about 10): the JSON parsers recurse once per level, and a file of deeply
// nested brackets would exhaust the stack.
constexpr int kMaxJsonDepth = 256;

// Whether the brackets of JSON text (outside strings) nest at most
// kMaxJsonDepth deep.
bool nestingWithinLimit(const uint8_t* text, size_t size) {
  int depth = 0;
  bool inString = false;
  for (size_t i = 0; i < size; ++i) {
    const uint8_t c = text[i];
    if (inString) {
      if (c == '\\') ++i;
      else if (c == '"') inString = false;
    } else if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth) return false;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return true;
}

// A primitive's indices taken out of the JSON (see holdDatalessIndices).
struct HeldIndices {
  size_t mesh, primitive;
  int accessor;
};

// tinygltf 2.7 refuses a primitive whose indices accessor has no buffer
// view, which is how the indices of a compressed primitive look (here as
// with KHR_draco_mesh_compression). Such indices are taken out of the JSON
// (of a .gltf, or of a .glb's JSON chunk) before tinygltf reads it, and put
// back after. JSON that does not parse is left for tinygltf to report.
std::vector<HeldIndices> holdDatalessIndices(std::vector<uint8_t>& bytes, bool binary) {
  std::vector<HeldIndices> held;
  size_t jsonStart = 0, jsonBytes = bytes.size();
  if (binary) {
    if (bytes.size() < 20) return held;
    uint32_t length = 0;
    std::memcpy(&length, &bytes[12], 4);
    if (length > bytes.size() - 20) return held;
    jsonStart = 20;
    jsonBytes = length;
  }
  nlohmann::json json = nlohmann::json::parse(bytes.begin() + long(jsonStart), bytes.begin() + long(jsonStart + jsonBytes),
                                              nullptr, /*allow_exceptions=*/false);
  if (!json.is_object() || !json["meshes"].is_array() || !json["accessors"].is_array()) return held;
  const nlohmann::json& accessors = json["accessors"];
  for (size_t m = 0; m < json["meshes"].size(); ++m) {
    nlohmann::json& mesh = json["meshes"][m];
    if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
    nlohmann::json& primitives = mesh["primitives"];
    for (size_t p = 0; p < primitives.size(); ++p) {
      nlohmann::json& primitive = primitives[p];
      if (!primitive.is_object() || !primitive.contains("indices") || !primitive["indices"].is_number_unsigned()) continue;
      const uint64_t index = primitive["indices"].get<uint64_t>();
      if (index >= accessors.size() || !accessors[index].is_object() || accessors[index].contains("bufferView")) continue;
      held.push_back({m, p, int(index)});
      primitive.erase("indices");
    }
  }
  if (held.empty()) return held;
  std::string text = json.dump();
  if (!binary) {
    bytes.assign(text.begin(), text.end());
    return held;
  }
  text.resize((text.size() + 3) & ~size_t{3}, ' ');
  std::vector<uint8_t> rebuilt(bytes.begin(), bytes.begin() + 12);
  const uint32_t length = uint32_t(text.size());
  rebuilt.resize(20);
  std::memcpy(&rebuilt[12], &length, 4);
  std::memcpy(&rebuilt[16], "JSON", 4);
  rebuilt.insert(rebuilt.end(), text.begin(), text.end());
  rebuilt.insert(rebuilt.end(), bytes.begin() + long(jsonStart + jsonBytes), bytes.end());
  // The header's total length changes by what the JSON did (a length that
  // disagrees with the file stays as wrong for tinygltf to report).
  uint32_t total = 0;
  std::memcpy(&total, &bytes[8], 4);
  total = uint32_t(int64_t(total) + int64_t(text.size()) - int64_t(jsonBytes));
  std::memcpy(&rebuilt[8], &total, 4);
  bytes = std::move(rebuilt);
  return held;
}

}  // namespace

std::string folderOf(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

Status readRelativeFile(const std::string& folder, const std::string& uri, std::vector<uint8_t>& bytes) {
  const bool scheme = uri.find(':') != std::string::npos;
  bool parent = false;
  for (size_t start = 0; start <= uri.size();) {
    size_t end = uri.find_first_of("/\\", start);
    if (end == std::string::npos) end = uri.size();
    parent = parent || uri.compare(start, end - start, "..") == 0;
    start = end + 1;
  }
  if (uri.empty() || scheme || uri[0] == '/' || uri[0] == '\\' || parent)
    return invalid("the stream URI \"" + uri + "\" is not a relative path inside the scene's folder");
  return io::readBytes(folder + uri, bytes);
}

Status loadScene(const std::string& path, tinygltf::Model& model, io::Notes& notes) {
  std::vector<uint8_t> bytes;
  if (Status status = io::readBytes(path, bytes); !status.ok()) return status;
  std::string error;
  // tinygltf takes 32-bit sizes, as the .glb header does.
  if (bytes.size() >= (uint64_t{1} << 32)) return invalid(path + ": larger than 4 GiB, which glTF cannot hold");
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(keepEncodedImage, nullptr);
  std::string warnings;
  const bool binary = bytes.size() >= 4 && std::equal(bytes.begin(), bytes.begin() + 4, "glTF");
  // A .glb's JSON chunk, or the whole .gltf (a chunk length beyond the file
  // is left for tinygltf to report).
  uint32_t jsonBytes = 0;
  if (binary && bytes.size() >= 20) std::memcpy(&jsonBytes, &bytes[12], 4);
  const size_t jsonStart = binary ? 20 : 0;
  const size_t jsonSize = binary ? std::min<size_t>(jsonBytes, bytes.size() - std::min<size_t>(bytes.size(), 20)) : bytes.size();
  if (!nestingWithinLimit(bytes.data() + std::min(jsonStart, bytes.size()), jsonSize))
    return invalid(path + ": its JSON nests deeper than " + std::to_string(kMaxJsonDepth) + " levels");
  const std::vector<HeldIndices> held = holdDatalessIndices(bytes, binary);
  const bool ok = binary
      ? loader.LoadBinaryFromMemory(&model, &error, &warnings, bytes.data(), unsigned(bytes.size()), folderOf(path))
      : loader.LoadASCIIFromString(&model, &error, &warnings, reinterpret_cast<const char*>(bytes.data()),
                                   unsigned(bytes.size()), folderOf(path));
  if (!warnings.empty()) notes.push_back("glTF reader: " + joinedLines(warnings));
  if (!ok) return invalid(path + ": " + (error.empty() ? "not a glTF file" : joinedLines(error)));
  for (const HeldIndices& h : held)
    if (h.mesh < model.meshes.size() && h.primitive < model.meshes[h.mesh].primitives.size())
      model.meshes[h.mesh].primitives[h.primitive].indices = h.accessor;
  // Images given as data URIs move into buffer views of their own: the
  // output's buffer holds them as the file's other binary data.
  BufferWriter writer(model);
  for (tinygltf::Image& image : model.images) {
    if (image.bufferView >= 0 || !image.uri.empty() || image.image.empty()) continue;
    image.bufferView = writer.add(image.image.data(), image.image.size());
    image.image.clear();
  }
  return Status::success();
}

Status saveScene(const std::string& path, const tinygltf::Model& model) {
  if (model.buffers.size() > 1) return Status::error(ErrorCode::InvalidArgument, "a scene to write has several buffers");
  const std::string lower = [&] {
    std::string text = path;
    for (char& c : text) c = char(std::tolower(static_cast<unsigned char>(c)));
    return text;
  }();
  const bool binary = lower.size() >= 4 && lower.compare(lower.size() - 4, 4, ".glb") == 0;
  tinygltf::TinyGLTF writer;
  writer.SetImageWriter(keepImageReference, nullptr);
  tinygltf::Model copy = model;
  // JSON glTF: the buffer goes to <stem>.bin (tinygltf names it so when the
  // buffer has no URI).
  for (tinygltf::Buffer& buffer : copy.buffers) buffer.uri.clear();
  if (!writer.WriteGltfSceneToFile(&copy, path, /*embedImages=*/false, /*embedBuffers=*/false,
                                   /*prettyPrint=*/!binary, binary))
    return Status::error(ErrorCode::InvalidArgument, "cannot write " + path);
  return Status::success();
}

}  // namespace detail
}  // namespace kdmesh::gltf
