// kdmesh/io.h — reading and writing mesh and point files.
//
// Separate from the codec core (kdmesh.h) because it touches the file system
// and is not part of the WebAssembly decoder. Every reader validates what it
// reads: malformed text, truncated binaries, counts that do not fit the file
// and out-of-range indices are errors with a one-line message naming the
// place (line number or element index), never a crash or an allocation the
// file size does not justify.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "kdmesh/kdmesh.h"

namespace kdmesh::io {

enum class Format : uint8_t { Unknown, Ply, Obj, Off, Xyz };

// By file extension, case-insensitive: .ply .obj .off .xyz (.txt, .pts -> Xyz).
Format formatFromPath(const std::string& path);
const char* formatName(Format format);

// Things a reader did that the user should know about but that are not
// errors (ignored properties, polygons split into triangles, ...). Each note
// is one line of text; repeated events are counted in one note.
using Notes = std::vector<std::string>;

Status readMemory(Format format, const uint8_t* data, size_t size,
                  Complex& out, Notes& notes);
Status readFile(const std::string& path, Complex& out, Notes& notes);

struct WriteOptions {
  // PLY only: ascii instead of binary little-endian.
  bool asciiPly = false;
};

// Text formats print 9 significant digits, enough to give back every float32
// bit; binary PLY stores float32 as is. A format that cannot hold some
// simplices of the complex (XYZ holds only vertices, OFF no tetrahedra) is an
// InvalidArgument error rather than a silent loss.
Status writeMemory(Format format, const Complex& complex,
                   std::vector<uint8_t>& out, const WriteOptions& options = {});
Status writeFile(const std::string& path, const Complex& complex,
                 const WriteOptions& options = {});

}  // namespace kdmesh::io
