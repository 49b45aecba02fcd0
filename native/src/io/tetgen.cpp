// TetGen .node and .ele files ('#' comments anywhere):
//
//   x.node: <points> <dimension = 3> [<attributes> [<boundary markers 0|1>]]
//           then per point: <number> <x> <y> <z> [attributes] [marker]
//   x.ele:  <tetrahedra> <nodes per tetrahedron 4|10> [<region attributes>]
//           then per tetrahedron: <number> <node> x 4 or 10 [attributes]
//
// Point numbers start at 0 or 1 (the first point decides) and go up by one;
// the .ele file uses the same numbering. A 10-node tetrahedron lists its 4
// corners first; the other 6 nodes are mid-edge points and stay vertices
// without simplices. Node order is kept as is, so the orientation survives.
#include <algorithm>
#include <cmath>
#include <limits>

#include "io/io_internal.h"

namespace kdmesh::io::detail {
namespace {

// The header counts of either file: the first is a count, the others small
// numbers, some optional.
Status readHeader(TextScanner& scanner, const char* file, size_t required,
                  uint64_t* values, size_t valueCount) {
  if (!scanner.nextContentLine()) {
    return inputError(std::string("TetGen ") + file + " file has no header");
  }
  std::string_view token;
  for (size_t i = 0; i < valueCount; ++i) values[i] = 0;
  for (size_t i = 0; i < valueCount; ++i) {
    if (!scanner.nextToken(token)) {
      if (i < required) {
        return lineError(scanner.lineNumber(),
                         std::string("TetGen ") + file + " header has " +
                             std::to_string(i) + " numbers, needs at least " +
                             std::to_string(required));
      }
      break;
    }
    if (!parseCount(token, values[i])) {
      return lineError(scanner.lineNumber(),
                       std::string("TetGen ") + file + " header: " +
                           quoted(token) + " is not a count");
    }
  }
  return Status::success();
}

// The name the reader gives the float32 attribute that holds .node point
// attribute columns `first` on, when the file has `total` of them.
std::string pointAttributeName(uint64_t first, uint64_t total) {
  return total <= 4 ? "attribute" : "attribute_" + std::to_string(first);
}

// Reads the number that starts an item line and checks that it continues
// the numbering; the first item sets the base (0 or 1).
Status readItemNumber(TextScanner& scanner, const char* what, uint64_t item,
                      int64_t& base) {
  std::string_view token;
  scanner.nextToken(token);  // nextContentLine() guaranteed one
  int64_t number = 0;
  if (!parseInteger(token, number)) {
    return lineError(scanner.lineNumber(), std::string(what) + " " +
                                               std::to_string(item) + ": " +
                                               quoted(token) +
                                               " is not a number");
  }
  if (item == 0) {
    if (number != 0 && number != 1) {
      return lineError(scanner.lineNumber(),
                       std::string("the first ") + what + " is numbered " +
                           std::to_string(number) + ", not 0 or 1");
    }
    base = number;
  } else if (number != base + static_cast<int64_t>(item)) {
    return lineError(scanner.lineNumber(),
                     std::string(what) + " " + std::to_string(item) +
                         " is numbered " + std::to_string(number) +
                         ", expected " +
                         std::to_string(base + static_cast<int64_t>(item)));
  }
  return Status::success();
}

// Counts the tokens left on the line: `expected` must be there (not parsed:
// attributes and markers are ignored), more are counted as extra.
Status skipColumns(TextScanner& scanner, const char* what, uint64_t item,
                   uint64_t expected, size_t& extraLines) {
  std::string_view token;
  uint64_t found = 0;
  while (found < expected && scanner.nextToken(token)) ++found;
  if (found < expected) {
    return lineError(scanner.lineNumber(),
                     std::string(what) + " " + std::to_string(item) +
                         " lacks " + std::to_string(expected - found) +
                         " of the attribute or marker values the header "
                         "declares");
  }
  extraLines += scanner.nextToken(token);
  return Status::success();
}

void noteTrailingLines(TextScanner& scanner, const char* file, uint64_t count,
                       const char* one, const char* many, Notes& notes) {
  size_t extraLines = 0, firstExtraLine = 0;
  while (scanner.nextContentLine()) {
    if (extraLines++ == 0) firstExtraLine = scanner.lineNumber();
  }
  if (extraLines > 0) {
    notes.push_back("ignored " + counted(extraLines, "line", "lines") + " of the " +
                    file + " file after the " + counted(count, one, many) +
                    " that its header declares (the first: line " +
                    std::to_string(firstExtraLine) + ")");
  }
}

Status endsEarly(const TextScanner& scanner, uint64_t read, uint64_t expected,
                 const char* one, const char* many) {
  return lineError(scanner.lineNumber(),
                   "the file ends after " + std::to_string(read) + " of " +
                       counted(expected, one, many));
}

}  // namespace

Status readTetgenNode(const uint8_t* data, size_t size, Complex& out,
                      Notes& notes, uint32_t& firstIndex, bool keepDoubles) {
  TextScanner scanner(data, size, {/*commaSeparates=*/false,
                                   /*hashComments=*/true});
  uint64_t header[4];  // points, dimension, attributes, markers
  if (Status status = readHeader(scanner, ".node", 2, header, 4);
      !status.ok()) {
    return status;
  }
  const uint64_t count = header[0], attributes = header[2],
                 markers = header[3];
  const size_t headerLine = scanner.lineNumber();
  if (header[1] != 3) {
    return lineError(headerLine, "TetGen .node dimension is " +
                                     std::to_string(header[1]) +
                                     "; only 3 is supported");
  }
  if (markers > 1) {
    return lineError(headerLine, "TetGen .node boundary marker count is " +
                                     std::to_string(markers) +
                                     ", not 0 or 1");
  }
  if (count > std::numeric_limits<uint32_t>::max()) {
    return lineError(headerLine,
                     "more points than 32-bit indices can address");
  }
  // A point line holds 4 + attributes + markers values of at least a digit
  // and a separator each.
  uint64_t budget = scanner.remainingBytes() + 1;
  if (attributes > budget / 2 ||
      !takeFromBudget(count, 2 * (4 + attributes + markers), budget)) {
    return lineError(headerLine,
                     "TetGen .node header declares " + std::to_string(count) +
                         " points with " + std::to_string(attributes) +
                         " attributes, more than the rest of the file can "
                         "hold");
  }
  out.positions.reserve(3 * count);
  // The point attributes in attributes of up to 4 components, as many as
  // a stream holds; the markers, typed once all are read.
  const uint64_t kept = std::min<uint64_t>(attributes, 4 * (kMaxAttributes - 1));
  std::vector<VertexAttribute> pointAttributes;
  for (uint64_t first = 0; first < kept; first += 4) {
    VertexAttribute a{pointAttributeName(first, kept), AttributeType::Float32,
                      uint8_t(std::min<uint64_t>(4, kept - first)), {}, {}};
    a.values.reserve(count * a.valueBytes());
    pointAttributes.push_back(std::move(a));
  }
  std::vector<int64_t> markerValues;
  markerValues.reserve(markers ? count : 0);
  int64_t base = 0;
  size_t extraLines = 0;
  bool beyondFloat = false;
  for (uint64_t p = 0; p < count; ++p) {
    if (!scanner.nextContentLine()) {
      return endsEarly(scanner, p, count, "point", "points");
    }
    if (Status status = readItemNumber(scanner, "point", p, base);
        !status.ok()) {
      return status;
    }
    for (int axis = 0; axis < 3; ++axis) {
      std::string_view token;
      float value = 0;
      if (!scanner.nextToken(token)) {
        return lineError(scanner.lineNumber(),
                         "point " + std::to_string(p) + " has " +
                             std::to_string(axis) + " coordinates, needs 3");
      }
      if (!parseCoordinate(token, value, keepDoubles ? &out.positions64 : nullptr, &beyondFloat)) {
        return lineError(scanner.lineNumber(), "point " + std::to_string(p) +
                                                   ": " + quoted(token) +
                                                   " is not a number");
      }
      out.positions.push_back(value);
    }
    for (uint64_t i = 0; i < attributes + markers; ++i) {
      std::string_view token;
      if (!scanner.nextToken(token)) {
        return lineError(scanner.lineNumber(),
                         "point " + std::to_string(p) + " lacks " +
                             std::to_string(attributes + markers - i) +
                             " of the attribute or marker values the header declares");
      }
      bool ok = true;
      if (i >= attributes) {
        int64_t marker;
        ok = parseInteger(token, marker);
        markerValues.push_back(marker);
      } else if (i < kept) {
        float value;
        ok = parseFloat(token, value);
        std::vector<uint8_t>& values = pointAttributes[size_t(i / 4)].values;
        const auto* bytes = reinterpret_cast<const uint8_t*>(&value);
        values.insert(values.end(), bytes, bytes + 4);
      }
      if (!ok) {
        return lineError(scanner.lineNumber(),
                         "point " + std::to_string(p) + ": " + quoted(token) + " is not " +
                             (i >= attributes ? "an integer boundary marker" : "a number"));
      }
    }
    std::string_view token;
    extraLines += scanner.nextToken(token);
  }
  firstIndex = static_cast<uint32_t>(base);
  settleDoubles(out, beyondFloat, keepDoubles, notes);
  noteTrailingLines(scanner, ".node", count, "point", "points", notes);
  for (VertexAttribute& a : pointAttributes) out.attributes.push_back(std::move(a));
  if (markers) {
    AttributeType type;
    if (!narrowestIntegerType(markerValues, type))
      return inputError("TetGen .node boundary markers beyond the 32-bit range");
    out.attributes.push_back(integerAttribute("marker", type, markerValues));
  }
  if (kept < attributes) {
    notes.push_back("ignored " + std::to_string(attributes - kept) + " of the " + std::to_string(attributes) +
                    " attributes of every .node point (a stream holds " + std::to_string(kMaxAttributes) +
                    " attributes)");
  }
  addCountNote(notes, "ignored extra values on ", extraLines,
               ".node point line", ".node point lines");
  return Status::success();
}

Status readTetgenEle(const uint8_t* data, size_t size, uint32_t firstIndex,
                     Complex& out, Notes& notes) {
  TextScanner scanner(data, size, {/*commaSeparates=*/false,
                                   /*hashComments=*/true});
  uint64_t header[3];  // tetrahedra, nodes per tetrahedron, attributes
  if (Status status = readHeader(scanner, ".ele", 2, header, 3);
      !status.ok()) {
    return status;
  }
  const uint64_t count = header[0], nodes = header[1], attributes = header[2];
  const size_t headerLine = scanner.lineNumber();
  if (nodes != 4 && nodes != 10) {
    return lineError(headerLine, "TetGen .ele has " + std::to_string(nodes) +
                                     " nodes per tetrahedron, not 4 or 10");
  }
  uint64_t budget = scanner.remainingBytes() + 1;
  if (attributes > budget / 2 ||
      !takeFromBudget(count, 2 * (1 + nodes + attributes), budget)) {
    return lineError(headerLine,
                     "TetGen .ele header declares " + std::to_string(count) +
                         " tetrahedra, more than the rest of the file can "
                         "hold");
  }
  out.tetrahedra.reserve(out.tetrahedra.size() + 4 * count);
  const uint64_t vertexCount = out.vertexCount();
  int64_t base = 0;
  size_t extraLines = 0;
  for (uint64_t t = 0; t < count; ++t) {
    if (!scanner.nextContentLine()) {
      return endsEarly(scanner, t, count, "tetrahedron", "tetrahedra");
    }
    if (Status status = readItemNumber(scanner, "tetrahedron", t, base);
        !status.ok()) {
      return status;
    }
    uint32_t corners[4];
    for (uint64_t k = 0; k < nodes; ++k) {
      std::string_view token;
      if (!scanner.nextToken(token)) {
        return lineError(scanner.lineNumber(),
                         "tetrahedron " + std::to_string(t) + " has " +
                             std::to_string(k) + " nodes, the header says " +
                             std::to_string(nodes));
      }
      int64_t value = 0;
      if (!parseInteger(token, value)) {
        return lineError(scanner.lineNumber(),
                         "tetrahedron " + std::to_string(t) + ": " +
                             quoted(token) + " is not a point number");
      }
      const int64_t index = value - static_cast<int64_t>(firstIndex);
      if (index < 0 || static_cast<uint64_t>(index) >= vertexCount) {
        return lineError(
            scanner.lineNumber(),
            "tetrahedron " + std::to_string(t) + ": point " +
                std::to_string(value) + " is out of range (" +
                std::to_string(firstIndex) + " to " +
                std::to_string(int64_t{firstIndex} +
                               static_cast<int64_t>(vertexCount) - 1) +
                ")");
      }
      if (k < 4) corners[k] = static_cast<uint32_t>(index);
    }
    // The first region attribute is the tetrahedron's label (TetGen writes
    // the integer region numbers of -A as reals).
    if (attributes > 0) {
      std::string_view token;
      int64_t region = 0;
      float real = 0;
      const bool read = scanner.nextToken(token);
      if (read && !parseInteger(token, region) && parseFloat(token, real) && real == std::floor(real) &&
          std::fabs(real) <= 16777216.f) {
        region = int64_t(real);  // an integer that float32 holds exactly
      } else if (read && !parseInteger(token, region)) {
        region = int64_t(1) << 40;  // refused below
      }
      if (read && region >= std::numeric_limits<int32_t>::min() && region <= std::numeric_limits<int32_t>::max()) {
        out.labels.tetrahedra.push_back(int32_t(region));
      } else {
        return lineError(scanner.lineNumber(), "tetrahedron " + std::to_string(t) + ": region attribute " +
                                                   quoted(token) + " is not an integer");
      }
    }
    if (Status status = skipColumns(scanner, "tetrahedron", t, attributes > 0 ? attributes - 1 : 0, extraLines);
        !status.ok()) {
      return status;
    }
    out.tetrahedra.insert(out.tetrahedra.end(), corners, corners + 4);
  }
  noteTrailingLines(scanner, ".ele", count, "tetrahedron", "tetrahedra", notes);
  if (nodes == 10 && count > 0) {
    notes.push_back("kept the 4 corners of " + std::to_string(count) +
                    " 10-node tetrahedra; their mid-edge nodes are vertices "
                    "without simplices");
  }
  if (attributes > 1) {
    notes.push_back("kept the first region attribute of every tetrahedron as its label, ignored the other " +
                    std::to_string(attributes - 1));
  }
  addCountNote(notes, "ignored extra values on ", extraLines,
               ".ele tetrahedron line", ".ele tetrahedron lines");
  return Status::success();
}

namespace {

// The attributes of `complex` that hold its .node point attribute columns,
// in column order: `attribute` alone, or `attribute_0`, `attribute_4`, ...
// (4 components each but the last), as readTetgenNode names them, so that
// the file reads back with the same attributes. Fails when the complex's
// point attributes are not such a sequence.
Status pointAttributeColumns(const Complex& complex, std::vector<const VertexAttribute*>& columns) {
  uint64_t total = 0;
  for (const VertexAttribute& a : complex.attributes)
    if (a.name != "marker") total += a.components;
  for (uint64_t first = 0; first < total; first += 4) {
    const VertexAttribute* a = findAttribute(complex, pointAttributeName(first, total));
    if (!a || a->components != std::min<uint64_t>(4, total - first))
      return Status::error(ErrorCode::InvalidArgument,
                           "TetGen point attributes must be float32 'attribute' (1 to 4 components) or "
                           "'attribute_0', 'attribute_4', ... of 4 components each but the last, as the "
                           "reader names them; this complex has no " + std::to_string(std::min<uint64_t>(4, total - first)) +
                               "-component '" + pointAttributeName(first, total) + "'");
    columns.push_back(a);
  }
  return Status::success();
}

}  // namespace

bool tetgenHoldsAttribute(const VertexAttribute& a) {
  if (a.name == "marker") return a.components == 1 && a.type != AttributeType::Float32;
  if (a.type != AttributeType::Float32) return false;
  if (a.name == "attribute") return true;
  // attribute_<first column>, the first column a multiple of 4.
  const std::string_view prefix = "attribute_";
  if (a.name.compare(0, prefix.size(), prefix) != 0 || a.name.size() == prefix.size()) return false;
  int64_t first = 0;
  return parseInteger(std::string_view(a.name).substr(prefix.size()), first) && first >= 0 && first % 4 == 0 &&
         a.name == "attribute_" + std::to_string(first);
}

Status writeTetgenNode(const Complex& complex, std::vector<uint8_t>& out) {
  if (!complex.edges.empty() || !complex.triangles.empty()) {
    return Status::error(ErrorCode::InvalidArgument,
                         "TetGen .node/.ele files hold only vertices and "
                         "tetrahedra, but the complex has edges or "
                         "triangles");
  }
  if (!pointsAreImplicit(complex)) {
    return Status::error(ErrorCode::InvalidArgument,
                         "TetGen cannot hold explicit points on vertices "
                         "that tetrahedra use");
  }
  std::vector<const VertexAttribute*> columns;
  if (Status status = pointAttributeColumns(complex, columns); !status.ok()) return status;
  uint64_t columnCount = 0;
  for (const VertexAttribute* a : columns) columnCount += a->components;
  const VertexAttribute* marker = findAttribute(complex, "marker");
  TextOut text(out);
  text.word("# written by kdmesh").endLine();
  text.integer(complex.vertexCount())
      .integer(3)
      .integer(columnCount)
      .integer(marker ? 1 : 0)
      .endLine();
  for (size_t v = 0; v < complex.vertexCount(); ++v) {
    text.integer(v + 1)  // numbered from 1, as TetGen writes by default
        .point(complex, v);
    for (const VertexAttribute* a : columns)
      for (size_t k = 0; k < a->components; ++k)
        text.value(AttributeType::Float32, &a->values[(v * a->components + k) * 4]);
    if (marker) text.value(marker->type, &marker->values[v * marker->valueBytes()]);
    text.endLine();
  }
  return Status::success();
}

Status writeTetgenEle(const Complex& complex, std::vector<uint8_t>& out) {
  TextOut text(out);
  text.word("# written by kdmesh").endLine();
  const std::vector<uint32_t>& tetrahedra = complex.tetrahedra;
  const std::vector<int32_t>& labels = complex.labels.tetrahedra;  // as the region attribute
  text.integer(tetrahedra.size() / 4).integer(4).integer(labels.empty() ? 0 : 1).endLine();
  for (size_t i = 0; i < tetrahedra.size(); i += 4) {
    text.integer(i / 4 + 1);
    for (size_t k = 0; k < 4; ++k) {
      text.integer(uint64_t{tetrahedra[i + k]} + 1);
    }
    if (!labels.empty()) text.word(std::to_string(labels[i / 4]));
    text.endLine();
  }
  return Status::success();
}

}  // namespace kdmesh::io::detail
