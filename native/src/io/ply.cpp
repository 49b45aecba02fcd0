// PLY: ascii, binary_little_endian and binary_big_endian.
//
// The header is parsed into a list of elements; each element then gets a plan
// saying what every property is used for (a coordinate, an index, a list of
// indices, or nothing). One templated loop executes the plans over either an
// ascii token stream or a binary byte cursor, so the two encodings share all
// element logic and differ only in how a single value is read.
#include <cstring>
#include <limits>
#include <type_traits>

#include "io/io_internal.h"

namespace kdmesh::io::detail {
namespace {

// ---------------------------------------------------------------------------
// Scalars
// ---------------------------------------------------------------------------

enum class Scalar : uint8_t {
  Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64
};

bool parseScalar(std::string_view name, Scalar& type) {
  static constexpr struct {
    std::string_view name;
    Scalar type;
  } kNames[] = {
      {"char", Scalar::Int8},      {"int8", Scalar::Int8},
      {"uchar", Scalar::UInt8},    {"uint8", Scalar::UInt8},
      {"short", Scalar::Int16},    {"int16", Scalar::Int16},
      {"ushort", Scalar::UInt16},  {"uint16", Scalar::UInt16},
      {"int", Scalar::Int32},      {"int32", Scalar::Int32},
      {"uint", Scalar::UInt32},    {"uint32", Scalar::UInt32},
      {"float", Scalar::Float32},  {"float32", Scalar::Float32},
      {"double", Scalar::Float64}, {"float64", Scalar::Float64},
  };
  for (const auto& entry : kNames) {
    if (entry.name == name) {
      type = entry.type;
      return true;
    }
  }
  return false;
}

size_t scalarBytes(Scalar type) {
  switch (type) {
    case Scalar::Int8: case Scalar::UInt8: return 1;
    case Scalar::Int16: case Scalar::UInt16: return 2;
    case Scalar::Int32: case Scalar::UInt32: case Scalar::Float32: return 4;
    case Scalar::Float64: return 8;
  }
  return 0;
}

bool isInteger(Scalar type) {
  return type != Scalar::Float32 && type != Scalar::Float64;
}

template <size_t Bytes>
using UnsignedBits = std::conditional_t<
    Bytes == 1, uint8_t,
    std::conditional_t<Bytes == 2, uint16_t,
                       std::conditional_t<Bytes == 4, uint32_t, uint64_t>>>;

// Assembles the bytes arithmetically, so the result does not depend on the
// byte order of the machine.
template <typename T>
T loadScalar(const uint8_t* bytes, bool bigEndian) {
  using Bits = UnsignedBits<sizeof(T)>;
  Bits bits = 0;
  for (size_t i = 0; i < sizeof(T); ++i) {
    const size_t shift = 8 * (bigEndian ? sizeof(T) - 1 - i : i);
    bits = static_cast<Bits>(bits | static_cast<Bits>(Bits{bytes[i]} << shift));
  }
  T value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

// Every PLY scalar type converts to double exactly.
double loadAsDouble(Scalar type, const uint8_t* bytes, bool bigEndian) {
  switch (type) {
    case Scalar::Int8: return loadScalar<int8_t>(bytes, bigEndian);
    case Scalar::UInt8: return loadScalar<uint8_t>(bytes, bigEndian);
    case Scalar::Int16: return loadScalar<int16_t>(bytes, bigEndian);
    case Scalar::UInt16: return loadScalar<uint16_t>(bytes, bigEndian);
    case Scalar::Int32: return loadScalar<int32_t>(bytes, bigEndian);
    case Scalar::UInt32: return loadScalar<uint32_t>(bytes, bigEndian);
    case Scalar::Float32: return loadScalar<float>(bytes, bigEndian);
    case Scalar::Float64: return loadScalar<double>(bytes, bigEndian);
  }
  return 0;
}

template <typename T>
void appendLittleEndian(std::vector<uint8_t>& out, T value) {
  UnsignedBits<sizeof(T)> bits;
  std::memcpy(&bits, &value, sizeof bits);
  for (size_t i = 0; i < sizeof(T); ++i) {
    out.push_back(static_cast<uint8_t>(bits >> (8 * i)));
  }
}

// ---------------------------------------------------------------------------
// Header
// ---------------------------------------------------------------------------

struct PlyProperty {
  std::string name;
  Scalar type = Scalar::Float32;     // of the items, for a list
  bool isList = false;
  Scalar countType = Scalar::UInt8;  // lists only
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

enum class Encoding : uint8_t { Ascii, BinaryLittleEndian, BinaryBigEndian };

struct PlyHeader {
  Encoding encoding = Encoding::Ascii;
  std::vector<PlyElement> elements;
};

Status parseFormatLine(TextScanner& scanner, PlyHeader& header) {
  std::string_view encoding, version;
  if (!scanner.nextToken(encoding) || !scanner.nextToken(version)) {
    return lineError(scanner.lineNumber(), "PLY format line is incomplete");
  }
  if (encoding == "ascii") {
    header.encoding = Encoding::Ascii;
  } else if (encoding == "binary_little_endian") {
    header.encoding = Encoding::BinaryLittleEndian;
  } else if (encoding == "binary_big_endian") {
    header.encoding = Encoding::BinaryBigEndian;
  } else {
    return lineError(scanner.lineNumber(),
                     "unknown PLY format " + quoted(encoding));
  }
  return Status::success();
}

Status parseElementLine(TextScanner& scanner, PlyHeader& header) {
  std::string_view name, count;
  PlyElement element;
  if (!scanner.nextToken(name) || !scanner.nextToken(count) ||
      !parseCount(count, element.count)) {
    return lineError(scanner.lineNumber(),
                     "PLY element line needs a name and a count");
  }
  element.name = name;
  header.elements.push_back(std::move(element));
  return Status::success();
}

Status parsePropertyLine(TextScanner& scanner, PlyHeader& header) {
  const size_t line = scanner.lineNumber();
  if (header.elements.empty()) {
    return lineError(line, "PLY property comes before any element");
  }
  PlyProperty property;
  std::string_view type, name;
  if (!scanner.nextToken(type)) {
    return lineError(line, "PLY property line is incomplete");
  }
  if (type == "list") {
    property.isList = true;
    std::string_view countType;
    if (!scanner.nextToken(countType) ||
        !parseScalar(countType, property.countType)) {
      return lineError(line, "PLY list property needs a count type");
    }
    if (!isInteger(property.countType)) {
      return lineError(line, "PLY list count type must be an integer type");
    }
    if (!scanner.nextToken(type)) {
      return lineError(line, "PLY property line is incomplete");
    }
  }
  if (!parseScalar(type, property.type)) {
    return lineError(line, "unknown PLY property type " + quoted(type));
  }
  if (!scanner.nextToken(name)) {
    return lineError(line, "PLY property line has no name");
  }
  property.name = name;
  header.elements.back().properties.push_back(std::move(property));
  return Status::success();
}

// The first line, 'ply' alone.
Status readPlySignature(TextScanner& scanner) {
  std::string_view token;
  if (!scanner.nextLine() || !scanner.nextToken(token) || token != "ply" ||
      scanner.nextToken(token)) {
    return inputError("not a PLY file: the first line is not 'ply'");
  }
  return Status::success();
}

// Leaves the scanner on the end_header line, so that an ascii body can be
// read on from there with the right line numbers.
Status parseHeader(TextScanner& scanner, PlyHeader& header) {
  std::string_view token;
  if (Status status = readPlySignature(scanner); !status.ok()) return status;
  bool hasFormat = false;
  while (scanner.nextLine()) {
    if (!scanner.nextToken(token) || token == "comment" ||
        token == "obj_info") {
      continue;
    }
    Status status;
    if (token == "end_header") {
      if (!hasFormat) return inputError("PLY header has no format line");
      return Status::success();
    } else if (token == "format") {
      hasFormat = true;
      status = parseFormatLine(scanner, header);
    } else if (token == "element") {
      status = parseElementLine(scanner, header);
    } else if (token == "property") {
      status = parsePropertyLine(scanner, header);
    } else {
      status = lineError(scanner.lineNumber(),
                         "unknown PLY header keyword " + quoted(token));
    }
    if (!status.ok()) return status;
  }
  return inputError("PLY header has no end_header line");
}

// ---------------------------------------------------------------------------
// Element plans
// ---------------------------------------------------------------------------

enum class Role : uint8_t { Vertex, Face, Edge, Tetra, Other };
enum class Use : uint8_t { Skip, X, Y, Z, First, Second, List, Attribute, Label };

// Integer properties of faces, edges and tetrahedra read as their simplices'
// labels (the first of these an element has); the writer names them `label`.
constexpr std::string_view kLabelNames[] = {"label", "material_index", "region"};

bool isIndexUse(Use use) {
  return use == Use::First || use == Use::Second || use == Use::List;
}

Role roleOf(std::string_view elementName) {
  if (elementName == "vertex") return Role::Vertex;
  if (elementName == "face") return Role::Face;
  if (elementName == "edge") return Role::Edge;
  if (elementName == "tetra" || elementName == "tetrahedron") {
    return Role::Tetra;
  }
  return Role::Other;
}

// The properties each role reads; an element lacking one is an error. Two
// names for the same use are alternatives.
struct Slot {
  Role role;
  Use use;
  std::string_view name;
  bool isList;
};
constexpr Slot kSlots[] = {
    {Role::Vertex, Use::X, "x", false},
    {Role::Vertex, Use::Y, "y", false},
    {Role::Vertex, Use::Z, "z", false},
    {Role::Face, Use::List, "vertex_indices", true},
    {Role::Face, Use::List, "vertex_index", true},
    {Role::Edge, Use::First, "vertex1", false},
    {Role::Edge, Use::Second, "vertex2", false},
    {Role::Tetra, Use::List, "vertex_indices", true},
    {Role::Tetra, Use::List, "vertex_index", true},
};

Use useOf(Role role, const PlyProperty& property) {
  for (const Slot& slot : kSlots) {
    if (slot.role == role && slot.name == property.name &&
        slot.isList == property.isList) {
      return slot.use;
    }
  }
  return Use::Skip;
}

// Where a vertex property's value goes: attribute `index`, `component`.
struct AttributeSlot {
  uint8_t index = 0, component = 0;
};

struct ElementPlan {
  Role role = Role::Other;
  std::vector<Use> uses;  // one per property
  std::vector<AttributeSlot> slots;  // one per property (Use::Attribute)
  // Vertex attributes: names, types and components (values empty).
  std::vector<VertexAttribute> attributes;
  // Allowed lengths of the index list: faces are polygons, tetrahedra have
  // exactly four vertices.
  uint64_t listMin = 0;
  uint64_t listMax = 0;
  bool labelled = false;  // a property is the simplices' label (Use::Label)
};

// The PLY scalar types an attribute keeps bit for bit.
bool attributeTypeOf(Scalar scalar, AttributeType& type) {
  switch (scalar) {
    case Scalar::Int8: type = AttributeType::Int8; return true;
    case Scalar::UInt8: type = AttributeType::UInt8; return true;
    case Scalar::Int16: type = AttributeType::Int16; return true;
    case Scalar::UInt16: type = AttributeType::UInt16; return true;
    case Scalar::Int32: type = AttributeType::Int32; return true;
    case Scalar::UInt32: type = AttributeType::UInt32; return true;
    case Scalar::Float32: type = AttributeType::Float32; return true;
    case Scalar::Float64: return false;
  }
  return false;
}

// Vertex properties read as one attribute of several components, by the
// names PLY files commonly give them; a group needs its first `required`
// properties, of one type. Properties name_0, name_1, ... (as the writer
// names an attribute's components) also form one attribute.
struct AttributeGroup {
  std::string_view attribute;
  std::array<std::string_view, 4> properties;
  size_t required;
};
constexpr AttributeGroup kAttributeGroups[] = {
    {"color", {"red", "green", "blue", "alpha"}, 3},
    {"color", {"r", "g", "b", "a"}, 3},
    {"normal", {"nx", "ny", "nz", ""}, 3},
    {"uv", {"u", "v", "", ""}, 2},
    {"uv", {"s", "t", "", ""}, 2},
    {"uv", {"texture_u", "texture_v", "", ""}, 2},
};

// Plans the vertex properties besides x, y, z as attributes; `skipped`
// gets those no attribute can hold.
void planAttributes(const PlyElement& element, ElementPlan& plan, std::string& skipped) {
  const std::vector<PlyProperty>& properties = element.properties;
  auto candidate = [&](size_t i) {
    AttributeType type;
    return plan.uses[i] == Use::Skip && !properties[i].isList && attributeTypeOf(properties[i].type, type) &&
           properties[i].name.size() <= kMaxAttributeNameBytes;
  };
  auto find = [&](std::string_view name) {
    for (size_t i = 0; i < properties.size(); ++i)
      if (candidate(i) && properties[i].name == name) return i;
    return properties.size();
  };
  // The attributes found, each with its properties; in the file's order of
  // their first properties.
  std::vector<std::pair<std::string, std::vector<size_t>>> found;
  std::vector<bool> taken(properties.size(), false);
  auto take = [&](std::string name, const std::vector<size_t>& members) {
    for (const size_t i : members) taken[i] = true;
    found.emplace_back(std::move(name), members);
  };
  auto free = [&](std::string_view name) {
    const size_t i = find(name);
    return i < properties.size() && !taken[i] ? i : properties.size();
  };
  for (const AttributeGroup& group : kAttributeGroups) {
    std::vector<size_t> members;
    for (const std::string_view name : group.properties) {
      if (name.empty()) break;
      const size_t i = free(name);
      if (i == properties.size() || (!members.empty() && properties[i].type != properties[members[0]].type)) break;
      members.push_back(i);
    }
    if (members.size() >= group.required) take(std::string(group.attribute), members);
  }
  for (size_t i = 0; i < properties.size(); ++i) {
    if (!candidate(i) || taken[i]) continue;
    const std::string& name = properties[i].name;
    std::vector<size_t> members{i};
    if (name.size() > 2 && name.compare(name.size() - 2, 2, "_0") == 0) {
      const std::string base = name.substr(0, name.size() - 2);
      for (size_t k = 1; k < 4; ++k) {
        const size_t j = free(base + "_" + std::to_string(k));
        if (j == properties.size() || properties[j].type != properties[i].type) break;
        members.push_back(j);
      }
      if (members.size() > 1) {
        take(base, members);
        continue;
      }
    }
    take(name, members);
  }
  std::stable_sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.second[0] < b.second[0]; });
  for (const auto& [name, members] : found) {
    if (plan.attributes.size() == kMaxAttributes) break;
    VertexAttribute a;
    a.name = name;
    attributeTypeOf(properties[members[0]].type, a.type);
    a.components = uint8_t(members.size());
    for (size_t k = 0; k < members.size(); ++k) {
      plan.uses[members[k]] = Use::Attribute;
      plan.slots[members[k]] = {uint8_t(plan.attributes.size()), uint8_t(k)};
    }
    plan.attributes.push_back(std::move(a));
  }
  for (size_t i = 0; i < properties.size(); ++i)
    if (plan.uses[i] == Use::Skip) skipped += " " + properties[i].name;
}

Status planElement(const PlyElement& element, ElementPlan& plan,
                   bool& doubleCoordinates, Notes& notes) {
  plan.role = roleOf(element.name);
  plan.listMin = plan.role == Role::Tetra ? 4 : 3;
  plan.listMax = plan.role == Role::Tetra ? 4
                                          : std::numeric_limits<uint64_t>::max();
  unsigned seen = 0;
  std::string skipped;
  for (const PlyProperty& property : element.properties) {
    Use use = useOf(plan.role, property);
    const unsigned bit = 1u << static_cast<unsigned>(use);
    if (use != Use::Skip && (seen & bit)) use = Use::Skip;  // a duplicate
    seen |= bit;
    if (isIndexUse(use) && !isInteger(property.type)) {
      return inputError("PLY property " + property.name + " of element " +
                        element.name + " must have an integer type");
    }
    if (use != Use::Skip && property.type == Scalar::Float64) {
      doubleCoordinates = true;
    }
    plan.uses.push_back(use);
  }
  plan.slots.resize(plan.uses.size());
  if (plan.role == Role::Vertex) {
    planAttributes(element, plan, skipped);
  } else if (plan.role != Role::Other) {
    for (const std::string_view name : kLabelNames) {
      for (size_t i = 0; i < plan.uses.size() && !plan.labelled; ++i) {
        const PlyProperty& property = element.properties[i];
        if (plan.uses[i] == Use::Skip && !property.isList && isInteger(property.type) && property.name == name) {
          plan.uses[i] = Use::Label;
          plan.labelled = true;
        }
      }
    }
    for (size_t i = 0; i < plan.uses.size(); ++i)
      if (plan.uses[i] == Use::Skip) skipped += " " + element.properties[i].name;
  } else {
    for (size_t i = 0; i < plan.uses.size(); ++i)
      if (plan.uses[i] == Use::Skip) skipped += " " + element.properties[i].name;
  }
  for (const Slot& slot : kSlots) {
    if (slot.role == plan.role &&
        !(seen & (1u << static_cast<unsigned>(slot.use)))) {
      return inputError("PLY element " + element.name + " has no " +
                        (slot.isList ? "list property " : "property ") +
                        std::string(slot.name));
    }
  }
  if (plan.role == Role::Other) {
    notes.push_back("skipped PLY element '" + element.name + "' (" +
                    std::to_string(element.count) + " items)");
  } else if (!skipped.empty()) {
    notes.push_back("ignored " + element.name + " properties:" + skipped);
  }
  return Status::success();
}

// ---------------------------------------------------------------------------
// Value sources: one value at a time from the ascii or binary body
// ---------------------------------------------------------------------------

class AsciiValues {
 public:
  explicit AsciiValues(TextScanner& scanner) : scanner_(scanner) {}

  // A coordinate as float32, and as a double into `exact` when given (then
  // `value` is its rounding).
  bool coordinate(Scalar, float& value, double* exact = nullptr) {
    std::string_view token;
    if (!next(token)) return false;
    if (exact ? !parseDouble(token, *exact) : !parseFloat(token, value)) {
      return fail(quoted(token) + " is not a number");
    }
    if (exact) value = static_cast<float>(*exact);
    return true;
  }
  bool integer(Scalar, int64_t& value) {
    std::string_view token;
    if (!next(token)) return false;
    if (!parseInteger(token, value)) {
      return fail(quoted(token) + " is not an integer");
    }
    return true;
  }
  bool skip(Scalar, uint64_t count) {
    std::string_view token;
    for (uint64_t i = 0; i < count; ++i) {
      if (!next(token)) return false;
    }
    return true;
  }
  // One attribute value of `type` into `out`, in memory order.
  bool attribute(Scalar type, uint8_t* out) {
    if (type == Scalar::Float32) {
      float value;
      if (!coordinate(type, value)) return false;
      std::memcpy(out, &value, 4);
      return true;
    }
    int64_t value;
    if (!integer(type, value)) return false;
    const int bits = int(8 * scalarBytes(type));
    const bool isSigned = type == Scalar::Int8 || type == Scalar::Int16 || type == Scalar::Int32;
    const int64_t low = isSigned ? -(int64_t(1) << (bits - 1)) : 0;
    const int64_t high = isSigned ? (int64_t(1) << (bits - 1)) - 1 : (int64_t(1) << bits) - 1;
    if (value < low || value > high) return fail(std::to_string(value) + " is out of the property's range");
    const uint32_t bitsOfValue = uint32_t(uint64_t(value));
    std::memcpy(out, &bitsOfValue, scalarBytes(type));  // little-endian, as the codec's values
    return true;
  }
  // A value takes at least a digit and a separator.
  static uint64_t minBytes(Scalar) { return 2; }
  bool canHold(uint64_t count, Scalar type) const {
    return count <= (scanner_.remainingBytes() + 1) / minBytes(type);
  }
  uint64_t remainingBytes() const { return scanner_.remainingBytes(); }
  std::string place() const {
    return "line " + std::to_string(scanner_.lineNumber());
  }
  bool fail(std::string problem) {
    problem_ = std::move(problem);
    return false;
  }
  const std::string& problem() const { return problem_; }

 private:
  bool next(std::string_view& token) {
    return scanner_.nextTokenAcrossLines(token) || fail("the file ends early");
  }

  TextScanner& scanner_;
  std::string problem_;
};

class BinaryValues {
 public:
  BinaryValues(ByteStream& bytes, bool bigEndian)
      : bytes_(bytes), bigEndian_(bigEndian) {}

  // A coordinate as float32, and as a double into `exact` when given.
  bool coordinate(Scalar type, float& value, double* exact = nullptr) {
    const uint8_t* bytes = take(type);
    if (bytes == nullptr) return false;
    // float32 goes straight through so that even NaN payloads keep their
    // bits; a double is rounded once.
    const double wide = loadAsDouble(type, bytes, bigEndian_);
    value = type == Scalar::Float32 ? loadScalar<float>(bytes, bigEndian_) : static_cast<float>(wide);
    if (exact) *exact = wide;
    return true;
  }
  // Only called for integer types, which double holds exactly.
  bool integer(Scalar type, int64_t& value) {
    const uint8_t* bytes = take(type);
    if (bytes == nullptr) return false;
    value = static_cast<int64_t>(loadAsDouble(type, bytes, bigEndian_));
    return true;
  }
  bool skip(Scalar type, uint64_t count) {
    if (!canHold(count, type) || !bytes_.skip(count * scalarBytes(type))) {
      return fail(kTruncated);
    }
    return true;
  }
  // One attribute value of `type` into `out`, in memory order
  // (little-endian).
  bool attribute(Scalar type, uint8_t* out) {
    const uint8_t* value = take(type);
    if (value == nullptr) return false;
    const size_t bytes = scalarBytes(type);
    for (size_t i = 0; i < bytes; ++i) out[i] = value[bigEndian_ ? bytes - 1 - i : i];
    return true;
  }
  static uint64_t minBytes(Scalar type) { return scalarBytes(type); }
  bool canHold(uint64_t count, Scalar type) const {
    return count <= remainingBytes() / scalarBytes(type);
  }
  uint64_t remainingBytes() const { return bytes_.remaining(); }
  std::string place() const {
    return "byte " + std::to_string(bytes_.offset());
  }
  bool fail(std::string problem) {
    problem_ = std::move(problem);
    return false;
  }
  const std::string& problem() const { return problem_; }

 private:
  static constexpr const char* kTruncated =
      "the data ends early (truncated file)";

  // The bytes of one value, or nullptr (and the problem) at the end.
  const uint8_t* take(Scalar type) {
    const uint8_t* bytes = bytes_.take(scalarBytes(type));
    if (bytes == nullptr) fail(kTruncated);
    return bytes;
  }

  ByteStream& bytes_;
  bool bigEndian_;
  std::string problem_;
};

// ---------------------------------------------------------------------------
// Body
// ---------------------------------------------------------------------------

struct BodyState {
  Complex& out;
  uint64_t vertexCount;
  bool doubles;  // coordinates kept as doubles too, in out.positions64
  std::vector<uint32_t> polygon;  // reused for every list
  PolygonSplit split;
};

template <class Values>
bool readIndex(Values& values, Scalar type, uint64_t vertexCount,
               uint32_t& index) {
  int64_t value;
  if (!values.integer(type, value)) return false;
  if (value < 0 || static_cast<uint64_t>(value) >= vertexCount) {
    return values.fail("vertex index " + std::to_string(value) +
                       " is out of range (" + std::to_string(vertexCount) +
                       " vertices)");
  }
  index = static_cast<uint32_t>(value);
  return true;
}

template <class Values>
bool readIndexList(Values& values, const PlyProperty& property,
                   const ElementPlan& plan, BodyState& state) {
  int64_t length;
  if (!values.integer(property.countType, length)) return false;
  if (length < 0 || static_cast<uint64_t>(length) < plan.listMin ||
      static_cast<uint64_t>(length) > plan.listMax) {
    return values.fail(
        "has " + counted(uint64_t(length), "vertex", "vertices") + ", " +
        (plan.listMin == plan.listMax ? "needs exactly " : "needs at least ") +
        std::to_string(plan.listMin));
  }
  if (!values.canHold(static_cast<uint64_t>(length), property.type)) {
    return values.fail("a list of " + std::to_string(length) +
                       " indices does not fit in the rest of the file");
  }
  state.polygon.resize(static_cast<size_t>(length));
  for (uint32_t& index : state.polygon) {
    if (!readIndex(values, property.type, state.vertexCount, index)) {
      return false;
    }
  }
  return true;
}

template <class Values>
bool skipProperty(Values& values, const PlyProperty& property) {
  if (!property.isList) return values.skip(property.type, 1);
  int64_t length;
  if (!values.integer(property.countType, length)) return false;
  if (length < 0) return values.fail("negative list length");
  return values.skip(property.type, static_cast<uint64_t>(length));
}

template <class Values>
uint64_t minItemBytes(const PlyElement& element, const ElementPlan& plan) {
  uint64_t bytes = 0;
  for (size_t i = 0; i < element.properties.size(); ++i) {
    const PlyProperty& property = element.properties[i];
    if (!property.isList) {
      bytes += Values::minBytes(property.type);
      continue;
    }
    bytes += Values::minBytes(property.countType);
    if (plan.uses[i] == Use::List) {
      bytes += plan.listMin * Values::minBytes(property.type);
    }
  }
  return bytes;
}

void reserveFor(Role role, uint64_t count, Complex& out) {
  auto grow = [count](auto& values, uint64_t arity) {
    values.reserve(values.size() + arity * count);
  };
  switch (role) {
    case Role::Vertex: grow(out.positions, 3); break;
    case Role::Face: grow(out.triangles, 3); break;
    case Role::Edge: grow(out.edges, 2); break;
    case Role::Tetra: grow(out.tetrahedra, 4); break;
    case Role::Other: break;
  }
}

template <class Values>
Status readElement(Values& values, const PlyElement& element,
                   const ElementPlan& plan, BodyState& state) {
  // Items without properties take no bytes, so the budget does not bound
  // their count: do not spend a step on each of up to 2^64 of them.
  if (element.properties.empty()) return Status::success();
  Complex& out = state.out;
  // One vertex's attribute values, component by component.
  std::vector<std::array<uint8_t, 16>> vertexValues(plan.attributes.size());
  // The simplex list the element adds to, and its labels.
  const int dimension = plan.role == Role::Edge ? 1 : plan.role == Role::Face ? 2 : plan.role == Role::Tetra ? 3 : 0;
  const std::vector<uint32_t>* simplices =
      dimension == 1 ? &out.edges : dimension == 2 ? &out.triangles : dimension == 3 ? &out.tetrahedra : nullptr;
  if (plan.labelled) {
    // Simplices listed before this element (a second face element) get 0.
    std::vector<int32_t>& labels = out.labels.of(dimension);
    labels.resize(simplices->size() / size_t(dimension + 1), 0);
  }
  for (uint64_t item = 0; item < element.count; ++item) {
    float xyz[3] = {0, 0, 0};
    double exact[3] = {0, 0, 0};
    uint32_t pair[2] = {0, 0};
    int64_t label = 0;
    for (size_t i = 0; i < element.properties.size(); ++i) {
      const PlyProperty& property = element.properties[i];
      const Use use = plan.uses[i];
      bool ok = true;
      switch (use) {
        case Use::X: case Use::Y: case Use::Z: {
          const int axis = static_cast<int>(use) - static_cast<int>(Use::X);
          ok = values.coordinate(property.type, xyz[axis], state.doubles ? &exact[axis] : nullptr);
          break;
        }
        case Use::First: case Use::Second:
          ok = readIndex(values, property.type, state.vertexCount,
                         pair[use == Use::First ? 0 : 1]);
          break;
        case Use::List:
          ok = readIndexList(values, property, plan, state);
          break;
        case Use::Attribute: {
          const AttributeSlot slot = plan.slots[i];
          ok = values.attribute(property.type,
                                vertexValues[slot.index].data() + slot.component * scalarBytes(property.type));
          break;
        }
        case Use::Label:
          ok = values.integer(property.type, label);
          if (ok && (label < std::numeric_limits<int32_t>::min() || label > std::numeric_limits<int32_t>::max())) {
            return inputError(element.name + " " + std::to_string(item) + " (" + values.place() + "): label " +
                              std::to_string(label) + " does not fit 32 bits");
          }
          break;
        case Use::Skip:
          ok = skipProperty(values, property);
          break;
      }
      if (!ok) {
        return inputError(element.name + " " + std::to_string(item) + " (" +
                          values.place() + "): " + values.problem());
      }
    }
    const std::vector<uint32_t>& polygon = state.polygon;
    switch (plan.role) {
      case Role::Vertex:
        out.positions.insert(out.positions.end(), xyz, xyz + 3);
        if (state.doubles) out.positions64.insert(out.positions64.end(), exact, exact + 3);
        for (size_t a = 0; a < vertexValues.size(); ++a) {
          std::vector<uint8_t>& values = out.attributes[a].values;
          values.insert(values.end(), vertexValues[a].data(), vertexValues[a].data() + out.attributes[a].valueBytes());
        }
        break;
      case Role::Face:
        state.split.append(polygon.data(), polygon.size(), out.triangles);
        break;
      case Role::Edge:
        out.edges.insert(out.edges.end(), pair, pair + 2);
        break;
      case Role::Tetra:
        out.tetrahedra.insert(out.tetrahedra.end(), polygon.begin(),
                              polygon.end());
        break;
      case Role::Other:
        break;
    }
    if (plan.labelled) {
      // A polygon's triangles all take its label.
      std::vector<int32_t>& labels = out.labels.of(dimension);
      labels.resize(simplices->size() / size_t(dimension + 1), int32_t(label));
    }
  }
  return Status::success();
}

template <class Values>
Status readBody(Values& values, const PlyHeader& header,
                const std::vector<ElementPlan>& plans, BodyState& state) {
  uint64_t budget = values.remainingBytes() + 1;
  for (size_t e = 0; e < header.elements.size(); ++e) {
    const PlyElement& element = header.elements[e];
    if (!takeFromBudget(element.count,
                        minItemBytes<Values>(element, plans[e]), budget)) {
      return inputError("PLY element " + element.name + " declares " +
                        std::to_string(element.count) +
                        " items, more than the rest of the file can hold");
    }
  }
  for (size_t e = 0; e < header.elements.size(); ++e) {
    reserveFor(plans[e].role, header.elements[e].count, state.out);
    Status status = readElement(values, header.elements[e], plans[e], state);
    if (!status.ok()) return status;
  }
  return Status::success();
}

// `doubleCoordinates` tells whether a coordinate is stored as double; unless
// `keepDoubles`, a note says they are rounded to float32.
Status planElements(const PlyHeader& header, std::vector<ElementPlan>& plans,
                    uint64_t& vertexCount, bool keepDoubles, bool& doubleCoordinates, Notes& notes) {
  bool haveVertices = false;
  plans.resize(header.elements.size());
  for (size_t e = 0; e < header.elements.size(); ++e) {
    const PlyElement& element = header.elements[e];
    Status status = planElement(element, plans[e], doubleCoordinates, notes);
    if (!status.ok()) return status;
    if (plans[e].role != Role::Vertex) continue;
    if (haveVertices) return inputError("PLY file has two vertex elements");
    haveVertices = true;
    vertexCount = element.count;
  }
  if (!haveVertices) return inputError("PLY file has no vertex element");
  if (vertexCount > std::numeric_limits<uint32_t>::max()) {
    return inputError("PLY file declares " + std::to_string(vertexCount) +
                      " vertices, more than 32-bit indices can address");
  }
  if (doubleCoordinates && !keepDoubles) {
    notes.push_back("coordinates stored as double were rounded to float32 (exact encoding keeps them)");
  }
  return Status::success();
}

}  // namespace

Status checkPlySignature(const uint8_t* head, size_t size) {
  TextScanner scanner(head, size);
  return readPlySignature(scanner);
}

namespace {

// Parses the header from the first block of the input, or from all of it
// when the block ends before the line that decides (end_header or an
// error). `body` receives the offset of the byte after end_header's line.
Status readHeader(Input& input, PlyHeader& header, uint64_t& body) {
  const Bytes head = input.head();
  TextScanner scanner(head.data, head.size);
  Status status = parseHeader(scanner, header);
  body = scanner.nextLineOffset();
  if (body < head.size || input.headIsWhole()) return status;
  const Bytes all = input.whole();
  TextScanner whole(all.data, all.size);
  header = PlyHeader{};
  status = parseHeader(whole, header);
  body = whole.nextLineOffset();
  return status;
}

// The ascii body, read from all of the input, with the line numbers of the
// file.
Status readAsciiBody(Input& input, const PlyHeader& header,
                     const std::vector<ElementPlan>& plans, BodyState& state,
                     uint64_t& trailingValues) {
  const Bytes all = input.whole();
  TextScanner scanner(all.data, all.size);
  PlyHeader again;  // moves the scanner past the header, already checked
  if (Status status = parseHeader(scanner, again); !status.ok()) return status;
  AsciiValues values(scanner);
  Status status = readBody(values, header, plans, state);
  std::string_view token;
  while (status.ok() && scanner.nextTokenAcrossLines(token)) ++trailingValues;
  return status;
}

// The binary body, streamed from `body` on.
Status readBinaryBody(Input& input, uint64_t body, const PlyHeader& header,
                      const std::vector<ElementPlan>& plans,
                      BodyState& state, uint64_t& trailingBytes) {
  ByteStream bytes = input.stream(body);
  BinaryValues values(bytes, header.encoding == Encoding::BinaryBigEndian);
  Status status = readBody(values, header, plans, state);
  trailingBytes = values.remainingBytes();
  return status;
}

}  // namespace

Status readPly(Input& input, Complex& out, Notes& notes, bool keepDoubles) {
  PlyHeader header;
  uint64_t body = 0;
  if (Status status = readHeader(input, header, body); !status.ok()) {
    return status;
  }
  std::vector<ElementPlan> plans;
  uint64_t vertexCount = 0;
  bool doubleCoordinates = false;
  if (Status status = planElements(header, plans, vertexCount, keepDoubles, doubleCoordinates, notes);
      !status.ok()) {
    return status;
  }
  for (const ElementPlan& plan : plans)
    if (plan.role == Role::Vertex) out.attributes = plan.attributes;
  BodyState state{out, vertexCount, doubleCoordinates && keepDoubles, {}, {}};
  uint64_t trailingBytes = 0;
  uint64_t trailingValues = 0;
  Status status =
      header.encoding == Encoding::Ascii
          ? readAsciiBody(input, header, plans, state, trailingValues)
          : readBinaryBody(input, body, header, plans, state, trailingBytes);
  if (!status.ok()) return status;
  // Simplices of an element without labels, listed after one with: label 0.
  for (int d = 1; d <= 3; ++d)
    if (!out.labels.of(d).empty()) out.labels.of(d).resize(out.simplexCount(d), 0);
  state.split.addNote(notes);
  addCountNote(notes, "ignored ", trailingBytes, "byte", "bytes",
               " after the last PLY element");
  addCountNote(notes, "ignored ", trailingValues, "value", "values",
               " after the last PLY element");
  return Status::success();
}

// ---------------------------------------------------------------------------
// Writer
// ---------------------------------------------------------------------------

namespace {

// The simplices of a complex as PLY elements; faces and tetrahedra are lists
// so that other PLY readers recognise them.
struct SimplexElement {
  const char* name;
  const std::vector<uint32_t>& indices;
  uint8_t arity;
  bool isList;
  const std::vector<int32_t>& labels;  // empty, or one per simplex
};

// The PLY names of an attribute's components: the names the reader groups
// (red green blue alpha, nx ny nz, u v), else the attribute's name, with _0,
// _1, ... for several components.
std::vector<std::string> propertyNames(const VertexAttribute& a) {
  static constexpr std::string_view kColour[4] = {"red", "green", "blue", "alpha"};
  static constexpr std::string_view kNormal[3] = {"nx", "ny", "nz"};
  static constexpr std::string_view kUv[2] = {"u", "v"};
  std::vector<std::string> names;
  for (int k = 0; k < a.components; ++k) {
    if (a.name == "color" && a.components >= 3) names.emplace_back(kColour[k]);
    else if (a.name == "normal" && a.components == 3) names.emplace_back(kNormal[k]);
    else if (a.name == "uv" && a.components == 2) names.emplace_back(kUv[k]);
    else if (a.components == 1) names.push_back(a.name);
    else names.push_back(a.name + "_" + std::to_string(k));
  }
  return names;
}

const char* plyTypeName(AttributeType type) {
  switch (type) {
    case AttributeType::UInt8: return "uchar";
    case AttributeType::Int8: return "char";
    case AttributeType::UInt16: return "ushort";
    case AttributeType::Int16: return "short";
    case AttributeType::UInt32: return "uint";
    case AttributeType::Int32: return "int";
    case AttributeType::Float32: return "float";
  }
  return "float";
}

class BinarySink {
 public:
  explicit BinarySink(std::vector<uint8_t>& out) : out_(out) {}
  void coordinate(float value) { appendLittleEndian(out_, value); }
  void coordinate(double value) { appendLittleEndian(out_, value); }
  // One attribute value, from its bytes in memory order (little-endian).
  void attribute(AttributeType type, const uint8_t* value) {
    out_.insert(out_.end(), value, value + attributeTypeBytes(type));
  }
  void listLength(uint8_t length) { out_.push_back(length); }
  void index(uint32_t value) { appendLittleEndian(out_, value); }
  void label(int32_t value) { appendLittleEndian(out_, value); }
  void endItem() {}

 private:
  std::vector<uint8_t>& out_;
};

class TextSink {
 public:
  explicit TextSink(std::vector<uint8_t>& out) : text_(out) {}
  void coordinate(float value) { text_.real(value); }
  void coordinate(double value) { text_.real(value); }
  void attribute(AttributeType type, const uint8_t* value) { text_.value(type, value); }
  void listLength(uint8_t length) { text_.integer(length); }
  void index(uint32_t value) { text_.integer(value); }
  void label(int32_t value) { text_.word(std::to_string(value)); }
  void endItem() { text_.endLine(); }

 private:
  TextOut text_;
};

template <class Sink>
void writeBody(const Complex& complex,
               const std::vector<SimplexElement>& elements, Sink& sink) {
  for (size_t v = 0; v < complex.vertexCount(); ++v) {
    for (size_t axis = 0; axis < 3; ++axis) {
      if (complex.positions64.empty())
        sink.coordinate(complex.positions[3 * v + axis]);
      else
        sink.coordinate(complex.positions64[3 * v + axis]);
    }
    for (const VertexAttribute& a : complex.attributes) {
      const size_t bytes = attributeTypeBytes(a.type);
      for (size_t k = 0; k < a.components; ++k) sink.attribute(a.type, &a.values[(v * a.components + k) * bytes]);
    }
    sink.endItem();
  }
  for (const SimplexElement& element : elements) {
    for (size_t i = 0; i < element.indices.size(); i += element.arity) {
      if (element.isList) sink.listLength(element.arity);
      for (size_t k = 0; k < element.arity; ++k) {
        sink.index(element.indices[i + k]);
      }
      if (!element.labels.empty()) sink.label(element.labels[i / element.arity]);
      sink.endItem();
    }
  }
}

void writeHeader(const Complex& complex,
                 const std::vector<SimplexElement>& elements, bool ascii,
                 std::vector<uint8_t>& out) {
  TextOut text(out);
  text.word("ply").endLine();
  text.word("format")
      .word(ascii ? "ascii" : "binary_little_endian")
      .word("1.0")
      .endLine();
  text.word("comment written by kdmesh").endLine();
  text.word("element vertex").integer(complex.vertexCount()).endLine();
  for (const char* axis : {"x", "y", "z"}) {
    text.word(complex.positions64.empty() ? "property float" : "property double").word(axis).endLine();
  }
  for (const VertexAttribute& a : complex.attributes)
    for (const std::string& name : propertyNames(a)) text.word("property").word(plyTypeName(a.type)).word(name).endLine();
  for (const SimplexElement& element : elements) {
    text.word("element")
        .word(element.name)
        .integer(element.indices.size() / element.arity)
        .endLine();
    if (element.isList) {
      text.word("property list uchar int vertex_indices").endLine();
    } else {
      text.word("property int vertex1").endLine();
      text.word("property int vertex2").endLine();
    }
    if (!element.labels.empty()) text.word("property int label").endLine();
  }
  text.word("end_header").endLine();
}

}  // namespace

Status writePly(const Complex& complex, std::vector<uint8_t>& out,
                const WriteOptions& options) {
  if (!pointsAreImplicit(complex)) {
    return Status::error(ErrorCode::InvalidArgument,
                         "PLY cannot hold explicit points on vertices that "
                         "simplices use");
  }
  std::vector<SimplexElement> elements;
  if (!complex.triangles.empty()) {
    elements.push_back({"face", complex.triangles, 3, true, complex.labels.triangles});
  }
  if (!complex.edges.empty()) {
    elements.push_back({"edge", complex.edges, 2, false, complex.labels.edges});
  }
  if (!complex.tetrahedra.empty()) {
    elements.push_back({"tetra", complex.tetrahedra, 4, true, complex.labels.tetrahedra});
  }
  writeHeader(complex, elements, options.asciiPly, out);
  if (options.asciiPly) {
    TextSink sink(out);
    writeBody(complex, elements, sink);
  } else {
    out.reserve(out.size() + 4 * complex.positions.size() +
                complex.triangles.size() / 3 * 13 + 4 * complex.edges.size() +
                complex.tetrahedra.size() / 4 * 17 + 4 * (complex.labels.edges.size() +
                complex.labels.triangles.size() + complex.labels.tetrahedra.size()));
    BinarySink sink(out);
    writeBody(complex, elements, sink);
  }
  return Status::success();
}

}  // namespace kdmesh::io::detail
