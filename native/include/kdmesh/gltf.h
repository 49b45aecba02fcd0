// kdmesh/gltf.h — kdmesh streams inside glTF 2.0 scenes.
//
// encodeFile() reads a .glb or .gltf scene and encodes the geometry of every
// triangle, line and point primitive as a kdmesh stream, recorded in the
// primitive's KDMESH_progressive_compression extension (docs/GLTF.md);
// materials, nodes, textures, images, animations, extras and every other
// part of the scene pass through unchanged. decodeFile() turns such a scene
// back into standard glTF. Like kdmesh/io.h this touches the file system and
// is not part of the WebAssembly decoder; reading a scene is validated as any
// other input (accessor ranges, counts that fit the file, index bounds).
#pragma once

#include <cstdint>
#include <string>

#include "kdmesh/io.h"
#include "kdmesh/kdmesh.h"

namespace kdmesh::gltf {

// The name of the glTF extension (docs/GLTF.md).
inline constexpr char kExtensionName[] = "KDMESH_progressive_compression";

// True for paths ending in .glb or .gltf (case-insensitive).
bool isGltfPath(const std::string& path);

struct EncodeOptions {
  // How every stream is coded. Positions are kept bit for bit unless
  // `stream.exact` is set to false (then `stream.bits` sets the grid);
  // vertex attributes are always kept bit for bit.
  kdmesh::EncodeOptions stream = [] {
    kdmesh::EncodeOptions options;
    options.exact = true;
    return options;
  }();
  // Keep the uncompressed accessors as well, so that loaders without the
  // extension draw the scene; the extension is then not required.
  bool fallback = false;
  // Write each stream to a file of its own next to the output
  // (<output stem>.<mesh>-<primitive>.kdm), referred to by URI, so that a
  // page can stream the geometry while the rest of the scene loads.
  bool separateStreams = false;
};

// What encodeFile() or decodeFile() did.
struct Summary {
  size_t primitives = 0;       // in the scene
  size_t streams = 0;          // primitives encoded (or decoded)
  uint64_t streamBytes = 0;    // bytes of those streams
  uint64_t vertices = 0;       // of those primitives
};

// A primitive that cannot be kept exactly as a kdmesh stream (morph
// targets, quantized positions, triangles listed twice, more than
// kMaxAttributes attributes, ...) stays uncompressed, with a note saying
// why. Scenes compressed with KHR_draco_mesh_compression or
// EXT_meshopt_compression are refused.
Status encodeFile(const std::string& input, const std::string& output, const EncodeOptions& options,
                  io::Notes& notes, Summary* summary = nullptr);

// Decodes every stream of the scene (from its buffer view, or from the file
// its URI names, relative to the input) into plain accessors and drops the
// extension. A stream whose counts or attributes disagree with the
// primitive's accessors is an error.
Status decodeFile(const std::string& input, const std::string& output, io::Notes& notes,
                  Summary* summary = nullptr);

// Writes a complex as a scene of one mesh (.glb, or .gltf with its .bin):
// a TRIANGLES, a LINES and a POINTS primitive (the vertices in no simplex)
// sharing the vertex accessors. Vertex attributes become COLOR_0
// ('color', normalized integers), NORMAL ('normal', float x 3), TEXCOORD_0
// ('uv', float x 2) and "_NAME" for the others; 32-bit integer attributes,
// which glTF vertex attributes cannot hold, are left out with a note.
// Tetrahedra are an InvalidArgument error.
Status writeComplexScene(const std::string& path, const Complex& complex, io::Notes& notes);

}  // namespace kdmesh::gltf
