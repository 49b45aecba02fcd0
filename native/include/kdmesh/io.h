// kdmesh/io.h — reading and writing mesh and point files.
//
// Separate from the codec core (kdmesh.h) because it touches the file system
// and is not part of the WebAssembly decoder. Every reader validates what it
// reads: malformed text, truncated binaries, counts that do not fit the file
// and out-of-range indices are errors with a one-line message naming the
// place (line number or element index), never a crash or an allocation the
// file size does not justify. readFile streams the bodies of binary STL and
// PLY files in blocks; the other formats are read whole, in one allocation.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "kdmesh/kdmesh.h"

namespace kdmesh::io {

enum class Format : uint8_t {
  Unknown,
  Ply,
  Obj,
  Off,
  Xyz,
  Stl,     // ascii or binary STL, read only
  Medit,   // INRIA Medit .mesh, ascii
  TetGen,  // TetGen .node (vertices) plus .ele (tetrahedra)
  Vtk,     // legacy VTK, ascii
};

// By file extension, case-insensitive: .ply .obj .off .xyz (.txt, .pts -> Xyz)
// .stl .mesh .vtk, and .node or .ele -> TetGen.
Format formatFromPath(const std::string& path);
const char* formatName(Format format);

// Things a reader did that the user should know about but that are not
// errors (ignored properties, polygons split into triangles, ...). Each note
// is one line of text; repeated events are counted in one note.
using Notes = std::vector<std::string>;

struct ReadOptions {
  // Merge vertices whose positions are bit-identical (so +0 and -0 stay
  // apart), keeping the first of each and the order of first appearance, and
  // renumber the simplices; a note gives the count. Meant for STL, a triangle
  // soup with three vertices of its own per triangle, but works for every
  // format. Simplices that welding leaves with a repeated vertex are
  // dropped, and a note counts them (the encoder would drop them as
  // degenerate). STL welds each corner as it is read, so that a soup takes
  // memory for its distinct vertices rather than three per triangle.
  bool weld = false;
  // Keep float64 coordinates: PLY `double` properties, Medit
  // MeshVersionFormatted 2 and OBJ, OFF, XYZ, VTK and TetGen .node
  // coordinates with more digits than float32 holds fill
  // Complex::positions64 (exactly), positions holding their float32
  // roundings, for exact encoding. Without it they are rounded to float32,
  // and a note says so. STL reads float32. (Text: a coordinate says more than float32 holds when its
  // double differs from that of the shortest decimal of its float32
  // rounding, so a file written from floats, "0.1" included, reads as
  // float32.)
  bool keepDoubles = false;
};

// Format notes:
// - STL: binary when the size is 84 + 50 * (the count at byte 80), or when
//   the first 64 KiB are not "solid" followed by a "facet" or "endsolid" line
//   (binary headers often start with "solid" too). A count that needs more
//   bytes than the file has is an error; bytes after the triangles are
//   ignored with a note. Three new vertices per triangle, as given; facet
//   normals and attribute bytes are ignored.
// - Medit: Dimension 3 only. Quadrilaterals are split into two triangles
//   (a note says how many); Hexahedra, Prisms, Pyramids, P2/Q2 elements and
//   known per-item sections (Corners, Ridges, Required*, Normals, ...) are
//   skipped with a note; any other keyword is an error naming it. Vertex
//   references become the attribute `ref` (unless all are 0), of the
//   narrowest integer type that holds them (uint8, int8, uint16, ...);
//   element references are counted in a note. The writer writes `ref`.
// - TetGen: readFile on x.node or x.ele reads both files (x.ele is optional
//   when x.node is given: without it the nodes are a point cloud). Point
//   numbers may start at 0 or 1; 10-node tetrahedra keep their 4 corners.
//   The .node point attributes become the attribute `attribute` (float32,
//   up to 4 components; more are grouped by 4 as `attribute_0`,
//   `attribute_4`, ...) and the boundary markers `marker`, of the narrowest
//   integer type that holds them; the writer writes every column and the
//   markers back (attributes named otherwise than the reader names them are
//   refused rather than renamed). Region
//   attributes of the .ele are counted in a note.
//   readMemory can read one buffer only, so it reads a .node alone.
// - VTK: legacy ascii UNSTRUCTURED_GRID or POLYDATA, cells in the classic
//   layout or the OFFSETS/CONNECTIVITY layout of version 5. Vertex and
//   poly-vertex cells become points, lines and poly-lines edges, triangles
//   and strips triangles, tetrahedra tetrahedra; quads and polygons are split
//   into triangles with a note, other cell types are skipped with a note.
//   POINT_DATA arrays of 1 to 4 components become vertex attributes named
//   as in the file, of the file's type (integers of up to 32 bits as such;
//   float and double as float32, double rounded with a note; 64-bit
//   integers as the narrowest type that holds their values), except NORMALS
//   as `normal`, TEXTURE_COORDINATES as `uv` and COLOR_SCALARS as `color`,
//   uint8 = 255 x value rounded, as VTK stores them. SCALARS, VECTORS,
//   GLOBAL_IDS, PEDIGREE_IDS and FIELD arrays of one tuple per point are
//   read; TENSORS, lookup tables, CELL_DATA and the dataset's FIELD data are
//   skipped and counted in a note. The writer gives `normal`, `uv` and a
//   uint8 `color` their keywords, every other attribute SCALARS of its type.
//   Binary VTK is an error.
// - OBJ: a corner v/vt/vn that names a texture coordinate or a normal makes
//   a vertex of its own for each distinct (v, vt, vn) triple, with the
//   attributes `uv` (float32 × 2, or × 3 when a vt line gives w; absent
//   coordinates 0) and `normal` (float32 × 3): a seam's vertices share a
//   position and keep their own values. A corner without vt or vn (v alone,
//   or v//vn without vt) gets 0 for what it lacks; it is the v line's own
//   vertex, shared by every such corner, as are the v lines no corner
//   names. Points (p) may name vt and vn too, as the writer does for
//   vertices in no face or line. vt and vn lines no corner names are
//   counted in a note. The writer writes each distinct position, texture
//   coordinate and normal once, and a vertex whose whole corner equals
//   another vertex's on a v line of its own. Materials (usemtl) label the
//   lines and faces that follow, or groups (g) in a file without usemtl:
//   by the names' values when every name is a 32-bit decimal integer and
//   no line or face precedes the first name, otherwise numbered from 0 in
//   order of first use (the unnamed one of what precedes any counting as
//   one), with a note listing the names. The writer writes labels as
//   usemtl lines named by their values. o, s and mtllib lines, and g lines
//   beside usemtl, are counted in a note.
Status readMemory(Format format, const uint8_t* data, size_t size,
                  Complex& out, Notes& notes, const ReadOptions& options = {});
Status readFile(const std::string& path, Complex& out, Notes& notes,
                const ReadOptions& options = {});

// Whether files of `format` hold the vertex attribute bit for bit: PLY any;
// OBJ `uv` (float32 × 2 or 3, as vt) and `normal` (float32 × 3, as vn); VTK
// any whose name has no space; Medit `ref` and TetGen `marker` (integers, 1
// component; read back as the narrowest type that holds their values) and
// TetGen `attribute` or `attribute_0`, `attribute_4`, ... (float32). (Text keeps a NaN's sign, not its payload.)
// Writers refuse a complex with an attribute their format cannot hold
// (InvalidArgument) rather than drop it.
bool holdsAttribute(Format format, const VertexAttribute& attribute);
// Whether files of `format` hold simplex labels exactly: PLY (a `label`
// property), Medit (element references), TetGen (the region attribute of
// tetrahedra), OBJ (usemtl lines whose material names are the labels) and
// VTK (an integer cell data array).
// Writers refuse a labelled complex otherwise (InvalidArgument).
bool holdsLabels(Format format);

struct WriteOptions {
  // PLY only: ascii instead of binary little-endian.
  bool asciiPly = false;
};

// Text formats print the shortest decimal that gives back every float32
// bit (at most 9 significant digits); binary PLY stores float32 as is. A
// complex with positions64 is written in doubles instead: PLY `double`
// properties, Medit MeshVersionFormatted 2, VTK `double` points, other text
// formats at most 17 significant digits. A format that cannot hold some
// simplices of the complex (XYZ holds only vertices, OFF no tetrahedra) is an
// InvalidArgument error rather than a silent loss. STL cannot be written.
// TetGen: writeFile on x.node or x.ele writes x.node, plus x.ele when there
// are tetrahedra or the path names the .ele; it holds no edges or triangles.
// writeMemory(TetGen) gives the .node alone and so refuses tetrahedra.
Status writeMemory(Format format, const Complex& complex,
                   std::vector<uint8_t>& out, const WriteOptions& options = {});
// The whole file at `path` (a .kdm stream, a glTF scene), or an error that
// names it.
Status readBytes(const std::string& path, std::vector<uint8_t>& bytes);

Status writeFile(const std::string& path, const Complex& complex,
                 const WriteOptions& options = {});

}  // namespace kdmesh::io
