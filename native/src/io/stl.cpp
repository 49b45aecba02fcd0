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
// file is binary when its size matches its triangle count, or when it does
// not read as "solid" followed by a "facet" or "endsolid" line.
#include <cstring>
#include <limits>

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

bool sizeMatchesBinary(const uint8_t* data, size_t size) {
  if (size < kStlPrefixBytes) return false;
  const uint64_t count = loadUint32(data + kStlHeaderBytes);
  return size - kStlPrefixBytes == count * kStlTriangleBytes;
}

bool looksAscii(const uint8_t* data, size_t size) {
  TextScanner scanner(data, size);
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

Status readBinary(const uint8_t* data, size_t size, Complex& out,
                  Notes& notes) {
  if (size < kStlPrefixBytes) {
    return inputError(
        "not an STL file: " + std::to_string(size) +
        " bytes are too few for the 84 bytes that start a binary STL, and "
        "the text is not ascii STL ('solid' followed by 'facet' lines)");
  }
  const uint64_t count = loadUint32(data + kStlHeaderBytes);
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
  out.positions.reserve(9 * count);
  out.triangles.reserve(3 * count);
  size_t withAttribute = 0;
  for (uint64_t t = 0; t < count; ++t) {
    const uint8_t* triangle = data + kStlPrefixBytes + t * kStlTriangleBytes;
    for (size_t k = 0; k < 9; ++k) {  // past the 3 floats of the normal
      out.positions.push_back(loadFloat(triangle + 12 + 4 * k));
    }
    const uint32_t base = static_cast<uint32_t>(3 * t);
    out.triangles.insert(out.triangles.end(), {base, base + 1, base + 2});
    withAttribute += (triangle[48] | triangle[49]) != 0;
  }
  addCountNote(notes, "ignored the attribute values (often a colour) of ",
               withAttribute, " triangles");
  addCountNote(notes, "ignored ", size - needed,
               " bytes after the triangles of the binary STL");
  return Status::success();
}

class AsciiStl {
 public:
  AsciiStl(const uint8_t* data, size_t size, Complex& out)
      : scanner_(data, size), out_(out) {}

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
    split_.addNote(notes);
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
    float ignored;
    if (Status status = expect("normal"); !status.ok()) return status;
    for (int axis = 0; axis < 3; ++axis) {
      if (Status status = number(ignored, "normal"); !status.ok()) {
        return status;
      }
    }
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
      polygon_.push_back(static_cast<uint32_t>(out_.vertexCount()));
      out_.positions.insert(out_.positions.end(), xyz, xyz + 3);
    }
    if (polygon_.size() < 3) {
      return facetError("has " + std::to_string(polygon_.size()) +
                        " vertices, needs 3");
    }
    if (Status status = expect("endfacet"); !status.ok()) return status;
    split_.append(polygon_.data(), polygon_.size(), out_.triangles);
    return Status::success();
  }

  TextScanner scanner_;
  Complex& out_;
  size_t facets_ = 0;
  std::vector<uint32_t> polygon_;  // vertices of one facet, reused
  PolygonSplit split_;
};

}  // namespace

Status readStl(const uint8_t* data, size_t size, Complex& out, Notes& notes) {
  if (!sizeMatchesBinary(data, size) && looksAscii(data, size)) {
    return AsciiStl(data, size, out).read(notes);
  }
  return readBinary(data, size, out, notes);
}

}  // namespace kdmesh::io::detail
