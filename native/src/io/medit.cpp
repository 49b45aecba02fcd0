// INRIA Medit .mesh, ascii: keywords, each followed by a count and that many
// items, with 1-based vertex indices and a reference label closing each item:
//
//   MeshVersionFormatted 1
//   Dimension 3
//   Vertices  n   then n lines "x y z ref"
//   Edges     n   then "a b ref"
//   Triangles n   then "a b c ref"
//   Tetrahedra n  then "a b c d ref"
//   End
//
// The references of edges, triangles and tetrahedra are their simplices'
// labels (when any is nonzero); a triangle or edge that is a face of a
// listed tetrahedron or triangle is no maximal simplex, and its reference is
// dropped with it (noted). Vertex references are not kept.
//
// Values are read as a token stream, so counts and items may wrap over lines;
// '#' starts a comment. Quadrilaterals become two triangles each (noted).
// Sections whose item size is known but which hold no simplices (hexahedra,
// prisms, corners, normals, ...) are skipped with a note; any other keyword
// is an error, since there is no telling how much of the file it takes.
#include <algorithm>
#include <array>
#include <limits>

#include "io/io_internal.h"

namespace kdmesh::io::detail {
namespace {

enum class Kind : uint8_t {
  Vertices, Edges, Triangles, Quadrilaterals, Tetrahedra, Skipped
};

struct Section {
  std::string_view keyword;
  Kind kind;
  uint64_t valuesPerItem;  // including the reference label, if any
};

constexpr Section kSections[] = {
    {"Vertices", Kind::Vertices, 4},
    {"Edges", Kind::Edges, 3},
    {"Triangles", Kind::Triangles, 4},
    {"Quadrilaterals", Kind::Quadrilaterals, 5},
    {"Tetrahedra", Kind::Tetrahedra, 5},
    // Cells that are not simplices, and higher-order elements.
    {"Hexahedra", Kind::Skipped, 9},
    {"Prisms", Kind::Skipped, 7},
    {"Pyramids", Kind::Skipped, 6},
    {"EdgesP2", Kind::Skipped, 4},
    {"TrianglesP2", Kind::Skipped, 7},
    {"QuadrilateralsQ2", Kind::Skipped, 10},
    {"TetrahedraP2", Kind::Skipped, 11},
    {"HexahedraQ2", Kind::Skipped, 28},
    // Attributes of vertices and elements.
    {"Corners", Kind::Skipped, 1},
    {"Ridges", Kind::Skipped, 1},
    {"RequiredVertices", Kind::Skipped, 1},
    {"RequiredEdges", Kind::Skipped, 1},
    {"RequiredTriangles", Kind::Skipped, 1},
    {"RequiredQuadrilaterals", Kind::Skipped, 1},
    {"RequiredTetrahedra", Kind::Skipped, 1},
    {"Normals", Kind::Skipped, 3},
    {"Tangents", Kind::Skipped, 3},
    {"NormalAtVertices", Kind::Skipped, 2},
    {"NormalAtTriangleVertices", Kind::Skipped, 3},
    {"NormalAtQuadrilateralVertices", Kind::Skipped, 3},
    {"TangentAtEdgeVertices", Kind::Skipped, 3},
};

const Section* findSection(std::string_view keyword) {
  for (const Section& section : kSections) {
    if (equalsIgnoringCase(section.keyword, keyword)) return &section;
  }
  return nullptr;
}

const char* itemName(Kind kind) {
  switch (kind) {
    case Kind::Vertices: return "vertex";
    case Kind::Edges: return "edge";
    case Kind::Triangles: return "triangle";
    case Kind::Quadrilaterals: return "quadrilateral";
    case Kind::Tetrahedra: return "tetrahedron";
    case Kind::Skipped: break;
  }
  return "item";
}

size_t arity(Kind kind) {
  switch (kind) {
    case Kind::Edges: return 2;
    case Kind::Triangles: return 3;
    case Kind::Quadrilaterals: return 4;
    case Kind::Tetrahedra: return 4;
    case Kind::Vertices: case Kind::Skipped: break;
  }
  return 0;
}

class MeditReader {
 public:
  MeditReader(const uint8_t* data, size_t size, Complex& out, bool keepDoubles)
      : scanner_(data, size, {/*commaSeparates=*/false,
                              /*hashComments=*/true}),
        out_(out),
        keepDoubles_(keepDoubles) {}

  Status read(Notes& notes) {
    std::string_view keyword;
    bool ended = false;
    while (!ended && scanner_.nextTokenAcrossLines(keyword)) {
      Status status;
      if (equalsIgnoringCase(keyword, "End")) {
        ended = true;
      } else if (equalsIgnoringCase(keyword, "MeshVersionFormatted")) {
        status = readVersion();
      } else if (equalsIgnoringCase(keyword, "Dimension")) {
        status = readDimension();
      } else if (const Section* section = findSection(keyword)) {
        status = readSection(*section);
      } else {
        status = error("unknown Medit keyword " + quoted(keyword) +
                       ": cannot tell how much of the file it takes");
      }
      if (!status.ok()) return status;
    }
    if (!sawVersion_) {
      return inputError("not a Medit file: no MeshVersionFormatted keyword");
    }
    std::string_view token;
    if (ended && scanner_.nextTokenAcrossLines(token)) {
      notes.push_back("ignored what follows End (from line " +
                      std::to_string(scanner_.lineNumber()) + ")");
    }
    if (doublePrecision_ && !keepDoubles_) {
      notes.push_back(
          "coordinates of MeshVersionFormatted 2 (double precision) were "
          "rounded to float32 (exact encoding keeps them)");
    }
    split_.addNote(notes);
    keepLabels(notes);
    if (Status status = keepVertexReferences(); !status.ok()) return status;
    for (const std::string& skipped : skipped_) notes.push_back(skipped);
    return Status::success();
  }

 private:
  Status error(const std::string& message) const {
    return lineError(scanner_.lineNumber(), message);
  }

  // The value after a keyword, which may be on the next line.
  Status keywordValue(std::string_view keyword, std::string_view& token) {
    if (!scanner_.nextTokenAcrossLines(token)) {
      return error("the file ends after " + std::string(keyword));
    }
    return Status::success();
  }

  Status readVersion() {
    std::string_view token;
    if (Status status = keywordValue("MeshVersionFormatted", token);
        !status.ok()) {
      return status;
    }
    int64_t version = 0;
    if (!parseInteger(token, version) || version < 1 || version > 4) {
      return error("MeshVersionFormatted " + quoted(token) +
                   " is not a version from 1 to 4");
    }
    sawVersion_ = true;
    doublePrecision_ = version >= 2;
    return Status::success();
  }

  Status readDimension() {
    std::string_view token;
    if (Status status = keywordValue("Dimension", token); !status.ok()) {
      return status;
    }
    int64_t dimension = 0;
    if (!parseInteger(token, dimension)) {
      return error("Dimension " + quoted(token) + " is not a number");
    }
    if (dimension != 3) {
      return error("Dimension " + std::to_string(dimension) +
                   " meshes are not supported, only Dimension 3");
    }
    return Status::success();
  }

  Status readSection(const Section& section) {
    if (!sawVersion_) {
      return error("not a Medit file: " + std::string(section.keyword) +
                   " comes before MeshVersionFormatted");
    }
    std::string_view token;
    if (Status status = keywordValue(section.keyword, token); !status.ok()) {
      return status;
    }
    uint64_t count = 0;
    if (!parseCount(token, count)) {
      return error(std::string(section.keyword) + " count " + quoted(token) +
                   " is not a count");
    }
    // Every value takes at least a digit and a separator.
    uint64_t budget = scanner_.remainingBytes() + 1;
    if (!takeFromBudget(count, 2 * section.valuesPerItem, budget)) {
      return error(std::string(section.keyword) + " declares " +
                   counted(count, "item", "items") +
                   ", more than the rest of the file can hold");
    }
    switch (section.kind) {
      case Kind::Vertices: return readVertices(count);
      case Kind::Skipped: return skipItems(section, count);
      default: return readElements(section.kind, count);
    }
  }

  Status readVertices(uint64_t count) {
    if (sawVertices_) return error("a second Vertices section");
    sawVertices_ = true;
    if (count > std::numeric_limits<uint32_t>::max()) {
      return error("more vertices than 32-bit indices can address");
    }
    out_.positions.reserve(3 * count);
    vertexReferences_.reserve(count);
    // Double precision files keep their doubles too when asked to.
    const bool doubles = doublePrecision_ && keepDoubles_;
    for (uint64_t v = 0; v < count; ++v) {
      float xyz[3];
      for (float& value : xyz) {
        std::string_view token;
        if (Status status = nextValue(Kind::Vertices, v, token); !status.ok()) {
          return status;
        }
        double exact = 0;
        if (doubles ? !parseDouble(token, exact) : !parseFloat(token, value)) {
          return error("vertex " + std::to_string(v) + ": " + quoted(token) +
                       " is not a number");
        }
        if (doubles) {
          value = static_cast<float>(exact);
          out_.positions64.push_back(exact);
        }
      }
      int64_t reference = 0;
      if (Status status = readReference(Kind::Vertices, v, reference); !status.ok()) {
        return status;
      }
      out_.positions.insert(out_.positions.end(), xyz, xyz + 3);
      vertexReferences_.push_back(reference);
    }
    return Status::success();
  }

  Status readElements(Kind kind, uint64_t count) {
    if (count > 0 && !sawVertices_) {
      return error(std::string(itemName(kind)) +
                   "s come before the Vertices they refer to");
    }
    const size_t size = arity(kind);
    std::vector<uint32_t>& target =
        kind == Kind::Edges        ? out_.edges
        : kind == Kind::Tetrahedra ? out_.tetrahedra
                                   : out_.triangles;
    target.reserve(target.size() +
                   (kind == Kind::Quadrilaterals ? 6 : size) * count);
    const uint64_t vertexCount = out_.vertexCount();
    uint32_t corners[4];
    for (uint64_t item = 0; item < count; ++item) {
      for (size_t k = 0; k < size; ++k) {
        std::string_view token;
        if (Status status = nextValue(kind, item, token); !status.ok()) {
          return status;
        }
        int64_t value = 0;
        if (!parseInteger(token, value)) {
          return error(std::string(itemName(kind)) + " " +
                       std::to_string(item) + ": " + quoted(token) +
                       " is not a vertex index");
        }
        if (value < 1 || static_cast<uint64_t>(value) > vertexCount) {
          return error(std::string(itemName(kind)) + " " +
                       std::to_string(item) + ": vertex index " +
                       std::to_string(value) + " is out of range (1 to " +
                       std::to_string(vertexCount) + ")");
        }
        corners[k] = static_cast<uint32_t>(value - 1);
      }
      int64_t reference = 0;
      if (Status status = readReference(kind, item, reference); !status.ok()) {
        return status;
      }
      if (reference < std::numeric_limits<int32_t>::min() || reference > std::numeric_limits<int32_t>::max()) {
        return error(std::string(itemName(kind)) + " " + std::to_string(item) + ": reference " +
                     std::to_string(reference) + " does not fit 32 bits");
      }
      if (kind == Kind::Quadrilaterals) {
        split_.append(corners, 4, target);
      } else {
        target.insert(target.end(), corners, corners + size);
      }
      // A quadrilateral's triangles all take its reference.
      const int d = kind == Kind::Edges ? 1 : kind == Kind::Tetrahedra ? 3 : 2;
      references_.of(d).resize(target.size() / size_t(d + 1), int32_t(reference));
      nonzeroReferences_ |= reference != 0;
    }
    return Status::success();
  }

  Status skipItems(const Section& section, uint64_t count) {
    for (uint64_t item = 0; item < count; ++item) {
      for (uint64_t k = 0; k < section.valuesPerItem; ++k) {
        std::string_view token;
        if (!scanner_.nextTokenAcrossLines(token)) {
          return error("the file ends inside " + std::string(section.keyword) +
                       " item " + std::to_string(item));
        }
      }
    }
    if (count > 0) {
      skipped_.push_back("skipped " + std::to_string(count) + " " +
                         std::string(section.keyword) +
                         " (not part of a simplicial complex)");
    }
    return Status::success();
  }

  Status nextValue(Kind kind, uint64_t item, std::string_view& token) {
    if (!scanner_.nextTokenAcrossLines(token)) {
      return error("the file ends inside " + std::string(itemName(kind)) +
                   " " + std::to_string(item));
    }
    return Status::success();
  }

  Status readReference(Kind kind, uint64_t item, int64_t& reference) {
    std::string_view token;
    if (Status status = nextValue(kind, item, token); !status.ok()) {
      return status;
    }
    if (!parseInteger(token, reference)) {
      return error(std::string(itemName(kind)) + " " + std::to_string(item) +
                   ": reference " + quoted(token) + " is not an integer");
    }
    return Status::success();
  }

  // The vertices' references as the attribute `ref`, of the narrowest
  // integer type that holds them, unless all are 0.
  Status keepVertexReferences() {
    bool any = false;
    for (const int64_t r : vertexReferences_) any = any || r != 0;
    if (!any) return Status::success();
    AttributeType type;
    if (!narrowestIntegerType(vertexReferences_, type))
      return inputError("vertex references beyond the 32-bit range");
    out_.attributes.push_back(integerAttribute("ref", type, vertexReferences_));
    return Status::success();
  }

  // Sorts the first n (2 or 3) ids.
  static void sortFirst(std::array<uint32_t, 3>& ids, size_t n) {
    if (ids[0] > ids[1]) std::swap(ids[0], ids[1]);
    if (n < 3) return;
    if (ids[1] > ids[2]) std::swap(ids[1], ids[2]);
    if (ids[0] > ids[1]) std::swap(ids[0], ids[1]);
  }

  // Element references become labels when any is nonzero (all zero say
  // nothing). Those of edges and triangles that are faces of listed
  // triangles or tetrahedra are counted in a note: the encoder drops such
  // faces.
  void keepLabels(Notes& notes) {
    if (!nonzeroReferences_) return;
    out_.labels = std::move(references_);
    uint64_t dropped = 0;
    std::vector<std::array<uint32_t, 3>> faces;  // sorted vertex ids, 0-padded
    for (int d = 2; d >= 1; --d) {
      const std::vector<uint32_t>& higher = d == 2 ? out_.tetrahedra : out_.triangles;
      const size_t arity = size_t(d + 2);
      faces.clear();
      for (size_t i = 0; i < higher.size(); i += arity)
        for (size_t skip = 0; skip < arity; ++skip) {
          std::array<uint32_t, 3> face{0, 0, 0};
          size_t n = 0;
          for (size_t k = 0; k < arity; ++k)
            if (k != skip) face[n++] = higher[i + k];
          sortFirst(face, n);
          faces.push_back(face);
        }
      std::sort(faces.begin(), faces.end());
      const std::vector<uint32_t>& list = d == 2 ? out_.triangles : out_.edges;
      const std::vector<int32_t>& labels = out_.labels.of(d);
      for (size_t i = 0; i < labels.size(); ++i) {
        if (labels[i] == 0) continue;
        std::array<uint32_t, 3> simplex{0, 0, 0};
        std::copy(list.begin() + std::ptrdiff_t(i * size_t(d + 1)), list.begin() + std::ptrdiff_t((i + 1) * size_t(d + 1)),
                  simplex.begin());
        sortFirst(simplex, size_t(d + 1));
        dropped += std::binary_search(faces.begin(), faces.end(), simplex);
      }
    }
    addCountNote(notes, "dropped the nonzero references of ", dropped, "edge or triangle", "edges and triangles",
                 dropped == 1 ? " that is a face of a listed triangle or tetrahedron"
                              : " that are faces of listed triangles or tetrahedra");
  }

  TextScanner scanner_;
  Complex& out_;
  const bool keepDoubles_;
  bool sawVersion_ = false;
  bool sawVertices_ = false;
  bool doublePrecision_ = false;
  SimplexLabels references_;  // of the elements, one per simplex
  bool nonzeroReferences_ = false;
  std::vector<int64_t> vertexReferences_;
  PolygonSplit split_;
  std::vector<std::string> skipped_;
};

}  // namespace

Status readMedit(const uint8_t* data, size_t size, Complex& out,
                 Notes& notes, bool keepDoubles) {
  return MeditReader(data, size, out, keepDoubles).read(notes);
}

bool meditHoldsAttribute(const VertexAttribute& a) {
  return a.name == "ref" && a.components == 1 && a.type != AttributeType::Float32;
}

Status writeMedit(const Complex& complex, std::vector<uint8_t>& out) {
  if (!pointsAreImplicit(complex)) {
    return Status::error(ErrorCode::InvalidArgument,
                         "Medit cannot hold explicit points on vertices that "
                         "simplices use");
  }
  TextOut text(out);
  // Version 2 declares double precision, for positions64.
  text.word(complex.positions64.empty() ? "MeshVersionFormatted 1" : "MeshVersionFormatted 2").endLine();
  text.word("Dimension 3").endLine();
  text.word("Vertices").endLine();
  text.integer(complex.vertexCount()).endLine();
  const VertexAttribute* references = findAttribute(complex, "ref");
  for (size_t v = 0; v < complex.vertexCount(); ++v) {
    text.point(complex, v);
    if (references) {
      text.value(references->type, &references->values[v * references->valueBytes()]);
    } else {
      text.integer(0);
    }
    text.endLine();
  }
  const struct {
    const char* keyword;
    const std::vector<uint32_t>& indices;
    size_t arity;
    const std::vector<int32_t>& labels;  // the references, if any
  } sections[] = {{"Edges", complex.edges, 2, complex.labels.edges},
                  {"Triangles", complex.triangles, 3, complex.labels.triangles},
                  {"Tetrahedra", complex.tetrahedra, 4, complex.labels.tetrahedra}};
  for (const auto& section : sections) {
    if (section.indices.empty()) continue;
    text.word(section.keyword).endLine();
    text.integer(section.indices.size() / section.arity).endLine();
    for (size_t i = 0; i < section.indices.size(); i += section.arity) {
      for (size_t k = 0; k < section.arity; ++k) {
        text.integer(uint64_t{section.indices[i + k]} + 1);  // 1-based
      }
      if (section.labels.empty()) text.integer(0);
      else text.word(std::to_string(section.labels[i / section.arity]));
      text.endLine();
    }
  }
  text.word("End").endLine();
  return Status::success();
}

}  // namespace kdmesh::io::detail
