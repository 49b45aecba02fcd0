// Pieces of kdmesh/gltf.h: scene files, accessors and buffers, primitives.
// They work on tinygltf's Model (Debian's libtinygltf-dev), which reads and
// writes the JSON and binary containers; everything glTF-specific that
// tinygltf leaves to its caller (accessor bounds, buffer layout) is here.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <tiny_gltf.h>

#include "kdmesh/gltf.h"

namespace kdmesh::gltf::detail {

// ---------------------------------------------------------------------------
// Scene files (gltf_file.cpp)
// ---------------------------------------------------------------------------

// Reads a .glb or .gltf (by its first bytes, whatever the extension).
// Images are kept as the encoded bytes the file holds, never decoded: an
// image given by a data URI moves into a buffer view of its own, one given
// by a file URI keeps the URI. tinygltf's warnings become notes.
Status loadScene(const std::string& path, tinygltf::Model& model, io::Notes& notes);
// Writes binary glTF for .glb paths, else JSON glTF with its buffer in
// <stem>.bin next to it. The model must have at most one buffer.
Status saveScene(const std::string& path, const tinygltf::Model& model);
// The folder of `path`, for URIs relative to it ("" for the current one).
std::string folderOf(const std::string& path);
// Reads a file named by a URI relative to `folder`: relative paths only
// (no scheme, no leading '/', no '..' segment).
Status readRelativeFile(const std::string& folder, const std::string& uri, std::vector<uint8_t>& bytes);

// ---------------------------------------------------------------------------
// Accessors and buffers (gltf_buffers.cpp)
// ---------------------------------------------------------------------------

// Bytes of one component of a glTF componentType (0 when invalid), and the
// components of an accessor type (0 for invalid types).
size_t componentBytes(int componentType);
int typeComponents(int type);
// The accessor type with `components` components (SCALAR, VEC2..4).
int vectorType(int components);

// The bytes of buffer view `index`, checked against its buffer.
Status viewBytes(const tinygltf::Model& model, int index, const uint8_t*& data, size_t& size);

// The accessor's elements packed one after the other (byteStride and
// byteOffset resolved, sparse values applied). Every range is checked
// against its buffer view and buffer; an accessor without a buffer view is
// refused (its values are not in the file).
Status readAccessor(const tinygltf::Model& model, int accessor, std::vector<uint8_t>& packed);
// An index accessor's values as uint32, each checked to be below `vertexCount`.
Status readIndices(const tinygltf::Model& model, int accessor, size_t vertexCount, std::vector<uint32_t>& indices);

// Sets the accessor's min and max to the bounds of `count` packed elements
// of its type (glTF requires them for POSITION; others keep them exact).
void setBounds(tinygltf::Accessor& accessor, const uint8_t* packed, size_t count);

// Appends buffer views to buffer 0 of a model (created when missing).
class BufferWriter {
 public:
  explicit BufferWriter(tinygltf::Model& model);
  // A new buffer view of `bytes`, at an offset aligned to 4 bytes.
  int add(const uint8_t* bytes, size_t size, int target = 0);
  // A vertex attribute's elements (`elementBytes` each), each at a multiple
  // of 4 bytes as glTF requires (byteStride set when that pads them).
  int addVertexAttribute(const uint8_t* packed, size_t count, size_t elementBytes);

 private:
  tinygltf::Model& model_;
};

// Merges every buffer into buffer 0 (byte ranges of unreferenced views
// dropped, views renumbered) so that the scene fits one .glb BIN chunk.
// Buffer views referenced by no accessor, image or kdmesh stream are
// removed, unless an extension the scene uses could refer to them
// (`keepUnreferencedViews`).
Status compactBuffers(tinygltf::Model& model, bool keepUnreferencedViews);

// ---------------------------------------------------------------------------
// Primitives (gltf_primitive.cpp)
// ---------------------------------------------------------------------------

// A primitive's geometry as a complex. Triangle strips and fans become
// triangle lists, line strips and loops line lists (`mode` is then 4 or 1;
// their degenerate triangles and lines, which draw nothing, are dropped);
// an indexed primitive keeps only the vertices its indices use. Vertex
// attributes other than POSITION become kdmesh attributes named as their
// semantics. `reason` says why a primitive cannot be encoded exactly
// (Unsupported status): it then stays uncompressed.
struct PrimitiveGeometry {
  Complex complex;
  int mode = 4;                  // of the encoded primitive: 0, 1 or 4
  size_t dropped = 0;            // degenerate strip, fan or loop pieces, points drawn twice
  bool allVerticesKept = true;   // every vertex of the accessors is drawn
};
Status primitiveGeometry(const tinygltf::Model& model, const tinygltf::Primitive& primitive,
                         PrimitiveGeometry& out);

// Whether a primitive drawn with `mode` holds the complex's simplices:
// 0 points, 1 edges, 4 triangles.
bool isListMode(int mode);

// Checks a decoded complex against the primitive's accessors (counts,
// attribute types and components) and writes its vertices and simplices
// into new buffer views behind those accessors.
Status writeDecodedPrimitive(tinygltf::Model& model, tinygltf::Primitive& primitive,
                             const tinygltf::Value& extension, const Complex& complex, BufferWriter& writer,
                             std::vector<bool>& accessorWritten);

}  // namespace kdmesh::gltf::detail
