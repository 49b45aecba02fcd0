// libFuzzer target: the stream decoder on arbitrary bytes, whole and pushed
// in pieces whose sizes come from the input itself, with snapshots between
// pieces. Any crash, leak, hang or sanitizer report is a bug.
#include <cstddef>
#include <cstdint>

#include "kdmesh/kdmesh.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  kdmesh::DecoderOptions options;
  // Small caps keep each run fast; hostile headers still get validated.
  options.limits.maxVertices = 1u << 16;
  options.limits.maxSimplices = 1u << 18;
  options.limits.maxChunkBytes = 1u << 16;

  kdmesh::Complex out;
  (void)kdmesh::decode(data, size, out, /*allowPrefix=*/true, options);

  kdmesh::Decoder decoder(options);
  size_t at = 0;
  for (size_t piece = 0; at < size; ++piece) {
    const size_t length = 1 + (data[piece % size] % 97);
    const size_t take = length < size - at ? length : size - at;
    if (!decoder.push(data + at, take).ok()) break;
    at += take;
    if (piece % 7 == 0) {
      decoder.snapshot(out);
      (void)decoder.errorBound();
      (void)decoder.vertexParents();
    }
  }
  (void)decoder.finish();
  decoder.snapshot(out);
  return 0;
}
