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
// case-insensitive. METADATA blocks are skipped. After POINT_DATA n, the
// arrays of 1 to 4 components (SCALARS, COLOR_SCALARS, VECTORS, NORMALS,
// TEXTURE_COORDINATES, GLOBAL_IDS, PEDIGREE_IDS and FIELD arrays of n
// tuples) become vertex attributes. After CELL_DATA, the first integer
// array of one value per cell (SCALARS or FIELD; a region, material or
// entity id) labels the simplices each cell becomes (a vertex cell's
// points carry none); other cell arrays, TENSORS, lookup tables and FIELD
// data of the dataset are skipped and counted.
//
// The writer writes labels back as CELL_DATA SCALARS `label` int.
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

// The attribute type of a VTK data type: integers of up to 32 bits as
// themselves, float as float32; `rounded` for double (rounded to float32),
// `wide` for 64-bit integers (whose values choose a type).
AttributeType attributeTypeOf(std::string_view name, bool& rounded, bool& wide) {
  rounded = wide = false;
  const auto is = [name](std::initializer_list<std::string_view> names) {
    for (std::string_view n : names)
      if (equalsIgnoringCase(name, n)) return true;
    return false;
  };
  if (is({"bit", "unsigned_char", "vtktypeuint8"})) return AttributeType::UInt8;
  if (is({"char", "vtktypeint8"})) return AttributeType::Int8;
  if (is({"unsigned_short", "vtktypeuint16"})) return AttributeType::UInt16;
  if (is({"short", "vtktypeint16"})) return AttributeType::Int16;
  if (is({"unsigned_int", "vtktypeuint32"})) return AttributeType::UInt32;
  if (is({"int", "vtktypeint32"})) return AttributeType::Int32;
  if (is({"float", "vtktypefloat32"})) return AttributeType::Float32;
  if (is({"double", "vtktypefloat64"})) {
    rounded = true;
    return AttributeType::Float32;
  }
  wide = true;  // long, unsigned_long, vtkIdType, vtktype(u)int64
  return AttributeType::Int32;
}

const char* vtkTypeName(AttributeType type) {
  switch (type) {
    case AttributeType::UInt8: return "unsigned_char";
    case AttributeType::Int8: return "char";
    case AttributeType::UInt16: return "unsigned_short";
    case AttributeType::Int16: return "short";
    case AttributeType::UInt32: return "unsigned_int";
    case AttributeType::Int32: return "int";
    default: return "float";
  }
}

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
  VtkReader(const uint8_t* data, size_t size, Complex& out, bool keepDoubles)
      : scanner_(data, size), tokens_(scanner_), out_(out), keepDoubles_(keepDoubles) {}

  Status read(Notes& notes) {
    if (Status status = readPreamble(); !status.ok()) return status;
    std::string_view keyword;
    while (tokens_.next(keyword)) {
      Status status;
      if (equalsIgnoringCase(keyword, "DATASET")) {
        status = readDataset();
      } else if (equalsIgnoringCase(keyword, "FIELD")) {
        status = readField();
      } else if (equalsIgnoringCase(keyword, "METADATA")) {
        tokens_.skipToBlankLine();
      } else if (equalsIgnoringCase(keyword, "POINT_DATA") ||
                 equalsIgnoringCase(keyword, "CELL_DATA")) {
        status = startData(keyword);
      } else if (data_ != Data::None && isDataSection(keyword)) {
        status = readDataSection(keyword);
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
    settleDoubles(out_, beyondFloat_, keepDoubles_, notes);
    addNotes(notes);
    return Status::success();
  }

 private:
  Status error(const std::string& message) const {
    return lineError(tokens_.line(), message);
  }

  // The simplices a cell became: `count` of dimension 1..3 from index
  // `first` of their list, or none (dimension 0; a vertex cell's points).
  struct CellSpan {
    uint8_t dimension;
    uint32_t first, count;
  };

  // Where the arrays being read belong: the dataset (FIELD before
  // POINT_DATA), its points or its cells.
  enum class Data { None, Points, Cells };

  Status startData(std::string_view keyword) {
    const bool points = equalsIgnoringCase(keyword, "POINT_DATA");
    uint64_t count = 0;
    if (Status status = readCount(points ? "POINT_DATA count" : "CELL_DATA count", count); !status.ok())
      return status;
    if (points) {
      if (!havePoints_) return error("POINT_DATA comes before POINTS");
      if (count != out_.vertexCount())
        return error("POINT_DATA gives values for " + counted(count, "point", "points") + ", the file has " +
                     std::to_string(out_.vertexCount()));
    }
    data_ = points ? Data::Points : Data::Cells;
    tuples_ = count;
    return Status::success();
  }

  static bool isDataSection(std::string_view keyword) {
    for (std::string_view k : {"SCALARS", "COLOR_SCALARS", "VECTORS", "NORMALS", "TEXTURE_COORDINATES", "TENSORS",
                               "LOOKUP_TABLE", "GLOBAL_IDS", "PEDIGREE_IDS"})
      if (equalsIgnoringCase(keyword, k)) return true;
    return false;
  }

  // The token after a section's keyword that names its array.
  Status readName(std::string_view keyword, std::string_view& name) {
    if (!tokens_.next(name)) return error("the file ends after " + std::string(keyword));
    return Status::success();
  }

  // One array of a POINT_DATA or CELL_DATA section, up to its values.
  Status readDataSection(std::string_view keyword) {
    std::string_view name, type = "float";
    uint64_t components = 1, tuples = tuples_;
    std::string attributeName;
    bool colour = false;
    if (Status status = readName(keyword, name); !status.ok()) return status;
    const std::string what(keyword);
    if (equalsIgnoringCase(keyword, "SCALARS")) {
      if (Status status = readDataType("SCALARS", type); !status.ok()) return status;
      // The optional component count ends the SCALARS line.
      const size_t line = tokens_.line();
      std::string_view token;
      if (tokens_.next(token)) {
        if (tokens_.line() != line || !parseCount(token, components)) tokens_.putBack(token), components = 1;
      }
      if (tokens_.next(token)) {  // the lookup table, optional in practice
        if (equalsIgnoringCase(token, "LOOKUP_TABLE")) {
          if (!tokens_.next(token)) return error("the file ends after LOOKUP_TABLE");
        } else {
          tokens_.putBack(token);
        }
      }
    } else if (equalsIgnoringCase(keyword, "COLOR_SCALARS")) {
      if (Status status = readCount("COLOR_SCALARS component count", components); !status.ok()) return status;
      colour = true;
      attributeName = "color";
    } else if (equalsIgnoringCase(keyword, "VECTORS") || equalsIgnoringCase(keyword, "NORMALS")) {
      if (Status status = readDataType(what.c_str(), type); !status.ok()) return status;
      components = 3;
      if (equalsIgnoringCase(keyword, "NORMALS")) attributeName = "normal";
    } else if (equalsIgnoringCase(keyword, "TEXTURE_COORDINATES")) {
      if (Status status = readCount("TEXTURE_COORDINATES dimension", components); !status.ok()) return status;
      if (Status status = readDataType(what.c_str(), type); !status.ok()) return status;
      attributeName = "uv";
    } else if (equalsIgnoringCase(keyword, "TENSORS")) {
      if (Status status = readDataType(what.c_str(), type); !status.ok()) return status;
      components = 9;
    } else if (equalsIgnoringCase(keyword, "LOOKUP_TABLE")) {  // its own section: RGBA entries
      if (Status status = readCount("LOOKUP_TABLE size", tuples); !status.ok()) return status;
      components = 4;
    } else {  // GLOBAL_IDS, PEDIGREE_IDS
      if (Status status = readDataType(what.c_str(), type); !status.ok()) return status;
    }
    if (attributeName.empty()) attributeName = std::string(name);
    if (equalsIgnoringCase(keyword, "SCALARS") && takesLabels(type, components, tuples))
      return readCellLabels(what, std::string(name), tuples);
    const bool keep = data_ == Data::Points && !equalsIgnoringCase(keyword, "LOOKUP_TABLE") &&
                      !equalsIgnoringCase(keyword, "TENSORS");
    return readArray(what, keep ? attributeName : std::string(), type, components, tuples, colour);
  }

  // FIELD name arrays, then per array "name components tuples type" and its
  // values; NULL_ARRAY stands for an empty one. In POINT_DATA, arrays of
  // one value per point become attributes.
  Status readField() {
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
      const std::string arrayName(token);
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
      if (takesLabels(type, components, tuples)) {
        if (Status status = readCellLabels("FIELD array", arrayName, tuples); !status.ok()) return status;
        continue;
      }
      const bool keep = data_ == Data::Points && tuples == tuples_;
      if (Status status = readArray("FIELD array", keep ? arrayName : std::string(), type, components, tuples, false);
          !status.ok())
        return status;
    }
    if (data_ == Data::None) ++fields_;
    return Status::success();
  }

  // The values of an array of `tuples` x `components`: kept as the
  // attribute `name` when it is not empty and the attribute can be one,
  // else skipped and counted. COLOR_SCALARS (`colour`) hold values in
  // 0..1 that VTK stores as bytes: kept as uint8, 255 x value rounded.
  Status readArray(const std::string& keyword, std::string name, std::string_view typeName, uint64_t components,
                   uint64_t tuples, bool colour) {
    const uint64_t limit = tokens_.remainingBytes() + 1;
    if (components != 0 && tuples > limit / components) {
      return error(keyword + " declares " + std::to_string(components) + " x " + std::to_string(tuples) +
                   " values, more than the rest of the file can hold");
    }
    const uint64_t count = components * tuples;
    if (Status status = checkBudget(keyword.c_str(), count); !status.ok()) return status;
    bool rounded = false, wide = false;
    const AttributeType type = colour ? AttributeType::UInt8 : attributeTypeOf(typeName, rounded, wide);
    if (!name.empty() && !attributeFits(name, components)) name.clear();
    if (name.empty()) {
      if (data_ != Data::None) ++skippedArrays_;  // the dataset's FIELD data is noted as a whole
      std::string_view token;
      for (uint64_t i = 0; i < count; ++i)
        if (!tokens_.next(token)) return error("the file ends inside " + keyword);
      return Status::success();
    }
    VertexAttribute a{name, type, uint8_t(components), {}, {}};
    std::vector<int64_t> integers;  // 64-bit values, typed when all are read
    a.values.resize(wide ? 0 : size_t(count) * attributeTypeBytes(type));
    std::string_view token;
    for (uint64_t i = 0; i < count; ++i) {
      if (!tokens_.next(token)) return error("the file ends inside " + keyword + " " + quoted(name));
      bool ok;
      if (colour) {
        float value;
        ok = parseFloat(token, value) && value >= 0 && value <= 1;
        if (ok) a.values[size_t(i)] = uint8_t(value * 255.f + 0.5f);
      } else if (wide) {
        int64_t value;
        ok = parseInteger(token, value);
        integers.push_back(value);
      } else {
        ok = parseAttributeValue(token, type, &a.values[size_t(i) * attributeTypeBytes(type)]);
      }
      if (!ok)
        return error(keyword + " " + quoted(name) + " value " + std::to_string(i) + ": " + quoted(token) +
                     (colour ? " is not a number from 0 to 1" : " is not a " + std::string(typeName) + " value"));
    }
    if (wide) {
      AttributeType narrow;
      if (!narrowestIntegerType(integers, narrow)) {
        ++skippedArrays_;
        return Status::success();
      }
      a.type = narrow;  // the bytes of the values in order, whatever the components
      a.values = integerAttribute(name, narrow, integers).values;
    }
    roundedArrays_ += rounded;
    out_.attributes.push_back(std::move(a));
    return Status::success();
  }

  // Whether a cell data array (SCALARS or FIELD) becomes the simplex
  // labels: the first one of one integer per cell.
  bool takesLabels(std::string_view typeName, uint64_t components, uint64_t tuples) const {
    bool rounded, wide;
    return data_ == Data::Cells && labelArray_.empty() && components == 1 &&
           tuples == tuples_ && tuples_ == cellCount() &&
           attributeTypeOf(typeName, rounded, wide) != AttributeType::Float32 && !rounded;
  }

  uint64_t cellCount() const {
    uint64_t count = 0;
    for (const std::vector<CellSpan>& section : cellSpans_) count += section.size();
    return count;
  }

  // The values of a cell array taken as labels: each cell's value labels
  // its simplices. An array with a value beyond int32 is skipped (counted).
  Status readCellLabels(const std::string& keyword, const std::string& name, uint64_t tuples) {
    if (Status status = checkBudget(keyword.c_str(), tuples); !status.ok()) return status;
    std::vector<int32_t> values(size_t(tuples), 0);
    bool fits = true;
    std::string_view token;
    for (uint64_t c = 0; c < tuples; ++c) {
      if (!tokens_.next(token)) return error("the file ends inside " + keyword + " " + quoted(name));
      int64_t value;
      if (!parseInteger(token, value))
        return error(keyword + " " + quoted(name) + " value " + std::to_string(c) + ": " + quoted(token) +
                     " is not an integer");
      fits = fits && value >= INT32_MIN && value <= INT32_MAX;
      values[size_t(c)] = int32_t(fits ? value : 0);
    }
    if (!fits) {
      ++skippedArrays_;
      return Status::success();
    }
    for (int d = 1; d <= 3; ++d) {
      const size_t arity = size_t(d) + 1;
      out_.labels.of(d).assign((d == 1 ? out_.edges : d == 2 ? out_.triangles : out_.tetrahedra).size() / arity, 0);
    }
    // Cells are numbered in VTK's order: POLYDATA's vertices, lines,
    // polygons, then strips, whatever the order of their sections.
    size_t c = 0;
    for (const std::vector<CellSpan>& section : cellSpans_)
      for (const CellSpan& span : section) {
        if (span.dimension > 0) {
          std::vector<int32_t>& labels = out_.labels.of(span.dimension);
          std::fill(labels.begin() + span.first, labels.begin() + span.first + span.count, values[c]);
        }
        ++c;
      }
    labelArray_ = name;
    return Status::success();
  }

  // Whether an array can become an attribute: 1 to 4 components, a name of
  // printable ASCII no other attribute has, room for one more.
  bool attributeFits(const std::string& name, uint64_t components) const {
    if (components < 1 || components > 4 || name.size() > kMaxAttributeNameBytes ||
        out_.attributes.size() == kMaxAttributes)
      return false;
    for (const char c : name)
      if (c < 0x20 || c > 0x7e) return false;
    for (const VertexAttribute& a : out_.attributes)
      if (a.name == name) return false;
    return true;
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
    out_.positions.reserve(3 * count);
    for (uint64_t i = 0; i < 3 * count; ++i) {
      std::string_view token;
      float value;
      if (!tokens_.next(token)) {
        return error("the file ends inside point " + std::to_string(i / 3) +
                     " of " + std::to_string(count));
      }
      if (!parseCoordinate(token, value, keepDoubles_ ? &out_.positions64 : nullptr, &beyondFloat_)) {
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
      if (Status status = addCell(type, cells_, c, cellSpans_[0]); !status.ok()) {
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
    const int64_t type = polyDataType(keyword);
    std::vector<CellSpan>& spans =
        cellSpans_[type == kPolyVertex ? 0 : type == kPolyLine ? 1 : type == kPolygon ? 2 : 3];
    for (uint64_t c = 0; c < cells.count(); ++c) {
      if (Status status = addCell(type, cells, c, spans); !status.ok()) {
        return status;
      }
    }
    return Status::success();
  }

  // Adds the simplices of cell c, and where they went to `spans`.
  Status addCell(int64_t type, const Cells& cells, uint64_t c, std::vector<CellSpan>& spans) {
    const size_t sizes[4] = {0, out_.edges.size() / 2, out_.triangles.size() / 3, out_.tetrahedra.size() / 4};
    Status status = addCellSimplices(type, cells, c);
    if (!status.ok()) return status;
    const size_t grown[4] = {0, out_.edges.size() / 2 - sizes[1], out_.triangles.size() / 3 - sizes[2],
                             out_.tetrahedra.size() / 4 - sizes[3]};
    CellSpan span{0, 0, 0};
    for (uint8_t d = 1; d <= 3; ++d)
      if (grown[d] > 0) span = {d, uint32_t(sizes[d]), uint32_t(grown[d])};
    spans.push_back(span);
    return Status::success();
  }

  Status addCellSimplices(int64_t type, const Cells& cells, uint64_t c) {
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
      notes.push_back("skipped " + counted(total, "cell that is", "cells that are") +
                      " neither simplices nor polygons (VTK "
                      "cell types " + types + ")");
    }
    addCountNote(notes, "ignored ", fields_, "FIELD data section", "FIELD data sections", " of the dataset");
    if (!labelArray_.empty())
      notes.push_back("kept the cell data array " + quoted(labelArray_) + " as simplex labels");
    addCountNote(notes, "ignored ", skippedArrays_, "data array", "data arrays",
                 " (cell data other than one integer label per cell, tensors, lookup tables, arrays of more than 4 "
                 "components or of 64-bit values beyond 32 bits, repeated names, or past 15 attributes)");
    addCountNote(notes, "rounded the values of ", roundedArrays_, "double array", "double arrays", " to float32");
  }

  TextScanner scanner_;
  Tokens tokens_;
  Complex& out_;
  bool dataset_ = false;
  bool polyData_ = false;
  bool havePoints_ = false;
  bool pendingCells_ = false;  // CELLS read, CELL_TYPES not yet
  // Coordinates are read as decimals: a double array of float32 values
  // stays float32, and `keepDoubles_` keeps any with more digits.
  const bool keepDoubles_;
  bool beyondFloat_ = false;
  Cells cells_;
  // Where each cell's simplices went, by section in VTK's cell order
  // (POLYDATA: vertices, lines, polygons, strips; a grid uses the first).
  std::vector<CellSpan> cellSpans_[4];
  std::string labelArray_;  // the cell data array taken as labels
  PolygonSplit split_;
  std::map<int64_t, size_t> skippedTypes_;  // at most 16 types named
  size_t skippedOthers_ = 0;                // cells of further types
  size_t fields_ = 0;
  Data data_ = Data::None;
  uint64_t tuples_ = 0;          // of the current POINT_DATA or CELL_DATA
  size_t skippedArrays_ = 0;
  size_t roundedArrays_ = 0;
};

}  // namespace

Status checkVtkSignature(const uint8_t* head, size_t size) {
  TextScanner scanner(head, size);
  return readVtkSignature(scanner);
}

Status readVtk(const uint8_t* data, size_t size, Complex& out, Notes& notes, bool keepDoubles) {
  return VtkReader(data, size, out, keepDoubles).read(notes);
}

bool vtkHoldsAttribute(const VertexAttribute& a) {
  // A VTK array name is one token.
  for (const char c : a.name)
    if (c == ' ') return false;
  return true;
}

Status writeVtk(const Complex& complex, std::vector<uint8_t>& out) {
  TextOut text(out);
  text.word("# vtk DataFile Version 3.0").endLine();
  text.word("written by kdmesh").endLine();
  text.word("ASCII").endLine();
  text.word("DATASET UNSTRUCTURED_GRID").endLine();
  text.word("POINTS").integer(complex.vertexCount()).word(complex.positions64.empty() ? "float" : "double").endLine();
  for (size_t v = 0; v < complex.vertexCount(); ++v) text.point(complex, v).endLine();
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
  if (!complex.labels.empty()) {
    // One label per cell: a vertex cell's 0, each simplex its own.
    text.word("CELL_DATA").integer(cells).endLine();
    text.word("SCALARS label int 1").endLine();
    text.word("LOOKUP_TABLE default").endLine();
    for (size_t i = 0; i < complex.points.size(); ++i) text.word("0").endLine();
    for (int d = 1; d <= 3; ++d) {
      const std::vector<int32_t>& labels = complex.labels.of(d);
      const size_t count = groups[d].indices.size() / groups[d].arity;
      for (size_t i = 0; i < count; ++i) text.word(std::to_string(i < labels.size() ? labels[i] : 0)).endLine();
    }
  }
  if (complex.attributes.empty()) return Status::success();
  // The attributes as the reader takes them back: normal, uv and color
  // (uint8, as COLOR_SCALARS in 0..1) under their own keywords, the others
  // as SCALARS of their type.
  text.word("POINT_DATA").integer(complex.vertexCount()).endLine();
  for (const VertexAttribute& a : complex.attributes) {
    const bool colour = a.name == "color" && a.type == AttributeType::UInt8;
    const bool floats = a.type == AttributeType::Float32;
    if (colour) {
      text.word("COLOR_SCALARS").word(a.name).integer(a.components).endLine();
    } else if (a.name == "normal" && floats && a.components == 3) {
      text.word("NORMALS").word(a.name).word("float").endLine();
    } else if (a.name == "uv" && floats && a.components <= 3) {
      text.word("TEXTURE_COORDINATES").word(a.name).integer(a.components).word("float").endLine();
    } else {
      text.word("SCALARS").word(a.name).word(vtkTypeName(a.type)).integer(a.components).endLine();
      text.word("LOOKUP_TABLE default").endLine();
    }
    const size_t bytes = attributeTypeBytes(a.type);
    for (size_t v = 0; v < complex.vertexCount(); ++v) {
      for (size_t k = 0; k < a.components; ++k) {
        const uint8_t* value = &a.values[(v * a.components + k) * bytes];
        if (colour) {
          text.real(float(*value) / 255.f);
        } else {
          text.value(a.type, value);
        }
      }
      text.endLine();
    }
  }
  return Status::success();
}

}  // namespace kdmesh::io::detail
