// Format dispatch and file access for kdmesh/io.h.
#include <cerrno>
#include <cstdio>

#include "io/io_internal.h"

namespace kdmesh::io {

using detail::Bytes;
using detail::ByteStream;
using detail::FilePtr;
using detail::Input;
using detail::inputError;

namespace {

Status fileError(const char* action, const std::string& path) {
  return detail::fileError(action, path, errno);
}

bool isBlank(uint8_t byte) {
  switch (byte) {
    case ' ': case '\t': case '\r': case '\n': case '\v': case '\f':
      return true;
    default:
      return false;
  }
}

// Looks at the first block, and past it only while the bytes stay blank, so
// that a large file is not read to tell that it is not empty.
bool isBlank(Input& input) {
  const Bytes head = input.head();
  for (size_t i = 0; i < head.size; ++i) {
    if (!isBlank(head.data[i])) return false;
  }
  if (input.headIsWhole()) return true;
  ByteStream rest = input.stream(head.size);
  while (const uint8_t* byte = rest.take(1)) {
    if (!isBlank(*byte)) return false;
  }
  return true;
}

// Names the first simplex with an index past the last vertex, so that no
// writer has to guard against them.
Status checkIndices(const std::vector<uint32_t>& indices, size_t arity,
                    size_t vertexCount, const char* simplexName) {
  if (indices.size() % arity != 0) {
    return inputError(std::string(simplexName) + " indices hold " +
                      std::to_string(indices.size()) +
                      " values, not a multiple of " + std::to_string(arity));
  }
  for (size_t i = 0; i < indices.size(); ++i) {
    if (indices[i] >= vertexCount) {
      return inputError(std::string(simplexName) + " " +
                        std::to_string(i / arity) + " refers to vertex " +
                        std::to_string(indices[i]) + ", but there " +
                        (vertexCount == 1 ? "is " : "are ") +
                        detail::counted(vertexCount, "vertex", "vertices"));
    }
  }
  return Status::success();
}

Status checkWritable(const Complex& complex) {
  if (complex.positions.size() % 3 != 0) {
    return inputError("positions hold " +
                      std::to_string(complex.positions.size()) +
                      " floats, not a multiple of 3");
  }
  if (!complex.positions64.empty() && complex.positions64.size() != complex.positions.size()) {
    return inputError("positions64 hold " + std::to_string(complex.positions64.size()) + " doubles for " +
                      std::to_string(complex.positions.size()) + " floats");
  }
  const size_t vertexCount = complex.vertexCount();
  for (Status status :
       {checkIndices(complex.points, 1, vertexCount, "point"),
        checkIndices(complex.edges, 2, vertexCount, "edge"),
        checkIndices(complex.triangles, 3, vertexCount, "triangle"),
        checkIndices(complex.tetrahedra, 4, vertexCount, "tetrahedron")}) {
    if (!status.ok()) return status;
  }
  return Status::success();
}

Status unknownFormat(const std::string& path) {
  return Status::error(ErrorCode::InvalidArgument,
                       "cannot tell the format of " + path +
                           " from its extension (expected .ply, .obj, "
                           ".off, .xyz, .txt, .pts, .stl, .mesh, .node, .ele "
                           "or .vtk)");
}

// The extension after the last dot of the file name, lower-cased; empty when
// there is none.
std::string extensionOf(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  const size_t slash = path.find_last_of("/\\");
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) {
    return std::string();
  }
  std::string extension = path.substr(dot + 1);
  for (char& c : extension) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return extension;
}

// Checks the first bytes of a file before the rest is read: a PLY or VTK
// file of another kind is refused without reading all of it.
using HeadCheck = Status (*)(const uint8_t* head, size_t size);

HeadCheck headCheckOf(Format format) {
  switch (format) {
    case Format::Ply: return detail::checkPlySignature;
    case Format::Vtk: return detail::checkVtkSignature;
    default: return nullptr;
  }
}

// Runs the reader of `format` on `input`, which is not blank.
Status readFormat(Format format, Input& input, Complex& out, Notes& notes,
                  const ReadOptions& options) {
  if (const HeadCheck check = headCheckOf(format)) {
    const Bytes head = input.head();
    if (Status status = check(head.data, head.size); !status.ok()) {
      return status;
    }
  }
  // STL and PLY read what they need; the others parse all the text.
  if (format == Format::Stl) return detail::readStl(input, out, notes, options.weld);
  if (format == Format::Ply) return detail::readPly(input, out, notes, options.keepDoubles);
  const Bytes all = input.whole();
  switch (format) {
    case Format::Obj: return detail::readObj(all.data, all.size, out, notes, options.keepDoubles);
    case Format::Off: return detail::readOff(all.data, all.size, out, notes, options.keepDoubles);
    case Format::Xyz: return detail::readXyz(all.data, all.size, out, notes, options.keepDoubles);
    case Format::Medit:
      return detail::readMedit(all.data, all.size, out, notes, options.keepDoubles);
    case Format::Vtk: return detail::readVtk(all.data, all.size, out, notes, options.keepDoubles);
    case Format::TetGen: {  // one buffer: the .node file alone
      uint32_t firstIndex = 0;
      return detail::readTetgenNode(all.data, all.size, out, notes,
                                    firstIndex, options.keepDoubles);
    }
    default: break;
  }
  return Status::error(ErrorCode::InvalidArgument, "unknown file format");
}

// Reads `input` in `format` into `out`, which it empties on error. A failed
// read of the file is the error even when the reader saw it as truncation.
Status readInput(Format format, Input& input, Complex& out, Notes& notes,
                 const ReadOptions& options) {
  out = Complex{};
  Status status = isBlank(input)
                      ? inputError("file is empty")
                      : readFormat(format, input, out, notes, options);
  if (Status readError = input.readError(); !readError.ok()) {
    status = readError;
  }
  if (!status.ok()) {
    out = Complex{};
  } else if (options.weld && format != Format::Stl) {  // STL welds as it reads
    detail::weldVertices(out, notes);
  }
  return status;
}

}  // namespace

Status readBytes(const std::string& path, std::vector<uint8_t>& bytes) {
  bytes.clear();
  FilePtr file(std::fopen(path.c_str(), "rb"));
  if (!file) return fileError("cannot open", path);
  uint8_t block[1 << 16];
  for (size_t got; (got = std::fread(block, 1, sizeof block, file.get())) > 0;)
    bytes.insert(bytes.end(), block, block + got);
  if (std::ferror(file.get())) return fileError("cannot read", path);
  return Status::success();
}

namespace {

Status writeWholeFile(const std::string& path,
                      const std::vector<uint8_t>& bytes) {
  FilePtr file(std::fopen(path.c_str(), "wb"));
  if (!file) return fileError("cannot open", path);
  const size_t written = std::fwrite(bytes.data(), 1, bytes.size(), file.get());
  // fclose flushes, so its result decides whether the bytes reached the file.
  if (written != bytes.size() || std::fclose(file.release()) != 0) {
    return fileError("cannot write", path);
  }
  return Status::success();
}

// x.node and x.ele beside a path that names either, with the extension in
// the case of the one given.
struct TetgenPaths {
  std::string node, ele;
  bool givenEle = false;
};

TetgenPaths tetgenPaths(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  const std::string stem = path.substr(0, dot);
  const bool upper = dot + 1 < path.size() && path[dot + 1] >= 'A' &&
                     path[dot + 1] <= 'Z';
  TetgenPaths paths;
  paths.node = stem + (upper ? ".NODE" : ".node");
  paths.ele = stem + (upper ? ".ELE" : ".ele");
  paths.givenEle = extensionOf(path) == "ele";
  return paths;
}

// An error in the file the user did not name says which file it is in.
Status inFile(Status status, const std::string& file,
              const std::string& given) {
  if (!status.ok() && file != given) {
    status.message = file + ": " + status.message;
  }
  return status;
}

// Opens one file of a TetGen pair and checks that it is not blank.
Status openTetgenFile(const std::string& file, const std::string& given,
                      Input& input, bool* missing = nullptr) {
  if (Status status = Input::open(file, input, missing); !status.ok()) {
    return status;
  }
  const bool blank = isBlank(input);
  if (Status status = input.readError(); !status.ok()) return status;
  return blank ? inFile(inputError("file is empty"), file, given)
               : Status::success();
}

Status readTetgenFiles(const std::string& path, Complex& out, Notes& notes, bool keepDoubles) {
  const TetgenPaths paths = tetgenPaths(path);
  Input node;
  if (Status status = openTetgenFile(paths.node, path, node); !status.ok()) {
    return status;
  }
  uint32_t firstIndex = 0;
  Bytes bytes = node.whole();
  Status status = detail::readTetgenNode(bytes.data, bytes.size, out, notes,
                                         firstIndex, keepDoubles);
  if (Status readError = node.readError(); !readError.ok()) return readError;
  if (!status.ok()) return inFile(status, paths.node, path);

  Input ele;
  bool missing = false;
  status = openTetgenFile(paths.ele, path, ele, &missing);
  if (!status.ok()) {
    if (!missing || paths.givenEle) return status;
    notes.push_back("no " + paths.ele + ": read the nodes as a point cloud");
    return Status::success();
  }
  bytes = ele.whole();
  status = detail::readTetgenEle(bytes.data, bytes.size, firstIndex, out,
                                 notes);
  if (Status readError = ele.readError(); !readError.ok()) return readError;
  return inFile(status, paths.ele, path);
}

Status writeTetgenFiles(const std::string& path, const Complex& complex) {
  if (Status status = checkWritable(complex); !status.ok()) return status;
  const TetgenPaths paths = tetgenPaths(path);
  std::vector<uint8_t> node, ele;
  if (Status status = detail::writeTetgenNode(complex, node); !status.ok()) {
    return status;
  }
  const bool writeEle = !complex.tetrahedra.empty() || paths.givenEle;
  if (writeEle) {
    if (Status status = detail::writeTetgenEle(complex, ele); !status.ok()) {
      return status;
    }
  }
  if (Status status = writeWholeFile(paths.node, node); !status.ok()) {
    return status;
  }
  return writeEle ? writeWholeFile(paths.ele, ele) : Status::success();
}

}  // namespace

Format formatFromPath(const std::string& path) {
  const std::string extension = extensionOf(path);
  if (extension == "ply") return Format::Ply;
  if (extension == "obj") return Format::Obj;
  if (extension == "off") return Format::Off;
  if (extension == "xyz" || extension == "txt" || extension == "pts") {
    return Format::Xyz;
  }
  if (extension == "stl") return Format::Stl;
  if (extension == "mesh") return Format::Medit;
  if (extension == "node" || extension == "ele") return Format::TetGen;
  if (extension == "vtk") return Format::Vtk;
  return Format::Unknown;
}

const char* formatName(Format format) {
  switch (format) {
    case Format::Ply: return "ply";
    case Format::Obj: return "obj";
    case Format::Off: return "off";
    case Format::Xyz: return "xyz";
    case Format::Stl: return "stl";
    case Format::Medit: return "medit";
    case Format::TetGen: return "tetgen";
    case Format::Vtk: return "vtk";
    case Format::Unknown: break;
  }
  return "unknown";
}

bool holdsLabels(Format format) {
  return format == Format::Ply || format == Format::Medit || format == Format::TetGen || format == Format::Obj ||
         format == Format::Vtk;
}

bool holdsAttribute(Format format, const VertexAttribute& a) {
  switch (format) {
    case Format::Ply: return true;
    case Format::Obj: return detail::objHoldsAttribute(a);
    case Format::Vtk: return detail::vtkHoldsAttribute(a);
    case Format::Medit: return detail::meditHoldsAttribute(a);
    case Format::TetGen: return detail::tetgenHoldsAttribute(a);
    default: return false;
  }
}

Status readMemory(Format format, const uint8_t* data, size_t size,
                  Complex& out, Notes& notes, const ReadOptions& options) {
  out = Complex{};
  if (format == Format::Unknown) {
    return Status::error(ErrorCode::InvalidArgument, "unknown file format");
  }
  Input input(data, size);
  return readInput(format, input, out, notes, options);
}

Status readFile(const std::string& path, Complex& out, Notes& notes,
                const ReadOptions& options) {
  const Format format = formatFromPath(path);
  if (format == Format::Unknown) return unknownFormat(path);
  if (format == Format::TetGen) {
    out = Complex{};
    Status status = readTetgenFiles(path, out, notes, options.keepDoubles);
    if (!status.ok()) {
      out = Complex{};
    } else if (options.weld) {
      detail::weldVertices(out, notes);
    }
    return status;
  }
  Input input;
  if (Status status = Input::open(path, input); !status.ok()) return status;
  return readInput(format, input, out, notes, options);
}

// A format refuses a complex with attributes it cannot hold rather than
// drop them silently.
Status checkAttributesWritable(Format format, const Complex& complex) {
  std::string names;
  for (const VertexAttribute& a : complex.attributes)
    if (!holdsAttribute(format, a)) names += (names.empty() ? "" : ", ") + a.name;
  if (names.empty()) return Status::success();
  return Status::error(ErrorCode::InvalidArgument, std::string(formatName(format)) +
                                                       " cannot hold the vertex attributes " + names +
                                                       ": write PLY to keep them");
}

Status checkLabelsWritable(Format format, const Complex& complex) {
  if (holdsLabels(format) || complex.labels.empty()) return Status::success();
  return Status::error(ErrorCode::InvalidArgument, std::string(formatName(format)) +
                                                       " cannot hold simplex labels: write PLY, OBJ, Medit, TetGen or VTK to keep them");
}

Status writeMemory(Format format, const Complex& complex,
                   std::vector<uint8_t>& out, const WriteOptions& options) {
  out.clear();
  if (format == Format::Unknown) {
    return Status::error(ErrorCode::InvalidArgument, "unknown file format");
  }
  if (format == Format::Stl) {
    return Status::error(ErrorCode::InvalidArgument,
                         "writing STL is not supported");
  }
  if (Status status = checkWritable(complex); !status.ok()) return status;
  if (Status status = checkAttributesWritable(format, complex); !status.ok()) return status;
  if (Status status = checkLabelsWritable(format, complex); !status.ok()) return status;
  Status status;
  switch (format) {
    case Format::Ply: status = detail::writePly(complex, out, options); break;
    case Format::Obj: status = detail::writeObj(complex, out); break;
    case Format::Off: status = detail::writeOff(complex, out); break;
    case Format::Xyz: status = detail::writeXyz(complex, out); break;
    case Format::Medit: status = detail::writeMedit(complex, out); break;
    case Format::Vtk: status = detail::writeVtk(complex, out); break;
    case Format::TetGen:
      if (!complex.tetrahedra.empty()) {
        status = Status::error(
            ErrorCode::InvalidArgument,
            "writeMemory gives only the TetGen .node file, which cannot hold "
            "tetrahedra; writeFile writes the .ele file beside it");
      } else {
        status = detail::writeTetgenNode(complex, out);
      }
      break;
    case Format::Stl: case Format::Unknown: break;
  }
  if (!status.ok()) out.clear();
  return status;
}

Status writeFile(const std::string& path, const Complex& complex,
                 const WriteOptions& options) {
  const Format format = formatFromPath(path);
  if (format == Format::Unknown) return unknownFormat(path);
  if (format == Format::TetGen) {
    if (Status status = checkAttributesWritable(format, complex); !status.ok()) return status;
    return writeTetgenFiles(path, complex);
  }
  std::vector<uint8_t> bytes;
  if (Status status = writeMemory(format, complex, bytes, options);
      !status.ok()) {
    return status;
  }
  return writeWholeFile(path, bytes);
}

namespace detail {

bool pointsAreImplicit(const Complex& complex) {
  if (complex.points.empty()) return true;
  std::vector<uint8_t> used(complex.vertexCount(), 0);
  for (const auto* indices :
       {&complex.edges, &complex.triangles, &complex.tetrahedra}) {
    for (uint32_t vertex : *indices) used[vertex] = 1;
  }
  for (uint32_t point : complex.points) {
    if (used[point]) return false;
  }
  return true;
}

}  // namespace detail
}  // namespace kdmesh::io
