// Legacy VTK, ascii:
//
//   # vtk DataFile Version 3.0
//   a title line
//   ASCII
//   DATASET UNSTRUCTURED_GRID
//   POINTS n float           then 3n coordinates, wrapped over lines freely
//   CELLS n size             then n cells "k i1 ... ik" (size values in all)
//   CELL_TYPES n             then n cell types
//
// Version 5 files may give the cells as "CELLS offsets connectivity" followed
// by OFFSETS and CONNECTIVITY arrays; both layouts are read. POLYDATA (with
// VERTICES, LINES, POLYGONS and TRIANGLE_STRIPS) is read too. Keywords are
// case-insensitive. FIELD data and METADATA blocks are skipped; POINT_DATA or
// CELL_DATA ends the reading, as the rest only holds attributes.
#include <limits>
#include <map>

#include "io/io_internal.h"

namespace kdmesh::io::detail {
namespace {

// VTK cell types that map onto simplices or polygons.
enum CellType : int64_t {
  kVertex = 1,
  kPolyVertex = 2,
  kLine = 3,
  kPolyLine = 4,
  kTriangle = 5,
  kTriangleStrip = 6,
  kPolygon = 7,
  kPixel = 8,
  kQuad = 9,
  kTetra = 10,
};

// Tokens across lines, with one token of look-ahead.
class Tokens {
 public:
  explicit Tokens(TextScanner& scanner) : scanner_(scanner) {}

  bool next(std::string_view& token) {
    previousLine_ = line_;
    if (hasPending_) {
      hasPending_ = false;
      token = pending_;
      line_ = pendingLine_;
      return true;
    }
    if (!scanner_.nextTokenAcrossLines(token)) return false;
    line_ = scanner_.lineNumber();
    return true;
  }
  // Returns the token just read, so that the next call gives it again.
  void putBack(std::string_view token) {
    pending_ = token;
    pendingLine_ = line_;
    hasPending_ = true;
    line_ = previousLine_;
  }
  // Line of the last token returned.
  size_t line() const { return line_; }
  uint64_t remainingBytes() const { return scanner_.remainingBytes(); }

  // Skips to the first blank line: how a METADATA block ends.
  void skipToBlankLine() {
    hasPending_ = false;
    std::string_view token;
    while (scanner_.nextToken(token)) {
    }
    while (scanner_.nextLine() && scanner_.nextToken(token)) {
    }
  }

 private:
  TextScanner& scanner_;
  std::string_view pending_;
  bool hasPending_ = false;
  size_t pendingLine_ = 0;
  size_t line_ = 0;
  size_t previousLine_ = 0;
};

bool isDataType(std::string_view name) {
  for (std::string_view type :
       {"bit", "char", "unsigned_char", "short", "unsigned_short", "int",
        "unsigned_int", "long", "unsigned_long", "float", "double",
        "vtkIdType", "vtktypeint8", "vtktypeuint8", "vtktypeint16",
        "vtktypeuint16", "vtktypeint32", "vtktypeuint32", "vtktypeint64",
        "vtktypeuint64", "vtktypefloat32", "vtktypefloat64"}) {
    if (equalsIgnoringCase(name, type)) return true;
  }
  return false;
}

// Cells as offsets into one connectivity array, as VTK 5 stores them.
struct Cells {
  std::vector<uint64_t> offsets{0};  // cell c is [offsets[c], offsets[c + 1])
  std::vector<uint32_t> connectivity;

  uint64_t count() const { return offsets.size() - 1; }
};

// The first line, '# vtk DataFile Version x.x'.
Status readVtkSignature(TextScanner& scanner) {
  std::string_view token;
  bool ok = scanner.nextLine();
  for (std::string_view word : {"#", "vtk", "DataFile", "Version"}) {
    ok = ok && scanner.nextToken(token) && equalsIgnoringCase(token, word);
  }
  if (!ok) {
    return inputError(
        "not a legacy VTK file: the first line is not "
        "'# vtk DataFile Version x.x'");
  }
  return Status::success();
}

class VtkReader {
 public:
  VtkReader(const uint8_t* data, size_t size, Complex& out)
      : scanner_(data, size), tokens_(scanner_), out_(out) {}

  Status read(Notes& notes) {
    if (Status status = readPreamble(); !status.ok()) return status;
    std::string_view keyword;
    while (tokens_.next(keyword)) {
      Status status;
      if (equalsIgnoringCase(keyword, "DATASET")) {
        status = readDataset();
      } else if (equalsIgnoringCase(keyword, "FIELD")) {
        status = skipField();
      } else if (equalsIgnoringCase(keyword, "METADATA")) {
        tokens_.skipToBlankLine();
      } else if (equalsIgnoringCase(keyword, "POINT_DATA") ||
                 equalsIgnoringCase(keyword, "CELL_DATA")) {
        notes.push_back("ignored " + std::string(keyword) +
                        " and everything after it (from line " +
                        std::to_string(tokens_.line()) + ")");
        break;
      } else if (!dataset_) {
        status = error("expected DATASET, found " + quoted(keyword));
      } else if (equalsIgnoringCase(keyword, "POINTS")) {
        status = readPoints();
      } else if (!polyData_ && equalsIgnoringCase(keyword, "CELLS")) {
        status = readCellsSection();
      } else if (!polyData_ && equalsIgnoringCase(keyword, "CELL_TYPES")) {
        status = readCellTypes();
      } else if (polyData_ && polyDataType(keyword) != 0) {
        status = readPolyDataSection(keyword);
      } else {
        status = error("unknown or unsupported VTK keyword " +
                       quoted(keyword));
      }
      if (!status.ok()) return status;
    }
    if (!dataset_) return inputError("VTK file has no DATASET");
    if (!havePoints_) return inputError("VTK file has no POINTS");
    if (pendingCells_) {
      return inputError("VTK file has CELLS but no CELL_TYPES");
    }
    addNotes(notes);
    return Status::success();
  }

 private:
  Status error(const std::string& message) const {
    return lineError(tokens_.line(), message);
  }

  Status readPreamble() {
    if (Status status = readVtkSignature(scanner_); !status.ok()) return status;
    std::string_view token;
    if (!scanner_.nextLine() || !scanner_.nextContentLine()) {  // the title
      return inputError("VTK file ends before its ASCII or BINARY line");
    }
    scanner_.nextToken(token);  // nextContentLine() guaranteed one
    if (equalsIgnoringCase(token, "BINARY")) {
      return lineError(scanner_.lineNumber(), "binary VTK is not supported");
    }
    if (!equalsIgnoringCase(token, "ASCII")) {
      return lineError(scanner_.lineNumber(),
                       "expected ASCII or BINARY, found " + quoted(token));
    }
    return Status::success();
  }

  Status readDataset() {
    std::string_view type;
    if (!tokens_.next(type)) return error("the file ends after DATASET");
    if (dataset_) return error("a second DATASET");
    if (equalsIgnoringCase(type, "POLYDATA")) {
      polyData_ = true;
    } else if (!equalsIgnoringCase(type, "UNSTRUCTURED_GRID")) {
      return error("VTK dataset " + quoted(type) +
                   " is not supported (only UNSTRUCTURED_GRID and "
                   "POLYDATA)");
    }
    dataset_ = true;
    return Status::success();
  }

  Status readCount(const char* what, uint64_t& count) {
    std::string_view token;
    if (!tokens_.next(token)) {
      return error(std::string("the file ends before the ") + what);
    }
    if (!parseCount(token, count)) {
      return error(std::string(what) + " " + quoted(token) +
                   " is not a count");
    }
    return Status::success();
  }

  Status readDataType(const char* keyword, std::string_view& type) {
    if (!tokens_.next(type)) {
      return error(std::string("the file ends before the data type of ") +
                   keyword);
    }
    if (!isDataType(type)) {
      return error(std::string(keyword) + ": unknown data type " +
                   quoted(type));
    }
    return Status::success();
  }

  // Takes `count` values of at least two bytes each from what is left.
  Status checkBudget(const char* keyword, uint64_t count) {
    uint64_t budget = tokens_.remainingBytes() + 1;
    if (!takeFromBudget(count, 2, budget)) {
      return error(std::string(keyword) + " declares " +
                   std::to_string(count) +
                   " values, more than the rest of the file can hold");
    }
    return Status::success();
  }

  Status readPoints() {
    if (havePoints_) return error("a second POINTS section");
    uint64_t count = 0;
    std::string_view type;
    if (Status status = readCount("point count", count); !status.ok()) {
      return status;
    }
    if (Status status = readDataType("POINTS", type); !status.ok()) {
      return status;
    }
    if (count > std::numeric_limits<uint32_t>::max()) {
      return error("more points than 32-bit indices can address");
    }
    if (Status status = checkBudget("POINTS", 3 * count); !status.ok()) {
      return status;
    }
    doubleCoordinates_ = equalsIgnoringCase(type, "double") ||
                         equalsIgnoringCase(type, "vtktypefloat64");
    out_.positions.reserve(3 * count);
    for (uint64_t i = 0; i < 3 * count; ++i) {
      std::string_view token;
      float value;
      if (!tokens_.next(token)) {
        return error("the file ends inside point " + std::to_string(i / 3) +
                     " of " + std::to_string(count));
      }
      if (!parseFloat(token, value)) {
        return error("point " + std::to_string(i / 3) + ": " + quoted(token) +
                     " is not a number");
      }
      out_.positions.push_back(value);
    }
    havePoints_ = true;
    return Status::success();
  }

  Status readIndex(const char* keyword, uint64_t item, uint32_t& index) {
    std::string_view token;
    if (!tokens_.next(token)) {
      return error(std::string("the file ends inside ") + keyword);
    }
    int64_t value = 0;
    if (!parseInteger(token, value)) {
      return error(std::string(keyword) + " cell " + std::to_string(item) +
                   ": " + quoted(token) + " is not a point index");
    }
    if (value < 0 || static_cast<uint64_t>(value) >= out_.vertexCount()) {
      return error(std::string(keyword) + " cell " + std::to_string(item) +
                   ": point index " + std::to_string(value) +
                   " is out of range (" + std::to_string(out_.vertexCount()) +
                   " points)");
    }
    index = static_cast<uint32_t>(value);
    return Status::success();
  }

  // "count size" and the cells after a CELLS, VERTICES, LINES, POLYGONS or
  // TRIANGLE_STRIPS keyword, in either layout.
  Status readCellArray(const char* keyword, Cells& cells) {
    if (!havePoints_) {
      return error(std::string(keyword) + " come before POINTS");
    }
    uint64_t first = 0, second = 0;
    if (Status status = readCount("cell count", first); !status.ok()) {
      return status;
    }
    if (Status status = readCount("cell array size", second); !status.ok()) {
      return status;
    }
    cells = Cells{};
    std::string_view token;
    if (tokens_.next(token)) {
      if (equalsIgnoringCase(token, "OFFSETS")) {
        return readOffsetCells(keyword, first, second, cells);
      }
      tokens_.putBack(token);
    }
    return readClassicCells(keyword, first, second, cells);
  }

  Status readClassicCells(const char* keyword, uint64_t count, uint64_t size,
                          Cells& cells) {
    if (Status status = checkBudget(keyword, size); !status.ok()) {
      return status;
    }
    if (count > size) {
      return error(std::string(keyword) + " declares " +
                   std::to_string(count) + " cells in only " +
                   std::to_string(size) + " values");
    }
    cells.offsets.reserve(count + 1);
    cells.connectivity.reserve(size - count);
    uint64_t used = 0;
    for (uint64_t c = 0; c < count; ++c) {
      uint64_t points = 0;
      if (Status status = readCount("cell point count", points);
          !status.ok()) {
        return status;
      }
      if (points >= size - used) {
        return error(std::string(keyword) + " cell " + std::to_string(c) +
                     " has " + std::to_string(points) +
                     " points, more than the declared size leaves");
      }
      used += 1 + points;
      for (uint64_t k = 0; k < points; ++k) {
        uint32_t index;
        if (Status status = readIndex(keyword, c, index); !status.ok()) {
          return status;
        }
        cells.connectivity.push_back(index);
      }
      cells.offsets.push_back(cells.connectivity.size());
    }
    if (used != size) {
      return error(std::string(keyword) + " declares a size of " +
                   std::to_string(size) + " values, but its cells hold " +
                   std::to_string(used));
    }
    return Status::success();
  }

  Status readOffsetCells(const char* keyword, uint64_t offsetCount,
                         uint64_t size, Cells& cells) {
    std::string_view type, token;
    if (Status status = readDataType("OFFSETS", type); !status.ok()) {
      return status;
    }
    uint64_t budget = tokens_.remainingBytes() + 1;
    if (!takeFromBudget(offsetCount, 2, budget) ||
        !takeFromBudget(size, 2, budget)) {
      return error(std::string(keyword) + " declares " +
                   std::to_string(offsetCount) + " offsets and " +
                   std::to_string(size) +
                   " indices, more than the rest of the file can hold");
    }
    cells.offsets.clear();
    cells.offsets.reserve(offsetCount);
    for (uint64_t i = 0; i < offsetCount; ++i) {
      uint64_t offset = 0;
      if (Status status = readCount("offset", offset); !status.ok()) {
        return status;
      }
      const uint64_t previous = i == 0 ? 0 : cells.offsets.back();
      if ((i == 0 && offset != 0) || offset < previous || offset > size) {
        return error("OFFSETS value " + std::to_string(i) + " is " +
                     std::to_string(offset) +
                     ": offsets must start at 0 and grow up to " +
                     std::to_string(size));
      }
      cells.offsets.push_back(offset);
    }
    if (cells.offsets.empty()) cells.offsets.push_back(0);
    if (cells.offsets.back() != size) {
      return error("the last OFFSETS value is " +
                   std::to_string(cells.offsets.back()) + ", not " +
                   std::to_string(size));
    }
    if (!tokens_.next(token) || !equalsIgnoringCase(token, "CONNECTIVITY")) {
      return error("expected CONNECTIVITY after the OFFSETS of " +
                   std::string(keyword));
    }
    if (Status status = readDataType("CONNECTIVITY", type); !status.ok()) {
      return status;
    }
    cells.connectivity.reserve(size);
    uint64_t cell = 0;
    for (uint64_t i = 0; i < size; ++i) {
      while (cells.offsets[cell + 1] <= i) ++cell;  // skips empty cells
      uint32_t index;
      if (Status status = readIndex(keyword, cell, index); !status.ok()) {
        return status;
      }
      cells.connectivity.push_back(index);
    }
    return Status::success();
  }

  Status readCellsSection() {
    if (pendingCells_) return error("CELLS again before CELL_TYPES");
    if (Status status = readCellArray("CELLS", cells_); !status.ok()) {
      return status;
    }
    pendingCells_ = true;
    return Status::success();
  }

  Status readCellTypes() {
    uint64_t count = 0;
    if (Status status = readCount("cell type count", count); !status.ok()) {
      return status;
    }
    const uint64_t cellCount = pendingCells_ ? cells_.count() : 0;
    if (count != cellCount) {
      return error("CELL_TYPES lists " + std::to_string(count) +
                   " types for " + std::to_string(cellCount) + " CELLS");
    }
    pendingCells_ = false;
    for (uint64_t c = 0; c < count; ++c) {
      std::string_view token;
      int64_t type = 0;
      if (!tokens_.next(token)) {
        return error("the file ends after " + std::to_string(c) + " of " +
                     std::to_string(count) + " cell types");
      }
      if (!parseInteger(token, type)) {
        return error("cell " + std::to_string(c) + ": type " + quoted(token) +
                     " is not an integer");
      }
      if (Status status = addCell(type, cells_, c); !status.ok()) {
        return status;
      }
    }
    cells_ = Cells{};
    return Status::success();
  }

  static int64_t polyDataType(std::string_view keyword) {
    if (equalsIgnoringCase(keyword, "VERTICES")) return kPolyVertex;
    if (equalsIgnoringCase(keyword, "LINES")) return kPolyLine;
    if (equalsIgnoringCase(keyword, "POLYGONS")) return kPolygon;
    if (equalsIgnoringCase(keyword, "TRIANGLE_STRIPS")) return kTriangleStrip;
    return 0;
  }

  Status readPolyDataSection(std::string_view keyword) {
    const std::string name(keyword);
    Cells cells;
    if (Status status = readCellArray(name.c_str(), cells); !status.ok()) {
      return status;
    }
    for (uint64_t c = 0; c < cells.count(); ++c) {
      if (Status status = addCell(polyDataType(keyword), cells, c);
          !status.ok()) {
        return status;
      }
    }
    return Status::success();
  }

  Status addCell(int64_t type, const Cells& cells, uint64_t c) {
    const uint32_t* v = cells.connectivity.data() + cells.offsets[c];
    const size_t n =
        static_cast<size_t>(cells.offsets[c + 1] - cells.offsets[c]);
    size_t minimum = 0, maximum = 0;  // points the type allows
    switch (type) {
      case kVertex: minimum = maximum = 1; break;
      case kPolyVertex: minimum = 1; break;
      case kLine: minimum = maximum = 2; break;
      case kPolyLine: minimum = 2; break;
      case kTriangle: minimum = maximum = 3; break;
      case kTriangleStrip: case kPolygon: minimum = 3; break;
      case kPixel: case kQuad: case kTetra: minimum = maximum = 4; break;
      default:
        countSkipped(type);
        return Status::success();
    }
    if (n < minimum || (maximum != 0 && n > maximum)) {
      return error("cell " + std::to_string(c) + " of VTK type " +
                   std::to_string(type) + " has " + std::to_string(n) +
                   " points, needs " +
                   (maximum == minimum ? "exactly " : "at least ") +
                   std::to_string(minimum));
    }
    switch (type) {
      case kVertex: case kPolyVertex:
        out_.points.insert(out_.points.end(), v, v + n);
        break;
      case kLine: case kPolyLine:
        for (size_t i = 0; i + 1 < n; ++i) {
          out_.edges.insert(out_.edges.end(), {v[i], v[i + 1]});
        }
        break;
      case kTriangle:
        out_.triangles.insert(out_.triangles.end(), v, v + 3);
        break;
      case kTriangleStrip:  // every other triangle turned to keep orientation
        for (size_t i = 0; i + 2 < n; ++i) {
          const bool even = i % 2 == 0;
          out_.triangles.insert(out_.triangles.end(),
                                {even ? v[i] : v[i + 1], even ? v[i + 1] : v[i],
                                 v[i + 2]});
        }
        break;
      case kPixel: {  // corners in grid order: 0 1 3 2 around the square
        const uint32_t quad[4] = {v[0], v[1], v[3], v[2]};
        split_.append(quad, 4, out_.triangles);
        break;
      }
      case kPolygon: case kQuad:
        split_.append(v, n, out_.triangles);
        break;
      case kTetra:
        out_.tetrahedra.insert(out_.tetrahedra.end(), v, v + 4);
        break;
      default:
        break;
    }
    return Status::success();
  }

  // FIELD name arrays, then per array "name components tuples type" and its
  // values; NULL_ARRAY stands for an empty one.
  Status skipField() {
    std::string_view name, token;
    uint64_t arrays = 0;
    if (!tokens_.next(name)) return error("the file ends after FIELD");
    if (Status status = readCount("FIELD array count", arrays); !status.ok()) {
      return status;
    }
    for (uint64_t a = 0; a < arrays; ++a) {
      if (!tokens_.next(token)) return error("the file ends inside FIELD");
      if (equalsIgnoringCase(token, "METADATA")) {
        tokens_.skipToBlankLine();
        --a;
        continue;
      }
      if (token == "NULL_ARRAY") continue;
      uint64_t components = 0, tuples = 0;
      std::string_view type;
      if (Status status = readCount("FIELD component count", components);
          !status.ok()) {
        return status;
      }
      if (Status status = readCount("FIELD tuple count", tuples);
          !status.ok()) {
        return status;
      }
      if (!tokens_.next(type)) return error("the file ends inside FIELD");
      if (equalsIgnoringCase(type, "string")) {
        return error("FIELD arrays of strings are not supported");
      }
      if (!isDataType(type)) {
        return error("FIELD: unknown data type " + quoted(type));
      }
      const uint64_t limit = tokens_.remainingBytes() + 1;
      if (components != 0 && tuples > limit / components) {
        return error("FIELD array declares " + std::to_string(components) +
                     " x " + std::to_string(tuples) +
                     " values, more than the rest of the file can hold");
      }
      const uint64_t values = components * tuples;
      if (Status status = checkBudget("FIELD array", values); !status.ok()) {
        return status;
      }
      for (uint64_t i = 0; i < values; ++i) {
        if (!tokens_.next(token)) return error("the file ends inside FIELD");
      }
    }
    ++fields_;
    return Status::success();
  }

  // The note names a few skipped types; a file cannot make it (or the
  // map) grow with a new type in every cell.
  void countSkipped(int64_t type) {
    constexpr size_t kNamedTypes = 16;
    const auto named = skippedTypes_.find(type);
    if (named != skippedTypes_.end()) {
      ++named->second;
    } else if (skippedTypes_.size() < kNamedTypes) {
      skippedTypes_.emplace(type, 1);
    } else {
      ++skippedOthers_;
    }
  }

  void addNotes(Notes& notes) const {
    if (doubleCoordinates_) {
      notes.push_back("coordinates stored as double were rounded to float32");
    }
    split_.addNote(notes);
    if (!skippedTypes_.empty()) {
      size_t total = skippedOthers_;
      std::string types;
      for (const auto& [type, count] : skippedTypes_) {
        total += count;
        types += (types.empty() ? "" : ", ") + std::to_string(type) + " x" +
                 std::to_string(count);
      }
      if (skippedOthers_ > 0) {
        types += ", other types x" + std::to_string(skippedOthers_);
      }
      notes.push_back("skipped " + std::to_string(total) +
                      " cells that are neither simplices nor polygons (VTK "
                      "cell types " + types + ")");
    }
    addCountNote(notes, "ignored ", fields_, "FIELD data section", "FIELD data sections");
  }

  TextScanner scanner_;
  Tokens tokens_;
  Complex& out_;
  bool dataset_ = false;
  bool polyData_ = false;
  bool havePoints_ = false;
  bool pendingCells_ = false;  // CELLS read, CELL_TYPES not yet
  bool doubleCoordinates_ = false;
  Cells cells_;
  PolygonSplit split_;
  std::map<int64_t, size_t> skippedTypes_;  // at most 16 types named
  size_t skippedOthers_ = 0;                // cells of further types
  size_t fields_ = 0;
};

}  // namespace

Status checkVtkSignature(const uint8_t* head, size_t size) {
  TextScanner scanner(head, size);
  return readVtkSignature(scanner);
}

Status readVtk(const uint8_t* data, size_t size, Complex& out, Notes& notes) {
  return VtkReader(data, size, out).read(notes);
}

Status writeVtk(const Complex& complex, std::vector<uint8_t>& out) {
  TextOut text(out);
  text.word("# vtk DataFile Version 3.0").endLine();
  text.word("written by kdmesh").endLine();
  text.word("ASCII").endLine();
  text.word("DATASET UNSTRUCTURED_GRID").endLine();
  text.word("POINTS").integer(complex.vertexCount()).word("float").endLine();
  const std::vector<float>& positions = complex.positions;
  for (size_t i = 0; i < positions.size(); i += 3) {
    text.point(&positions[i]).endLine();
  }
  const struct {
    const std::vector<uint32_t>& indices;
    size_t arity;
    int type;
  } groups[] = {{complex.points, 1, kVertex},
                {complex.edges, 2, kLine},
                {complex.triangles, 3, kTriangle},
                {complex.tetrahedra, 4, kTetra}};
  uint64_t cells = 0, size = 0;
  for (const auto& group : groups) {
    const uint64_t count = group.indices.size() / group.arity;
    cells += count;
    size += count * (group.arity + 1);
  }
  text.word("CELLS").integer(cells).integer(size).endLine();
  for (const auto& group : groups) {
    for (size_t i = 0; i < group.indices.size(); i += group.arity) {
      text.integer(group.arity);
      for (size_t k = 0; k < group.arity; ++k) {
        text.integer(group.indices[i + k]);
      }
      text.endLine();
    }
  }
  text.word("CELL_TYPES").integer(cells).endLine();
  for (const auto& group : groups) {
    for (size_t i = 0; i < group.indices.size(); i += group.arity) {
      text.integer(static_cast<uint64_t>(group.type)).endLine();
    }
  }
  return Status::success();
}

}  // namespace kdmesh::io::detail
