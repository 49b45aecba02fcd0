// libFuzzer target: every file reader of kdmesh/io.h on arbitrary bytes (the
// first byte picks the format and whether vertices are welded), then the
// encoder on whatever was read.
#include <cstddef>
#include <cstdint>

#include "kdmesh/io.h"
#include "kdmesh/kdmesh.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  using kdmesh::io::Format;
  static const Format kFormats[] = {Format::Ply, Format::Obj, Format::Off, Format::Xyz,
                                    Format::Stl, Format::Medit, Format::TetGen, Format::Vtk};
  const Format format = kFormats[data[0] % (sizeof kFormats / sizeof kFormats[0])];
  kdmesh::io::ReadOptions options;
  options.weld = (data[0] & 0x80) != 0;
  kdmesh::Complex complex;
  kdmesh::io::Notes notes;
  if (!kdmesh::io::readMemory(format, data + 1, size - 1, complex, notes, options).ok()) return 0;
  if (complex.vertexCount() > 4096 || complex.simplexCount(2) + complex.simplexCount(3) > 8192) return 0;
  kdmesh::EncodeOptions encode;
  encode.bits = 1 + data[0] % 20;
  const kdmesh::EncodeResult result = kdmesh::encode(complex, encode);
  if (result.status.ok()) {
    kdmesh::Complex decoded;
    if (!kdmesh::decode(result.bytes.data(), result.bytes.size(), decoded).ok()) __builtin_trap();
    if (decoded.vertexCount() != complex.vertexCount()) __builtin_trap();
  }
  return 0;
}
