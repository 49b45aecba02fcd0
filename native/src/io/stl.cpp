// STL, ascii and binary: a triangle soup. Every triangle brings three vertices
// of its own, kept as given (ReadOptions::weld merges equal ones); facet
// normals are ignored, as every other reader recomputes them anyway.
//
// Binary: an 80-byte header, a little-endian uint32 triangle count, then 50
// bytes per triangle (normal, three vertices as float32, a uint16 attribute).
// Ascii: "solid name", then per facet
//   facet normal nx ny nz / outer loop / vertex x y z (3 times) / endloop /
//   endfacet
// and "endsolid name". Binary headers often start with "solid" as well, so a
// file is binary when its size matches its triangle count, or when its first
// 64 KiB do not read as "solid" followed by a "facet" or "endsolid" line.
//
// A binary file is streamed: its triangles are read in blocks, and with
// welding each corner goes straight to its vertex, so that a soup takes
// memory for its distinct vertices and the triangles that welding keeps.
#include <cstring>
#include <limits>
#include <optional>

#include "io/io_internal.h"

namespace kdmesh::io::detail {
namespace {

constexpr size_t kStlHeaderBytes = 80;
constexpr size_t kStlPrefixBytes = kStlHeaderBytes + 4;
constexpr size_t kStlTriangleBytes = 50;

uint32_t loadUint32(const uint8_t* bytes) {
  return uint32_t{bytes[0]} | uint32_t{bytes[1]} << 8 |
         uint32_t{bytes[2]} << 16 | uint32_t{bytes[3]} << 24;
}

// Assembled arithmetically, so independent of the machine's byte order; the
// bits go through unchanged, NaN payloads included.
float loadFloat(const uint8_t* bytes) {
  const uint32_t bits = loadUint32(bytes);
  float value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

// The vertices and triangles of a soup: every corner is a new vertex, or
// with welding the first vertex with its position bits; a welded triangle
// left with a repeated vertex is dropped (the encoder would drop it too).
class Soup {
 public:
  Soup(Complex& out, bool weld) : out_(out) {
    if (weld) welder_.emplace(out.positions);
  }

  // Room for `triangles` triangles of three new corners each; welded soups
  // grow as their vertices turn out to be distinct.
  void reserve(uint64_t triangles) {
    if (welder_) return;
    out_.positions.reserve(9 * triangles);
    out_.triangles.reserve(3 * triangles);
  }

  uint32_t corner(const float* xyz) {
    ++corners_;
    if (welder_) return welder_->vertexAt(xyz);
    out_.positions.insert(out_.positions.end(), xyz, xyz + 3);
    return static_cast<uint32_t>(out_.vertexCount() - 1);
  }

  // A facet of `size` corners, split into a fan of triangles.
  void facet(const uint32_t* corners, size_t size) {
    const size_t first = out_.triangles.size();
    split_.append(corners, size, out_.triangles);
    if (welder_) dropped_ += dropRepeated(out_.triangles, 3, first);
  }

  void addNotes(Notes& notes) const {
    split_.addNote(notes);
    if (welder_) addWeldNotes(notes, corners_, out_.vertexCount(), dropped_);
  }

 private:
  Complex& out_;
  std::optional<Welder> welder_;
  size_t corners_ = 0;
  size_t dropped_ = 0;
  PolygonSplit split_;
};

bool sizeMatchesBinary(Bytes head, uint64_t size) {
  if (head.size < kStlPrefixBytes) return false;
  const uint64_t count = loadUint32(head.data + kStlHeaderBytes);
  return size - kStlPrefixBytes == count * kStlTriangleBytes;
}

bool looksAscii(Bytes head) {
  TextScanner scanner(head.data, head.size);
  std::string_view token;
  if (!scanner.nextContentLine() || !scanner.nextToken(token) ||
      !equalsIgnoringCase(token, "solid")) {
    return false;
  }
  if (!scanner.nextContentLine()) return false;
  scanner.nextToken(token);  // nextContentLine() guaranteed one
  return equalsIgnoringCase(token, "facet") ||
         equalsIgnoringCase(token, "endsolid");
}

// The triangle count, checked against the size before anything is
// allocated or read past the prefix.
Status readBinaryCount(Bytes head, uint64_t size, uint64_t& count) {
  if (size < kStlPrefixBytes || head.size < kStlPrefixBytes) {
    return inputError(
        "not an STL file: " + std::to_string(size) +
        " bytes are too few for the 84 bytes that start a binary STL, and "
        "the text is not ascii STL ('solid' followed by 'facet' lines)");
  }
  count = loadUint32(head.data + kStlHeaderBytes);
  const uint64_t needed = kStlPrefixBytes + count * kStlTriangleBytes;
  if (size < needed) {
    return inputError("binary STL declares " + std::to_string(count) +
                      " triangles, which take " + std::to_string(needed) +
                      " bytes, but the file has " + std::to_string(size) +
                      " (truncated file)");
  }
  if (3 * count > std::numeric_limits<uint32_t>::max()) {
    return inputError("binary STL declares " + std::to_string(count) +
                      " triangles, more vertices than 32-bit indices can "
                      "address");
  }
  return Status::success();
}

// The facet normals are not kept (every viewer recomputes them from the
// corners): a note counts the facets that gave one.
void addFacetNormalNote(Notes& notes, size_t withNormal) {
  addCountNote(notes, "ignored the facet normals of ", withNormal, "triangle", "triangles",
               " (kdmesh keeps the corners; normals follow from them)");
}

Status readBinary(Input& input, uint64_t size, Complex& out, Notes& notes,
                  bool weld) {
  uint64_t count = 0;
  if (Status status = readBinaryCount(input.head(), size, count);
      !status.ok()) {
    return status;
  }
  Soup soup(out, weld);
  soup.reserve(count);
  ByteStream bytes = input.stream(kStlPrefixBytes);
  size_t withAttribute = 0, withNormal = 0;
  for (uint64_t t = 0; t < count; ++t) {
    const uint8_t* triangle = bytes.take(kStlTriangleBytes);
    if (triangle == nullptr) {
      return inputError("binary STL ends inside triangle " +
                        std::to_string(t) + " (truncated file)");
    }
    uint32_t corners[3];
    for (size_t k = 0; k < 3; ++k) {  // past the 3 floats of the normal
      float xyz[3];
      for (size_t axis = 0; axis < 3; ++axis) {
        xyz[axis] = loadFloat(triangle + 12 * (k + 1) + 4 * axis);
      }
      corners[k] = soup.corner(xyz);
    }
    soup.facet(corners, 3);
    withAttribute += (triangle[48] | triangle[49]) != 0;
    bool normal = false;
    for (size_t i = 0; i < 12; ++i) normal |= triangle[i] != 0;
    withNormal += normal;
  }
  addFacetNormalNote(notes, withNormal);
  addCountNote(notes, "ignored the attribute values (often a colour) of ",
               withAttribute, "triangle", "triangles");
  addCountNote(notes, "ignored ", bytes.remaining(), "byte", "bytes",
               " after the triangles of the binary STL");
  soup.addNotes(notes);
  return Status::success();
}

class AsciiStl {
 public:
  AsciiStl(Bytes text, Complex& out, bool weld)
      : scanner_(text.data, text.size), out_(out), soup_(out, weld) {}

  Status read(Notes& notes) {
    std::string_view token;
    bool ended = true;  // outside a solid
    while (next(token)) {
      if (ended) {
        if (!equalsIgnoringCase(token, "solid")) {
          return error("expected 'solid', found " + quoted(token));
        }
        skipRestOfLine();  // the name
        ended = false;
      } else if (equalsIgnoringCase(token, "endsolid")) {
        skipRestOfLine();
        ended = true;
      } else if (equalsIgnoringCase(token, "facet")) {
        if (Status status = readFacet(); !status.ok()) return status;
        ++facets_;
      } else {
        return error("expected 'facet' or 'endsolid', found " +
                     quoted(token));
      }
    }
    if (!ended) {
      notes.push_back("the ascii STL ends without 'endsolid' (truncated "
                      "file?)");
    }
    addFacetNormalNote(notes, withNormal_);
    soup_.addNotes(notes);
    return Status::success();
  }

 private:
  bool next(std::string_view& token) {
    return scanner_.nextTokenAcrossLines(token);
  }

  void skipRestOfLine() {
    std::string_view token;
    while (scanner_.nextToken(token)) {
    }
  }

  Status error(const std::string& message) const {
    return lineError(scanner_.lineNumber(), message);
  }

  Status facetError(const std::string& message) const {
    return error("facet " + std::to_string(facets_) + ": " + message);
  }

  Status expect(std::string_view keyword) {
    std::string_view token;
    if (!next(token)) {
      return facetError("the file ends before '" + std::string(keyword) +
                        "'");
    }
    if (!equalsIgnoringCase(token, keyword)) {
      return facetError("expected '" + std::string(keyword) + "', found " +
                        quoted(token));
    }
    return Status::success();
  }

  Status number(float& value, const char* what) {
    std::string_view token;
    if (!next(token)) {
      return facetError(std::string("the file ends inside a ") + what);
    }
    if (!parseFloat(token, value)) {
      return facetError(std::string(what) + ": " + quoted(token) +
                        " is not a number");
    }
    return Status::success();
  }

  // After "facet": the normal, the loop of vertices and "endfacet".
  Status readFacet() {
    float normal;
    bool given = false;
    if (Status status = expect("normal"); !status.ok()) return status;
    for (int axis = 0; axis < 3; ++axis) {
      if (Status status = number(normal, "normal"); !status.ok()) {
        return status;
      }
      given |= normal != 0;
    }
    withNormal_ += given;
    for (const char* keyword : {"outer", "loop"}) {
      if (Status status = expect(keyword); !status.ok()) return status;
    }
    polygon_.clear();
    std::string_view token;
    for (;;) {
      if (!next(token)) return facetError("the file ends inside the loop");
      if (equalsIgnoringCase(token, "endloop")) break;
      if (!equalsIgnoringCase(token, "vertex")) {
        return facetError("expected 'vertex' or 'endloop', found " +
                          quoted(token));
      }
      if (out_.vertexCount() >= std::numeric_limits<uint32_t>::max()) {
        return facetError("more vertices than 32-bit indices can address");
      }
      float xyz[3];
      for (float& value : xyz) {
        if (Status status = number(value, "vertex"); !status.ok()) {
          return status;
        }
      }
      polygon_.push_back(soup_.corner(xyz));
    }
    if (polygon_.size() < 3) {
      return facetError("has " + std::to_string(polygon_.size()) +
                        " vertices, needs 3");
    }
    if (Status status = expect("endfacet"); !status.ok()) return status;
    soup_.facet(polygon_.data(), polygon_.size());
    return Status::success();
  }

  TextScanner scanner_;
  Complex& out_;
  size_t facets_ = 0;
  size_t withNormal_ = 0;  // facets with a nonzero normal
  std::vector<uint32_t> polygon_;  // vertices of one facet, reused
  Soup soup_;
};

}  // namespace

Status readStl(Input& input, Complex& out, Notes& notes, bool weld) {
  const Bytes head = input.head();
  const uint64_t size = input.size();
  if (!sizeMatchesBinary(head, size) && looksAscii(head)) {
    return AsciiStl(input.whole(), out, weld).read(notes);
  }
  return readBinary(input, size, out, notes, weld);
}

}  // namespace kdmesh::io::detail
