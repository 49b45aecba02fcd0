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
#include <initializer_list>
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
  // Decoder::errorBound() walks every current cell; it changes only when
  // the header arrives or a chunk is applied, so it is kept until then.
  int64_t boundKey = -2;  // -1: before the header, else chunks applied
  double bound = 0;

  int remember(kdmesh::Status s) {
    status = std::move(s);
    return int(status.code);
  }

  double errorBound(const kdmesh::DecodeProgress& p) {
    const int64_t key = decoder.hasHeader() ? int64_t(p.chunksApplied) : -1;
    if (key != boundKey) {
      bound = decoder.errorBound();
      boundKey = key;
    }
    return bound;
  }
};

// The records JavaScript reads as doubles. Each visit function names every
// field once, beside its value: kdm_layout() describes the records from the
// names, kdm_header() and kdm_progress() write the values in the same order,
// and web/kdmesh.js builds its objects from the description. A field is
// `name` (one value), `name[N]` (N values), `name:bool` (1 or 0) or
// `name:a|b|...` (value i stands for the i-th word).
using Values = std::initializer_list<double>;

template <class Field>
void visitHeader(const kdmesh::Header& h, Field&& field) {
  field("vertexCount", Values{double(h.vertexCount)});
  field("maxDimension", Values{double(h.maxDimension)});
  field("simplexCounts[4]", Values{double(h.simplexCounts[0]), double(h.simplexCounts[1]),
                                   double(h.simplexCounts[2]), double(h.simplexCounts[3])});
  static_assert(int(kdmesh::Quantization::Grid) == 0 && int(kdmesh::Quantization::Float32) == 1);
  field("quantization:grid|float32", Values{double(h.quantization)});
  field("bits", Values{double(h.bits)});
  field("step", Values{h.step});
  field("totalBytes", Values{double(h.totalBytes())});
  field("chunkCount", Values{double(h.chunkCount)});
  field("depth", Values{double(h.depth())});  // kd-tree levels: the last level of a complete stream
  field("attributeCount", Values{double(h.attributeCount)});
  field("labelled:bool", Values{h.labelled ? 1.0 : 0.0});
  field("fastDecode:bool", Values{h.fastDecode ? 1.0 : 0.0});
}

template <class Field>
void visitProgress(const kdmesh::DecodeProgress& p, double errorBound, Field&& field) {
  field("bytesReceived", Values{double(p.bytesReceived)});
  field("bytesConsumed", Values{double(p.bytesConsumed)});
  field("bytesExpected", Values{double(p.bytesExpected)});
  field("chunksApplied", Values{double(p.chunksApplied)});
  field("level", Values{double(p.level)});
  field("vertexCount", Values{double(p.cellCount)});
  field("complete:bool", Values{p.complete ? 1.0 : 0.0});
  field("errorBound", Values{errorBound});
}

// Appends the fields' names to a layout line.
struct Describe {
  char*& end;
  void operator()(const char* name, Values) {
    *end++ = ' ';
    while (*name) *end++ = *name++;
  }
};

// Writes the fields' values one after the other.
struct Write {
  double* out;
  void operator()(const char*, Values values) {
    for (double v : values) *out++ = v;
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

// Limits of 0 keep the defaults (kdmesh::DecoderLimits); `cellCentres`
// places coarse vertices at their cells' centres (kdmesh::CoarsePlacement).
EMSCRIPTEN_KEEPALIVE KdmDecoder* kdm_create(uint32_t maxVertices, uint32_t maxSimplices, uint32_t maxChunkBytes,
                                            uint32_t maxVerticesPerByte, uint32_t maxSimplicesPerByte,
                                            uint32_t cellCentres) {
  kdmesh::DecoderOptions options;
  if (cellCentres) options.coarsePlacement = kdmesh::CoarsePlacement::CellCentre;
  if (maxVertices) options.limits.maxVertices = maxVertices;
  if (maxSimplices) options.limits.maxSimplices = maxSimplices;
  if (maxChunkBytes) options.limits.maxChunkBytes = maxChunkBytes;
  if (maxVerticesPerByte) options.limits.maxVerticesPerByte = maxVerticesPerByte;
  if (maxSimplicesPerByte) options.limits.maxSimplicesPerByte = maxSimplicesPerByte;
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

// The records' layout, one line each: "header: FIELD ..." and
// "progress: FIELD ...".
EMSCRIPTEN_KEEPALIVE const char* kdm_layout() {
  static char layout[512];  // the fields' names take about 250
  if (!layout[0]) {
    char* end = layout;
    for (const char c : "header:") if (c) *end++ = c;
    visitHeader(kdmesh::Header{}, Describe{end});
    for (const char c : "\nprogress:") if (c) *end++ = c;
    visitProgress(kdmesh::DecodeProgress{}, 0, Describe{end});
  }
  return layout;
}

// The header record into `out` (see kdm_layout).
EMSCRIPTEN_KEEPALIVE void kdm_header(KdmDecoder* d, double* out) { visitHeader(d->decoder.header(), Write{out}); }

// The progress record into `out` (see kdm_layout).
EMSCRIPTEN_KEEPALIVE void kdm_progress(KdmDecoder* d, double* out) {
  const kdmesh::DecodeProgress p = d->decoder.progress();
  visitProgress(p, d->errorBound(p), Write{out});
}

EMSCRIPTEN_KEEPALIVE void kdm_snapshot(KdmDecoder* d) { d->decoder.snapshot(d->snapshot); }
EMSCRIPTEN_KEEPALIVE uint32_t kdm_vertex_count(KdmDecoder* d) { return uint32_t(d->snapshot.vertexCount()); }
EMSCRIPTEN_KEEPALIVE const float* kdm_positions(KdmDecoder* d) { return d->snapshot.positions.data(); }
// A float64 stream's doubles, 3 per vertex (the snapshot's positions64),
// or null for other streams.
EMSCRIPTEN_KEEPALIVE const double* kdm_positions64(KdmDecoder* d) {
  return d->snapshot.positions64.empty() ? nullptr : d->snapshot.positions64.data();
}
// Number of indices (not simplices) of dimension 0..3 in the snapshot.
EMSCRIPTEN_KEEPALIVE uint32_t kdm_index_count(KdmDecoder* d, int dimension) {
  return uint32_t(indices(d->snapshot, dimension).size());
}
EMSCRIPTEN_KEEPALIVE const uint32_t* kdm_indices(KdmDecoder* d, int dimension) {
  return indices(d->snapshot, dimension).data();
}
// The snapshot's vertex attributes: how many, and each one's name, type
// (kdmesh::AttributeType), components and values (vertex count · components
// of the type, in WebAssembly memory).
EMSCRIPTEN_KEEPALIVE uint32_t kdm_attribute_count(KdmDecoder* d) { return uint32_t(d->snapshot.attributes.size()); }
EMSCRIPTEN_KEEPALIVE const char* kdm_attribute_name(KdmDecoder* d, uint32_t a) {
  return d->snapshot.attributes[a].name.c_str();
}
EMSCRIPTEN_KEEPALIVE int kdm_attribute_type(KdmDecoder* d, uint32_t a) { return int(d->snapshot.attributes[a].type); }
EMSCRIPTEN_KEEPALIVE int kdm_attribute_components(KdmDecoder* d, uint32_t a) {
  return d->snapshot.attributes[a].components;
}
EMSCRIPTEN_KEEPALIVE const uint8_t* kdm_attribute_values(KdmDecoder* d, uint32_t a) {
  return d->snapshot.attributes[a].values.data();
}
// How the stream codes attribute a: its kdmesh::AttributeQuantization::Kind
// (exact, uniform, octahedral, geometric octahedral) and, for the lossy
// codings, the bits per component (uniform) or per octahedral coordinate.
EMSCRIPTEN_KEEPALIVE int kdm_attribute_coding(KdmDecoder* d, uint32_t a) {
  return int(d->snapshot.attributes[a].quantization.kind);
}
EMSCRIPTEN_KEEPALIVE int kdm_attribute_coding_bits(KdmDecoder* d, uint32_t a) {
  return int(d->snapshot.attributes[a].quantization.bits);
}
// The snapshot's labels of the simplices of dimension 1..3: as many as
// simplices, or none when the stream has no labels.
EMSCRIPTEN_KEEPALIVE uint32_t kdm_label_count(KdmDecoder* d, int dimension) {
  return uint32_t(d->snapshot.labels.of(dimension).size());
}
EMSCRIPTEN_KEEPALIVE const int32_t* kdm_labels(KdmDecoder* d, int dimension) {
  return d->snapshot.labels.of(dimension).data();
}
// The stream's label table (Decoder::labels()): its distinct labels,
// ascending; none until it has arrived or when the stream has no labels.
EMSCRIPTEN_KEEPALIVE uint32_t kdm_table_label_count(KdmDecoder* d) { return uint32_t(d->decoder.labels().size()); }
EMSCRIPTEN_KEEPALIVE const int32_t* kdm_table_labels(KdmDecoder* d) { return d->decoder.labels().data(); }
EMSCRIPTEN_KEEPALIVE uint32_t kdm_parent_count(KdmDecoder* d) { return uint32_t(d->decoder.vertexParents().size()); }
EMSCRIPTEN_KEEPALIVE const uint32_t* kdm_parents(KdmDecoder* d) { return d->decoder.vertexParents().data(); }

// Bytes of WebAssembly heap in use: lets tests prove that decoders free
// everything they allocate.
EMSCRIPTEN_KEEPALIVE uint32_t kdm_heap_in_use() { return uint32_t(mallinfo().uordblks); }

}  // extern "C"
