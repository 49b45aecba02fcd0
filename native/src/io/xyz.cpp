// XYZ point clouds: one "x y z" per line, separated by whitespace or commas;
// further columns (normals, colours, intensity) are ignored.
#include "io/io_internal.h"

namespace kdmesh::io::detail {

Status readXyz(const uint8_t* data, size_t size, Complex& out, Notes& notes, bool keepDoubles) {
  TextScanner scanner(data, size, {/*commaSeparates=*/true,
                                   /*hashComments=*/true});
  size_t extraColumnLines = 0;
  bool beyondFloat = false;  // a coordinate that float32 does not hold
  while (scanner.nextContentLine()) {
    bool extraColumns = false;
    Status status = readPositionLine(scanner, out.positions, extraColumns,
                                     keepDoubles ? &out.positions64 : nullptr, &beyondFloat);
    if (!status.ok()) return status;
    extraColumnLines += extraColumns;
  }
  settleDoubles(out, beyondFloat, keepDoubles, notes);
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
