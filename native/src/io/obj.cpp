// Wavefront OBJ: vertices, points, polylines and faces, with the texture
// coordinates (vt) and normals (vn) their corners name as the vertex
// attributes `uv` and `normal`, and the materials (usemtl) of lines and
// faces as simplex labels (SimplexNames), or their groups (g) in a file
// without materials. Objects, smoothing groups and material libraries are
// not part of a simplicial complex: their lines are counted in a note.
#include <charconv>
#include <cstring>
#include <type_traits>
#include <unordered_map>
#include <unordered_set>

#include "io/io_internal.h"

namespace kdmesh::io::detail {
namespace {

// Keywords whose data kdmesh does not keep (yet), and what they hold: each
// skipped line is counted, and the counts noted.
constexpr struct {
  std::string_view keyword, one, many;
} kSkippedKeywords[] = {
    {"vp", "parameter-space vertex (vp)", "parameter-space vertices (vp)"},
    {"o", "object name (o)", "object names (o)"},
    {"s", "smoothing group (s)", "smoothing groups (s)"},
    {"mtllib", "material library (mtllib)", "material libraries (mtllib)"},
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

// The names that lines and faces are given, materials (usemtl) or groups
// (g), as simplex labels. When every name is a decimal 32-bit integer and
// no line or face comes before the first name (as writeObj() writes
// labels), the names are the labels; otherwise names are numbered from 0
// in order of first use, lines and faces before any counting as one more.
class SimplexNames {
 public:
  // `one`, `many`: what the names are, singular and plural ("material (usemtl)").
  SimplexNames(const char* one, const char* many) : one_(one), many_(many) {}

  bool used() const { return used_; }
  void use(std::string_view name) {
    current_ = number(name);
    used_ = true;
  }
  // Labels the edges and triangles added since the last call.
  void label(const Complex& out) {
    if (current_ < 0) {
      current_ = number({});  // lines and faces before any usemtl
      unnamedFirst_ = true;
    }
    edges_.resize(out.edges.size() / 2, current_);
    triangles_.resize(out.triangles.size() / 3, current_);
  }
  // Moves the labels into `out` when the file named simplices, with a note
  // of how they were numbered.
  void finish(Complex& out, Notes& notes) {
    if (!used_) return;
    bool integers = !unnamedFirst_;
    std::vector<int32_t> values(names_.size());
    for (size_t i = 0; i < names_.size() && integers; ++i) {
      const std::string& name = names_[i];
      const auto [end, error] = std::from_chars(name.data(), name.data() + name.size(), values[i]);
      integers = error == std::errc() && end == name.data() + name.size();
    }
    for (auto* list : {&edges_, &triangles_})
      for (int32_t& label : *list) label = integers ? values[size_t(label)] : label;
    out.labels.edges = std::move(edges_);
    out.labels.triangles = std::move(triangles_);
    if (integers) return;
    std::string list;
    constexpr size_t kNamed = 8;
    for (size_t i = 0; i < std::min(names_.size(), kNamed); ++i)
      list += (i ? ", " : "") + std::to_string(i) + " " + (names_[i].empty() ? "(none)" : quoted(names_[i]));
    if (names_.size() > kNamed) list += ", ...";
    notes.push_back("kept the " + counted(names_.size(), one_, many_) +
                    " of lines and faces as simplex labels, numbered in order of first use: " + list);
  }

 private:
  int32_t number(std::string_view name) {
    const auto [at, inserted] = numbers_.emplace(std::string(name), int32_t(names_.size()));
    if (inserted) names_.emplace_back(name);
    return at->second;
  }
  std::unordered_map<std::string, int32_t> numbers_;
  std::vector<std::string> names_;
  std::vector<int32_t> edges_, triangles_;
  const char *one_, *many_;
  int32_t current_ = -1;
  bool used_ = false, unnamedFirst_ = false;
};

constexpr uint32_t kNone = 0xffffffffu;
// Vertex numbers of corners that name a texture coordinate or a normal
// carry this bit while the file is read (see CornerVertices); the codec
// takes fewer than 2^31 vertices, so position numbers never reach it.
constexpr uint32_t kCornerBit = 0x80000000u;

// OBJ counts vertices (and texture coordinates, normals) from 1; a
// negative index counts back from the latest, so both depend on how many
// precede the line.
bool resolveIndex(int64_t value, size_t definedSoFar, uint32_t& index) {
  const int64_t resolved = value > 0 ? value - 1 : static_cast<int64_t>(definedSoFar) + value;
  if (resolved < 0 || static_cast<uint64_t>(resolved) >= definedSoFar) return false;
  index = static_cast<uint32_t>(resolved);
  return true;
}

// The vertex data an OBJ file defines before its elements refer to it.
struct Definitions {
  std::vector<float> uvs;      // 3 per vt line: u, v, w (absent ones 0)
  std::vector<float> normals;  // 3 per vn line
  int uvComponents = 2;        // 3 once a vt line gives w
  size_t uvCount() const { return uvs.size() / 3; }
  size_t normalCount() const { return normals.size() / 3; }
};

// The corners (v, vt, vn) that name a texture coordinate or a normal, each
// distinct triple once, numbered in order of first appearance.
struct CornerVertices {
  struct Key {
    uint32_t v, vt, vn;
    bool operator==(const Key& o) const { return v == o.v && vt == o.vt && vn == o.vn; }
  };
  struct Hash {
    size_t operator()(const Key& k) const {
      uint64_t h = (uint64_t{k.v} * 0x9E3779B97F4A7C15ull) ^ (uint64_t{k.vt} * 0xC2B2AE3D27D4EB4Full) ^
                   (uint64_t{k.vn} * 0x165667B19E3779F9ull);
      return size_t(h ^ (h >> 31));
    }
  };
  std::vector<Key> keys;
  std::unordered_map<Key, uint32_t, Hash> index;

  // The vertex number of a corner: its position's, or kCornerBit plus the
  // triple's number when it names vt or vn.
  uint32_t of(uint32_t v, uint32_t vt, uint32_t vn) {
    if (vt == kNone && vn == kNone) return v;
    const auto [at, inserted] = index.emplace(Key{v, vt, vn}, uint32_t(keys.size()));
    if (inserted) keys.push_back({v, vt, vn});
    return kCornerBit | at->second;
  }
};

// Reads one v, v/vt, v//vn or v/vt/vn corner; `what` names the element for
// messages.
Status readCorner(TextScanner& scanner, std::string_view token, const char* what, size_t positions,
                  const Definitions& defined, uint32_t (&indices)[3]) {
  const size_t counts[3] = {positions, defined.uvCount(), defined.normalCount()};
  static const char* const kKinds[3] = {"vertex", "texture coordinate", "normal"};
  static const char* const kKeywords[3] = {"v", "vt", "vn"};
  indices[0] = indices[1] = indices[2] = kNone;
  std::string_view rest = token;
  for (int k = 0; k < 3; ++k) {
    const size_t slash = rest.find('/');
    const std::string_view field = rest.substr(0, slash);
    if (k > 0 && slash == std::string_view::npos && field.empty() && rest.empty()) break;
    if (!field.empty() || k == 0) {
      int64_t value;
      if (!parseInteger(field, value))
        return lineError(scanner.lineNumber(), quoted(token) + " is not a " + kKinds[k] + " index");
      if (!resolveIndex(value, counts[k], indices[k]))
        return lineError(scanner.lineNumber(),
                         std::string(what) + " " + kKinds[k] + " index " + std::to_string(value) +
                             " is out of range: OBJ numbers " + kKeywords[k] +
                             " lines from 1 (and from -1 back from the last), " + std::to_string(counts[k]) +
                             " defined so far");
    }
    if (slash == std::string_view::npos) break;
    rest = rest.substr(slash + 1);
    if (k == 2) return lineError(scanner.lineNumber(), quoted(token) + " has more than three indices");
  }
  return Status::success();
}

// Reads the corners of an f, l or p line as vertex numbers.
Status readIndexLine(TextScanner& scanner, char keyword, size_t positions, const Definitions& defined,
                     CornerVertices& corners, std::vector<uint32_t>& indices) {
  indices.clear();
  std::string_view token;
  while (scanner.nextToken(token)) {
    uint32_t corner[3];
    if (Status s = readCorner(scanner, token, simplexName(keyword), positions, defined, corner); !s.ok()) return s;
    indices.push_back(corners.of(corner[0], corner[1], corner[2]));
  }
  if (indices.size() < minimumIndices(keyword)) {
    return lineError(scanner.lineNumber(),
                     std::string(simplexName(keyword)) + " has " + counted(indices.size(), "vertex", "vertices") +
                         ", needs at least " + std::to_string(minimumIndices(keyword)));
  }
  return Status::success();
}

void addSimplices(char keyword, const std::vector<uint32_t>& indices, Complex& out, PolygonSplit& split) {
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

// Reads the numbers of a vt or vn line: `least` to 3 of them, the absent
// ones 0. Returns how many the line gave.
Status readValues(TextScanner& scanner, const char* keyword, size_t least, std::vector<float>& out, size_t& given) {
  float values[3] = {0, 0, 0};
  std::string_view token;
  given = 0;
  while (scanner.nextToken(token)) {
    if (given == 3)
      return lineError(scanner.lineNumber(), std::string(keyword) + " has more than 3 values");
    if (!parseFloat(token, values[given])) return lineError(scanner.lineNumber(), quoted(token) + " is not a number");
    ++given;
  }
  if (given < least)
    return lineError(scanner.lineNumber(), std::string(keyword) + " has " + counted(given, "value", "values") +
                                               ", needs " + std::to_string(least));
  out.insert(out.end(), values, values + 3);
  return Status::success();
}

VertexAttribute floatAttribute(const char* name, int components, size_t vertices) {
  VertexAttribute a{name, AttributeType::Float32, uint8_t(components), {}, {}};
  a.values.assign(vertices * a.valueBytes(), 0);
  return a;
}

// Gives every corner triple a vertex of its own: first the positions used
// by an element without vt and vn or by none (in file order), then the
// triples in order of first appearance, their positions copied. Values a
// vertex lacks (no vt or no vn at its corner) are 0. Adds the notes about
// vt and vn lines no corner names.
void makeCornerVertices(const Definitions& defined, const CornerVertices& corners, Complex& out, Notes& notes) {
  const size_t positions = out.vertexCount();
  std::vector<uint8_t> bare(positions, 1), uvUsed(defined.uvCount(), 0), normalUsed(defined.normalCount(), 0);
  bool anyUv = false, anyNormal = false;
  for (const CornerVertices::Key& k : corners.keys) {
    bare[k.v] = 0;
    if (k.vt != kNone) uvUsed[k.vt] = 1, anyUv = true;
    if (k.vn != kNone) normalUsed[k.vn] = 1, anyNormal = true;
  }
  // A position used bare and by triples keeps its bare vertex.
  auto markBare = [&bare](const std::vector<uint32_t>& list) {
    for (const uint32_t v : list)
      if (!(v & kCornerBit)) bare[v] = 1;
  };
  for (const auto* list : {&out.points, &out.edges, &out.triangles}) markBare(*list);
  std::vector<uint32_t> vertexOf(positions, kNone);
  size_t count = 0;
  for (size_t v = 0; v < positions; ++v)
    if (bare[v]) vertexOf[v] = uint32_t(count++);
  const size_t firstCorner = count;
  count += corners.keys.size();
  // The bare positions, then each corner's copy (doubles alike).
  auto reorder = [&](auto& values) {
    std::remove_reference_t<decltype(values)> reordered;
    reordered.reserve(count * 3);
    for (size_t v = 0; v < positions; ++v)
      if (bare[v]) reordered.insert(reordered.end(), &values[3 * v], &values[3 * v] + 3);
    for (const CornerVertices::Key& k : corners.keys)
      reordered.insert(reordered.end(), &values[3 * size_t(k.v)], &values[3 * size_t(k.v)] + 3);
    values.swap(reordered);
  };
  reorder(out.positions);
  if (!out.positions64.empty()) reorder(out.positions64);

  VertexAttribute uv = floatAttribute("uv", defined.uvComponents, count);
  VertexAttribute normal = floatAttribute("normal", 3, count);
  for (size_t i = 0; i < corners.keys.size(); ++i) {
    const CornerVertices::Key& k = corners.keys[i];
    if (k.vt != kNone)
      std::memcpy(&uv.values[(firstCorner + i) * uv.valueBytes()], &defined.uvs[3 * size_t(k.vt)], uv.valueBytes());
    if (k.vn != kNone)
      std::memcpy(&normal.values[(firstCorner + i) * 12], &defined.normals[3 * size_t(k.vn)], 12);
  }
  if (anyUv) out.attributes.push_back(std::move(uv));
  if (anyNormal) out.attributes.push_back(std::move(normal));
  for (auto* list : {&out.points, &out.edges, &out.triangles})
    for (uint32_t& v : *list) v = v & kCornerBit ? uint32_t(firstCorner) + (v & ~kCornerBit) : vertexOf[v];

  size_t unusedUvs = 0, unusedNormals = 0;
  for (const uint8_t used : uvUsed) unusedUvs += !used;
  for (const uint8_t used : normalUsed) unusedNormals += !used;
  addCountNote(notes, "ignored ", unusedUvs, "texture coordinate (vt)", "texture coordinates (vt)",
               " that no corner names");
  addCountNote(notes, "ignored ", unusedNormals, "normal (vn)", "normals (vn)", " that no corner names");
}

}  // namespace

Status readObj(const uint8_t* data, size_t size, Complex& out, Notes& notes, bool keepDoubles) {
  TextScanner scanner(data, size, {/*commaSeparates=*/false,
                                   /*hashComments=*/true});
  std::vector<uint32_t> indices;  // of one line, reused
  Definitions defined;
  CornerVertices corners;
  PolygonSplit split;
  size_t extraColumnLines = 0;
  size_t unknownLines = 0;
  size_t skipped[kSkippedKinds] = {};
  // Labels: the materials, or the groups of a file without materials.
  SimplexNames materials("material (usemtl)", "materials (usemtl)"), groups("group (g)", "groups (g)");
  size_t groupLines = 0;
  std::string firstUnknown;
  bool beyondFloat = false;  // a coordinate that float32 does not hold
  std::string_view keyword;
  while (scanner.nextLine()) {
    if (!scanner.nextToken(keyword)) continue;
    if (keyword == "v") {
      if (out.vertexCount() >= kCornerBit - 1)
        return lineError(scanner.lineNumber(), "more than 2^31 - 1 vertices");
      bool extraColumns = false;
      Status status = readPositionLine(scanner, out.positions, extraColumns,
                                       keepDoubles ? &out.positions64 : nullptr, &beyondFloat);
      if (!status.ok()) return status;
      extraColumnLines += extraColumns;
    } else if (keyword == "vt" || keyword == "vn") {
      const bool uv = keyword == "vt";
      size_t given = 0;
      Status status = readValues(scanner, uv ? "vt" : "vn", uv ? 1 : 3, uv ? defined.uvs : defined.normals, given);
      if (!status.ok()) return status;
      if (uv && given == 3) defined.uvComponents = 3;
    } else if (keyword == "f" || keyword == "l" || keyword == "p") {
      Status status = readIndexLine(scanner, keyword[0], out.vertexCount(), defined, corners, indices);
      if (!status.ok()) return status;
      addSimplices(keyword[0], indices, out, split);
      if (keyword[0] != 'p') {
        materials.label(out);
        groups.label(out);
      }
    } else if (keyword == "usemtl" || keyword == "g") {
      // The rest of the line is the name (names may hold spaces; a group
      // line may name several groups, which together name the group).
      std::string_view name, more;
      scanner.nextToken(name);  // none: the unnamed one, as before any
      while (scanner.nextToken(more)) name = std::string_view(name.data(), size_t(more.data() + more.size() - name.data()));
      (keyword == "g" ? groups : materials).use(name);
      groupLines += keyword == "g";
    } else if (const size_t kind = skippedKind(keyword); kind < kSkippedKinds) {
      ++skipped[kind];
    } else {
      if (unknownLines++ == 0) {
        firstUnknown = quoted(keyword) + " on line " +
                       std::to_string(scanner.lineNumber());
      }
    }
  }
  settleDoubles(out, beyondFloat, keepDoubles, notes);
  if (materials.used())
    addCountNote(notes, "ignored ", groupLines, "group name (g)", "group names (g)",
                 ": the materials (usemtl) are the simplex labels");
  (materials.used() ? materials : groups).finish(out, notes);
  if (!corners.keys.empty() || defined.uvCount() > 0 || defined.normalCount() > 0)
    makeCornerVertices(defined, corners, out, notes);
  addCountNote(notes, "ignored extra columns (w or colour) on ", extraColumnLines, "vertex line", "vertex lines");
  split.addNote(notes);
  std::string lost;
  for (size_t i = 0; i < kSkippedKinds; ++i)
    if (skipped[i] > 0)
      lost += (lost.empty() ? "" : ", ") + counted(skipped[i], kSkippedKeywords[i].one, kSkippedKeywords[i].many);
  if (!lost.empty()) {
    notes.push_back("ignored " + lost +
                    ": kdmesh keeps an OBJ's vertex positions, texture coordinates, normals, faces, lines, points "
                    "and materials (usemtl) or groups (g) only");
  }
  if (unknownLines > 0) {
    notes.push_back("ignored " + counted(unknownLines, "line", "lines") + " with unknown keywords (the first: " + firstUnknown +
                    ")");
  }
  return Status::success();
}

namespace {

// Numbers the distinct values of `count` records of `bytes` bytes, in order
// of first appearance; returns each record's number, and appends to `firsts`
// the record that first had each.
std::vector<uint32_t> distinctRecords(const uint8_t* records, size_t count, size_t bytes,
                                      std::vector<uint32_t>& firsts) {
  std::unordered_map<std::string_view, uint32_t> seen;
  std::vector<uint32_t> numbers(count);
  for (size_t i = 0; i < count; ++i) {
    const std::string_view key(reinterpret_cast<const char*>(records + i * bytes), bytes);
    const auto [at, inserted] = seen.emplace(key, uint32_t(firsts.size()));
    if (inserted) firsts.push_back(uint32_t(i));
    numbers[i] = at->second;
  }
  return numbers;
}

}  // namespace

bool objHoldsAttribute(const VertexAttribute& a) {
  return a.type == AttributeType::Float32 &&
         ((a.name == "uv" && (a.components == 2 || a.components == 3)) || (a.name == "normal" && a.components == 3));
}

Status writeObj(const Complex& complex, std::vector<uint8_t>& out) {
  if (!complex.tetrahedra.empty()) {
    return Status::error(ErrorCode::InvalidArgument,
                         "OBJ cannot hold tetrahedra");
  }
  TextOut text(out);
  text.word("# written by kdmesh").endLine();
  const size_t n = complex.vertexCount();
  const VertexAttribute* uv = findAttribute(complex, "uv");
  const VertexAttribute* normal = findAttribute(complex, "normal");
  // Corner (v, vt, vn) of each vertex, numbered from 0; without attributes
  // vertex i is line v i.
  std::vector<uint32_t> position(n), uvOf, normalOf;
  std::vector<uint32_t> positionLines, uvLines, normalLines;  // the vertex each line comes from
  if (!uv && !normal) {
    for (size_t v = 0; v < n; ++v) position[v] = uint32_t(v);
    positionLines = position;
  } else {
    // Identical positions, texture coordinates and normals are written
    // once; a vertex whose whole corner equals another's gets a v line of
    // its own, so that reading the file back gives every vertex again.
    const std::vector<uint32_t> samePosition =
        complex.positions64.empty()
            ? distinctRecords(reinterpret_cast<const uint8_t*>(complex.positions.data()), n, 12, positionLines)
            : distinctRecords(reinterpret_cast<const uint8_t*>(complex.positions64.data()), n, 24, positionLines);
    if (uv) uvOf = distinctRecords(uv->values.data(), n, uv->valueBytes(), uvLines);
    if (normal) normalOf = distinctRecords(normal->values.data(), n, 12, normalLines);
    struct Corner {
      uint32_t position, uv, normal;
      bool operator==(const Corner& o) const { return position == o.position && uv == o.uv && normal == o.normal; }
    };
    struct CornerHash {
      size_t operator()(const Corner& c) const {
        const uint64_t h = uint64_t{c.position} * 0x9E3779B97F4A7C15ull ^ uint64_t{c.uv} * 0xC2B2AE3D27D4EB4Full ^
                           uint64_t{c.normal} * 0x165667B19E3779F9ull;
        return size_t(h ^ (h >> 31));
      }
    };
    std::unordered_set<Corner, CornerHash> taken;
    for (size_t v = 0; v < n; ++v) {
      Corner c{samePosition[v], uv ? uvOf[v] : 0, normal ? normalOf[v] : 0};
      if (!taken.insert(c).second) {
        c.position = uint32_t(positionLines.size());
        positionLines.push_back(uint32_t(v));
        taken.insert(c);
      }
      position[v] = c.position;
    }
  }
  for (const uint32_t v : positionLines) text.word("v").point(complex, v).endLine();
  for (const uint32_t v : uvLines) {
    text.word("vt");
    for (size_t k = 0; k < uv->components; ++k) {
      float value;
      std::memcpy(&value, &uv->values[(size_t(v) * uv->components + k) * 4], 4);
      text.real(value);
    }
    text.endLine();
  }
  for (const uint32_t v : normalLines) {
    float xyz[3];
    std::memcpy(xyz, &normal->values[size_t(v) * 12], 12);
    text.word("vn").real(xyz[0]).real(xyz[1]).real(xyz[2]).endLine();
  }
  // OBJ indices count from 1; v/vt/vn, or v//vn without texture coordinates.
  std::string corner;
  auto writeCorner = [&](uint32_t v) {
    corner = std::to_string(uint64_t{position[v]} + 1);
    if (uv || normal) corner += '/';
    if (uv) corner += std::to_string(uint64_t{uvOf[v]} + 1);
    if (normal) corner += '/' + std::to_string(uint64_t{normalOf[v]} + 1);
    text.word(corner);
  };
  // With attributes, a vertex in no element would read back without its
  // values: such vertices are written as points too.
  std::vector<uint32_t> points = complex.points;
  if (uv || normal) {
    std::vector<uint8_t> used(n, 0);
    for (const auto* list : {&complex.points, &complex.edges, &complex.triangles})
      for (const uint32_t v : *list) used[v] = 1;
    for (size_t v = 0; v < n; ++v)
      if (!used[v]) points.push_back(uint32_t(v));
  }
  for (uint32_t point : points) {
    text.word("p");
    writeCorner(point);
    text.endLine();
  }
  // Labels as materials named by their values, a usemtl line wherever the
  // label changes (and before each list's first element), which readObj()
  // reads back as the same labels.
  const bool labelled = !complex.labels.empty();
  int64_t material = -1;  // no label is -1: the first element always names its material
  auto useMaterial = [&](int dimension, size_t simplex, bool first) {
    const std::vector<int32_t>& labels = complex.labels.of(dimension);
    const int32_t label = simplex < labels.size() ? labels[simplex] : 0;
    if (!labelled || (!first && label == material)) return;
    material = label;
    text.word("usemtl").word(std::to_string(label)).endLine();
  };
  for (size_t i = 0; i < complex.edges.size(); i += 2) {
    useMaterial(1, i / 2, i == 0);
    text.word("l");
    writeCorner(complex.edges[i]);
    writeCorner(complex.edges[i + 1]);
    text.endLine();
  }
  for (size_t i = 0; i < complex.triangles.size(); i += 3) {
    useMaterial(2, i / 3, i == 0);
    text.word("f");
    for (size_t k = 0; k < 3; ++k) writeCorner(complex.triangles[i + k]);
    text.endLine();
  }
  return Status::success();
}

}  // namespace kdmesh::io::detail
