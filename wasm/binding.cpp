// The C API that the JavaScript wrapper (web/kdmesh.js) calls: a thin layer
// over kdmesh::Decoder that keeps the bytes to push and the last snapshot in
// WebAssembly memory, where JavaScript reads them through typed arrays.
//
// Lifetime: pointers returned by kdm_input stay valid until the next
// kdm_input or kdm_destroy; pointers into the snapshot until the next
// kdm_snapshot or kdm_destroy.
#include <emscripten/emscripten.h>
#include <malloc.h>

#include <cstdint>
#include <new>
#include <vector>

#include "kdmesh/kdmesh.h"

namespace {

struct KdmDecoder {
  explicit KdmDecoder(const kdmesh::DecoderOptions& options) : decoder(options) {}
  kdmesh::Decoder decoder;
  std::vector<uint8_t> input;
  kdmesh::Complex snapshot;
  kdmesh::Status status;

  int remember(kdmesh::Status s) {
    status = std::move(s);
    return int(status.code);
  }
};

const std::vector<uint32_t>& indices(const kdmesh::Complex& c, int dimension) {
  switch (dimension) {
    case 0: return c.points;
    case 1: return c.edges;
    case 2: return c.triangles;
    default: return c.tetrahedra;
  }
}

}  // namespace

extern "C" {

EMSCRIPTEN_KEEPALIVE KdmDecoder* kdm_create(uint32_t maxVertices, uint32_t maxSimplices,
                                            uint32_t maxChunkBytes) {
  kdmesh::DecoderOptions options;
  if (maxVertices) options.limits.maxVertices = maxVertices;
  if (maxSimplices) options.limits.maxSimplices = maxSimplices;
  if (maxChunkBytes) options.limits.maxChunkBytes = maxChunkBytes;
  return new (std::nothrow) KdmDecoder(options);
}

EMSCRIPTEN_KEEPALIVE void kdm_destroy(KdmDecoder* d) { delete d; }

// Room for the next `size` bytes to push.
EMSCRIPTEN_KEEPALIVE uint8_t* kdm_input(KdmDecoder* d, uint32_t size) {
  d->input.resize(size);
  return d->input.data();
}

// Pushes the first `size` bytes of the input buffer; returns an ErrorCode.
EMSCRIPTEN_KEEPALIVE int kdm_push(KdmDecoder* d, uint32_t size) {
  return d->remember(d->decoder.push(d->input.data(), size));
}

EMSCRIPTEN_KEEPALIVE int kdm_finish(KdmDecoder* d) { return d->remember(d->decoder.finish()); }

EMSCRIPTEN_KEEPALIVE const char* kdm_error_message(KdmDecoder* d) { return d->status.message.c_str(); }

EMSCRIPTEN_KEEPALIVE const char* kdm_error_name(int code) {
  return kdmesh::errorCodeName(kdmesh::ErrorCode(code));
}

EMSCRIPTEN_KEEPALIVE int kdm_has_header(KdmDecoder* d) { return d->decoder.hasHeader(); }

// Header fields into `out` (doubles): vertexCount, maxDimension, simplex
// counts 0..3, quantization (0 grid, 1 float32), bits, step, totalBytes,
// chunkCount.
EMSCRIPTEN_KEEPALIVE void kdm_header(KdmDecoder* d, double* out) {
  const kdmesh::Header& h = d->decoder.header();
  const double fields[] = {double(h.vertexCount),      double(h.maxDimension),    double(h.simplexCounts[0]),
                           double(h.simplexCounts[1]), double(h.simplexCounts[2]), double(h.simplexCounts[3]),
                           double(h.quantization),     double(h.bits),            h.step,
                           double(h.totalBytes()),     double(h.chunkCount)};
  for (size_t i = 0; i < sizeof fields / sizeof fields[0]; ++i) out[i] = fields[i];
}

// Progress into `out` (doubles): bytesReceived, bytesConsumed, bytesExpected,
// chunksApplied, level, cellCount, complete, errorBound.
EMSCRIPTEN_KEEPALIVE void kdm_progress(KdmDecoder* d, double* out) {
  const kdmesh::DecodeProgress p = d->decoder.progress();
  const double fields[] = {double(p.bytesReceived), double(p.bytesConsumed), double(p.bytesExpected),
                           double(p.chunksApplied), double(p.level),         double(p.cellCount),
                           p.complete ? 1.0 : 0.0,  d->decoder.errorBound()};
  for (size_t i = 0; i < sizeof fields / sizeof fields[0]; ++i) out[i] = fields[i];
}

EMSCRIPTEN_KEEPALIVE void kdm_snapshot(KdmDecoder* d) { d->decoder.snapshot(d->snapshot); }
EMSCRIPTEN_KEEPALIVE uint32_t kdm_vertex_count(KdmDecoder* d) { return uint32_t(d->snapshot.vertexCount()); }
EMSCRIPTEN_KEEPALIVE const float* kdm_positions(KdmDecoder* d) { return d->snapshot.positions.data(); }
// Number of indices (not simplices) of dimension 0..3 in the snapshot.
EMSCRIPTEN_KEEPALIVE uint32_t kdm_index_count(KdmDecoder* d, int dimension) {
  return uint32_t(indices(d->snapshot, dimension).size());
}
EMSCRIPTEN_KEEPALIVE const uint32_t* kdm_indices(KdmDecoder* d, int dimension) {
  return indices(d->snapshot, dimension).data();
}
EMSCRIPTEN_KEEPALIVE uint32_t kdm_parent_count(KdmDecoder* d) { return uint32_t(d->decoder.vertexParents().size()); }
EMSCRIPTEN_KEEPALIVE const uint32_t* kdm_parents(KdmDecoder* d) { return d->decoder.vertexParents().data(); }

// Bytes of WebAssembly heap in use: lets tests prove that decoders free
// everything they allocate.
EMSCRIPTEN_KEEPALIVE uint32_t kdm_heap_in_use() { return uint32_t(mallinfo().uordblks); }

}  // extern "C"
