// Wavefront OBJ: vertices, points, polylines and faces; materials, texture
// coordinates, normals and groups are not part of a simplicial complex.
#include "io/io_internal.h"

namespace kdmesh::io::detail {
namespace {

// Keywords whose data kdmesh does not keep (yet), and what they hold: each
// skipped line is counted, and the counts noted.
constexpr struct {
  std::string_view keyword, what;
} kSkippedKeywords[] = {
    {"vt", "texture coordinates (vt)"}, {"vn", "normals (vn)"},       {"vp", "parameter-space vertices (vp)"},
    {"g", "group names (g)"},           {"o", "object names (o)"},    {"s", "smoothing groups (s)"},
    {"usemtl", "material uses (usemtl)"}, {"mtllib", "material libraries (mtllib)"},
};
constexpr size_t kSkippedKinds = sizeof kSkippedKeywords / sizeof kSkippedKeywords[0];

// The index of a skipped keyword, or kSkippedKinds.
size_t skippedKind(std::string_view keyword) {
  for (size_t i = 0; i < kSkippedKinds; ++i)
    if (keyword == kSkippedKeywords[i].keyword) return i;
  return kSkippedKinds;
}

const char* simplexName(char keyword) {
  switch (keyword) {
    case 'f': return "face";
    case 'l': return "line";
    default: return "point";
  }
}

size_t minimumIndices(char keyword) {
  switch (keyword) {
    case 'f': return 3;
    case 'l': return 2;
    default: return 1;
  }
}

// OBJ counts vertices from 1; a negative index counts back from the latest
// vertex, so both depend on how many vertices precede the line.
bool resolveIndex(int64_t value, size_t verticesSoFar, uint32_t& index) {
  const int64_t resolved =
      value > 0 ? value - 1 : static_cast<int64_t>(verticesSoFar) + value;
  if (resolved < 0 || static_cast<uint64_t>(resolved) >= verticesSoFar) {
    return false;
  }
  index = static_cast<uint32_t>(resolved);
  return true;
}

// Reads the vertex indices of an f, l or p line. Face corners may be v, v/vt,
// v//vn or v/vt/vn; only v matters here.
Status readIndexLine(TextScanner& scanner, char keyword, size_t verticesSoFar,
                     std::vector<uint32_t>& indices) {
  indices.clear();
  std::string_view token;
  while (scanner.nextToken(token)) {
    const std::string_view vertex = token.substr(0, token.find('/'));
    int64_t value;
    if (!parseInteger(vertex, value)) {
      return lineError(scanner.lineNumber(),
                       quoted(token) + " is not a vertex index");
    }
    uint32_t index;
    if (!resolveIndex(value, verticesSoFar, index)) {
      return lineError(scanner.lineNumber(),
                       std::string(simplexName(keyword)) + " vertex index " +
                           std::to_string(value) +
                           " is out of range: OBJ numbers vertices from 1 (and "
                           "from -1 back from the last), " +
                           std::to_string(verticesSoFar) +
                           " defined so far");
    }
    indices.push_back(index);
  }
  if (indices.size() < minimumIndices(keyword)) {
    return lineError(scanner.lineNumber(),
                     std::string(simplexName(keyword)) + " has " +
                         std::to_string(indices.size()) +
                         " vertices, needs at least " +
                         std::to_string(minimumIndices(keyword)));
  }
  return Status::success();
}

void addSimplices(char keyword, const std::vector<uint32_t>& indices,
                  Complex& out, PolygonSplit& split) {
  switch (keyword) {
    case 'f':
      split.append(indices.data(), indices.size(), out.triangles);
      break;
    case 'l':  // a polyline: an edge between each consecutive pair
      for (size_t i = 0; i + 1 < indices.size(); ++i) {
        out.edges.insert(out.edges.end(), {indices[i], indices[i + 1]});
      }
      break;
    default:
      out.points.insert(out.points.end(), indices.begin(), indices.end());
      break;
  }
}

}  // namespace

Status readObj(const uint8_t* data, size_t size, Complex& out, Notes& notes) {
  TextScanner scanner(data, size, {/*commaSeparates=*/false,
                                   /*hashComments=*/true});
  std::vector<uint32_t> indices;  // of one line, reused
  PolygonSplit split;
  size_t extraColumnLines = 0;
  size_t unknownLines = 0;
  size_t skipped[kSkippedKinds] = {};
  std::string firstUnknown;
  std::string_view keyword;
  while (scanner.nextLine()) {
    if (!scanner.nextToken(keyword)) continue;
    if (keyword == "v") {
      bool extraColumns = false;
      Status status = readPositionLine(scanner, out.positions, extraColumns);
      if (!status.ok()) return status;
      extraColumnLines += extraColumns;
    } else if (keyword == "f" || keyword == "l" || keyword == "p") {
      Status status =
          readIndexLine(scanner, keyword[0], out.vertexCount(), indices);
      if (!status.ok()) return status;
      addSimplices(keyword[0], indices, out, split);
    } else if (const size_t kind = skippedKind(keyword); kind < kSkippedKinds) {
      ++skipped[kind];
    } else {
      if (unknownLines++ == 0) {
        firstUnknown = quoted(keyword) + " on line " +
                       std::to_string(scanner.lineNumber());
      }
    }
  }
  addCountNote(notes, "ignored extra columns (w or colour) on ",
               extraColumnLines, " vertex lines");
  split.addNote(notes);
  std::string lost;
  for (size_t i = 0; i < kSkippedKinds; ++i)
    if (skipped[i] > 0)
      lost += (lost.empty() ? "" : ", ") + std::to_string(skipped[i]) + " " + std::string(kSkippedKeywords[i].what);
  if (!lost.empty()) {
    notes.push_back("ignored " + lost +
                    ": kdmesh keeps an OBJ's vertex positions, faces, lines and points only");
  }
  if (unknownLines > 0) {
    notes.push_back("ignored " + std::to_string(unknownLines) +
                    " lines with unknown keywords (the first: " +
                    firstUnknown + ")");
  }
  return Status::success();
}

Status writeObj(const Complex& complex, std::vector<uint8_t>& out) {
  if (!complex.tetrahedra.empty()) {
    return Status::error(ErrorCode::InvalidArgument,
                         "OBJ cannot hold tetrahedra");
  }
  TextOut text(out);
  text.word("# written by kdmesh").endLine();
  const std::vector<float>& positions = complex.positions;
  for (size_t i = 0; i < positions.size(); i += 3) {
    text.word("v").point(&positions[i]).endLine();
  }
  // OBJ indices count from 1.
  for (uint32_t point : complex.points) {
    text.word("p").integer(uint64_t{point} + 1).endLine();
  }
  for (size_t i = 0; i < complex.edges.size(); i += 2) {
    text.word("l")
        .integer(uint64_t{complex.edges[i]} + 1)
        .integer(uint64_t{complex.edges[i + 1]} + 1)
        .endLine();
  }
  for (size_t i = 0; i < complex.triangles.size(); i += 3) {
    text.word("f");
    for (size_t k = 0; k < 3; ++k) {
      text.integer(uint64_t{complex.triangles[i + k]} + 1);
    }
    text.endLine();
  }
  return Status::success();
}

}  // namespace kdmesh::io::detail
