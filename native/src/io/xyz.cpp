// XYZ point clouds: one "x y z" per line, separated by whitespace or commas;
// further columns (normals, colours, intensity) are ignored.
#include "io/io_internal.h"

namespace kdmesh::io::detail {

Status readXyz(const uint8_t* data, size_t size, Complex& out, Notes& notes) {
  TextScanner scanner(data, size, {/*commaSeparates=*/true,
                                   /*hashComments=*/true});
  size_t extraColumnLines = 0;
  while (scanner.nextContentLine()) {
    bool extraColumns = false;
    Status status = readPositionLine(scanner, out.positions, extraColumns);
    if (!status.ok()) return status;
    extraColumnLines += extraColumns;
  }
  addCountNote(notes, "ignored extra columns on ", extraColumnLines,
               "line", "lines");
  return Status::success();
}

Status writeXyz(const Complex& complex, std::vector<uint8_t>& out) {
  if (complex.hasSimplices()) {
    return Status::error(ErrorCode::InvalidArgument,
                         "XYZ holds only points, but the complex has "
                         "edges, triangles or tetrahedra");
  }
  TextOut text(out);
  for (size_t v = 0; v < complex.vertexCount(); ++v) text.point(complex, v).endLine();
  return Status::success();
}

}  // namespace kdmesh::io::detail
