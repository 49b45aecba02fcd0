// Geomview OFF: a header keyword, vertex and face counts, one vertex per line,
// then one polygon per line ("n i1 ... in", optionally followed by a colour).
#include <limits>

#include "io/io_internal.h"

namespace kdmesh::io::detail {
namespace {

// OFF, or a variant whose prefix letters announce extra vertex columns
// (ST texture coordinates, C colour, N normal), which are ignored.
// 4OFF and nOFF change the dimension and are not OFF in three dimensions.
bool isOffKeyword(std::string_view keyword) {
  constexpr std::string_view kOff = "OFF";
  if (keyword.size() < kOff.size() ||
      keyword.substr(keyword.size() - kOff.size()) != kOff) {
    return false;
  }
  for (char c : keyword.substr(0, keyword.size() - kOff.size())) {
    if (c != 'S' && c != 'T' && c != 'C' && c != 'N') return false;
  }
  return true;
}

Status readCounts(TextScanner& scanner, uint64_t& vertices, uint64_t& faces) {
  std::string_view keyword, vertexCount, faceCount;
  if (!scanner.nextContentLine()) {
    return inputError("not an OFF file: it has no header");
  }
  scanner.nextToken(keyword);  // nextContentLine() guaranteed one
  if (!isOffKeyword(keyword)) {
    return lineError(scanner.lineNumber(), "not an OFF file: the header is " +
                                               quoted(keyword) +
                                               ", not 'OFF'");
  }
  // The counts may follow the keyword on its own line; the edge count after
  // them is optional and unused.
  if (!scanner.nextTokenAcrossLines(vertexCount) ||
      !scanner.nextTokenAcrossLines(faceCount) ||
      !parseCount(vertexCount, vertices) || !parseCount(faceCount, faces)) {
    return lineError(scanner.lineNumber(),
                     "OFF header needs vertex and face counts");
  }
  if (vertices > std::numeric_limits<uint32_t>::max()) {
    return lineError(scanner.lineNumber(),
                     "more vertices than 32-bit indices can address");
  }
  // The smallest vertex line is "0 0 0\n", the smallest face "3 0 0 0\n".
  uint64_t budget = scanner.remainingBytes() + 1;
  if (!takeFromBudget(vertices, 6, budget) ||
      !takeFromBudget(faces, 8, budget)) {
    return lineError(scanner.lineNumber(),
                     "OFF header declares " + std::to_string(vertices) +
                         " vertices and " + std::to_string(faces) +
                         " faces, more than the rest of the file can hold");
  }
  return Status::success();
}

Status endsEarly(size_t line, uint64_t read, uint64_t expected,
                 const char* one, const char* many) {
  return lineError(line, "the file ends after " + std::to_string(read) +
                             " of " + counted(expected, one, many));
}

// Reads the polygon on the current line into `polygon`; sets `extraValues`
// when a colour follows it.
Status readFace(TextScanner& scanner, uint64_t face, uint64_t vertexCount,
                std::vector<uint32_t>& polygon, bool& extraValues) {
  const std::string prefix = "face " + std::to_string(face);
  std::string_view token;
  uint64_t size = 0;
  scanner.nextToken(token);  // nextContentLine() guaranteed one
  if (!parseCount(token, size)) {
    return lineError(scanner.lineNumber(),
                     prefix + ": " + quoted(token) + " is not a vertex count");
  }
  if (size < 3) {
    return lineError(scanner.lineNumber(), prefix + " has " +
                                               std::to_string(size) +
                                               " vertices, needs at least 3");
  }
  // Each index takes at least a digit and a separator.
  if (size > (scanner.remainingBytes() + 1) / 2) {
    return lineError(scanner.lineNumber(),
                     prefix + " has more vertices than the line holds");
  }
  polygon.resize(size);
  for (uint32_t& index : polygon) {
    uint64_t value = 0;
    if (!scanner.nextToken(token)) {
      return lineError(scanner.lineNumber(), prefix + " has fewer than " +
                                                 std::to_string(size) +
                                                 " vertex indices");
    }
    if (!parseCount(token, value)) {
      return lineError(scanner.lineNumber(), prefix + ": " + quoted(token) +
                                                 " is not a vertex index");
    }
    if (value >= vertexCount) {
      return lineError(scanner.lineNumber(),
                       prefix + ": vertex index " + std::to_string(value) +
                           " is out of range (" + std::to_string(vertexCount) +
                           " vertices)");
    }
    index = static_cast<uint32_t>(value);
  }
  extraValues = scanner.nextToken(token);
  return Status::success();
}

}  // namespace

Status readOff(const uint8_t* data, size_t size, Complex& out, Notes& notes, bool keepDoubles) {
  TextScanner scanner(data, size, {/*commaSeparates=*/false,
                                   /*hashComments=*/true});
  uint64_t vertexCount = 0, faceCount = 0;
  if (Status status = readCounts(scanner, vertexCount, faceCount);
      !status.ok()) {
    return status;
  }
  out.positions.reserve(3 * vertexCount);
  out.triangles.reserve(3 * faceCount);

  size_t extraVertexColumns = 0;
  bool beyondFloat = false;  // a coordinate that float32 does not hold
  for (uint64_t v = 0; v < vertexCount; ++v) {
    if (!scanner.nextContentLine()) {
      return endsEarly(scanner.lineNumber(), v, vertexCount, "vertex", "vertices");
    }
    bool extraColumns = false;
    Status status = readPositionLine(scanner, out.positions, extraColumns,
                                     keepDoubles ? &out.positions64 : nullptr, &beyondFloat);
    if (!status.ok()) return status;
    extraVertexColumns += extraColumns;
  }
  settleDoubles(out, beyondFloat, keepDoubles, notes);

  std::vector<uint32_t> polygon;  // reused for every face
  PolygonSplit split;
  size_t facesWithColour = 0;
  for (uint64_t f = 0; f < faceCount; ++f) {
    if (!scanner.nextContentLine()) {
      return endsEarly(scanner.lineNumber(), f, faceCount, "face", "faces");
    }
    bool extraValues = false;
    Status status = readFace(scanner, f, vertexCount, polygon, extraValues);
    if (!status.ok()) return status;
    facesWithColour += extraValues;
    split.append(polygon.data(), polygon.size(), out.triangles);
  }

  // More lines than the header declares: most likely wrong counts, so say so
  // rather than drop them silently.
  size_t extraLines = 0, firstExtraLine = 0;
  while (scanner.nextContentLine()) {
    if (extraLines++ == 0) firstExtraLine = scanner.lineNumber();
  }
  if (extraLines > 0) {
    notes.push_back("ignored " + counted(extraLines, "line", "lines") +
                    " after the " + counted(faceCount, "face", "faces") +
                    " that the header declares (the first: line " +
                    std::to_string(firstExtraLine) + ")");
  }
  addCountNote(notes,
               "ignored extra vertex columns (colour, normal or texture "
               "coordinates) on ",
               extraVertexColumns, "vertex", "vertices");
  addCountNote(notes, "ignored colour values on ", facesWithColour, "face", "faces");
  split.addNote(notes);
  return Status::success();
}

Status writeOff(const Complex& complex, std::vector<uint8_t>& out) {
  if (!complex.edges.empty() || !complex.tetrahedra.empty()) {
    return Status::error(ErrorCode::InvalidArgument,
                         "OFF holds only triangles, but the complex has "
                         "edges or tetrahedra");
  }
  if (!pointsAreImplicit(complex)) {
    return Status::error(ErrorCode::InvalidArgument,
                         "OFF cannot hold explicit points on vertices that "
                         "triangles use");
  }
  TextOut text(out);
  text.word("OFF").endLine();
  text.integer(complex.vertexCount())
      .integer(complex.triangles.size() / 3)
      .integer(0)
      .endLine();
  for (size_t v = 0; v < complex.vertexCount(); ++v) text.point(complex, v).endLine();
  for (size_t i = 0; i < complex.triangles.size(); i += 3) {
    text.integer(3);
    for (size_t k = 0; k < 3; ++k) text.integer(complex.triangles[i + k]);
    text.endLine();
  }
  return Status::success();
}

}  // namespace kdmesh::io::detail
