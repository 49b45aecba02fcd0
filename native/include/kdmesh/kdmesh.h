// kdmesh — progressive, lossless compression of simplicial complexes.
//
// The codec follows Gandoin & Devillers, "Progressive Lossless Compression of
// Arbitrary Simplicial Complexes" (SIGGRAPH 2002): a kd-tree halves the
// bounding box cell by cell and arithmetic-codes how many vertices fall in the
// first half of every cell, coarse to fine, so that any prefix of a stream
// decodes to a coarser model.
//
// This header is the whole public C++ API of the codec core. The core does no
// file I/O and throws no exceptions; it compiles unchanged to WebAssembly,
// where the decoder runs on untrusted bytes. File formats live in kdmesh/io.h.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace kdmesh {

// ---------------------------------------------------------------------------
// Data model
// ---------------------------------------------------------------------------

// A simplicial complex of dimension <= 3: vertex positions plus simplices of
// each dimension as flat index arrays (2 indices per edge, 3 per triangle,
// 4 per tetrahedron). A vertex that belongs to no edge, triangle or
// tetrahedron is an isolated point of the complex whether or not it is listed
// in `points`: readers fill `points` with what a file declares (OBJ `p`), the
// encoder ignores it, and the decoder lists there every isolated vertex.
// A per-vertex attribute: `components` values of one type for every
// vertex, vertex after vertex (colours, normals, texture coordinates,
// intensities, ...). The codec keeps them bit-exact: every prefix of a
// stream gives each of its vertices the values of the input vertex it
// stands for (see docs/FORMAT.md).
enum class AttributeType : uint8_t { UInt8, Int8, UInt16, Int16, UInt32, Int32, Float32 };
constexpr int kAttributeTypeCount = 7;
// Bytes per value (1, 2 or 4) and the type's name ("uint8", "float32", ...).
size_t attributeTypeBytes(AttributeType type);
const char* attributeTypeName(AttributeType type);

// How a stream codes a float32 attribute's values (docs/FORMAT.md). The
// encoder chooses it from EncodeOptions (attributeBits, normalBits) and
// ignores this field of its input; the decoder reports what the stream did.
struct AttributeQuantization {
  enum Kind : uint8_t {
    Exact = 0,       // every bit
    Uniform = 1,     // per component, value q of `bits` bits stands for minimum + q · step
    Octahedral = 2,  // a unit vector (3 components) as two `bits`-bit octahedral coordinates
    // As Octahedral, but coded once the kd-tree is complete, predicted by the
    // decoded triangles' normals; before that a prefix shows the normals of
    // its own triangles (docs/FORMAT.md). The encoder's choice for normals
    // of a complex with triangles.
    GeometricOctahedral = 3,
  };
  Kind kind = Exact;
  uint8_t bits = 0;
  std::array<float, 4> minimum{}, step{};  // Uniform, per component
};

struct VertexAttribute {
  std::string name;          // 1..64 printable ASCII characters, unique in a complex
  AttributeType type = AttributeType::Float32;
  uint8_t components = 1;    // 1..4
  std::vector<uint8_t> values;  // vertex count · components values, in memory order
  AttributeQuantization quantization;

  size_t valueBytes() const { return attributeTypeBytes(type) * components; }  // per vertex
};
// A stream carries at most this many attributes.
constexpr size_t kMaxAttributes = 15;
constexpr size_t kMaxAttributeNameBytes = 64;

// An integer label per listed edge, triangle and tetrahedron (a material,
// region or group id), parallel to the simplex lists: labels.triangles[i]
// belongs to triangle i. Each vector is empty (no labels) or holds one label
// per simplex of its list. When any list has labels, a list with simplices
// and no labels gets label 0 for each of them. Isolated points carry no
// label: give them a vertex attribute instead.
//
// The codec keeps labels exactly: the decoded complex lists every input
// maximal simplex with its label (in its own vertex ids and order). Labels
// of input simplices the encoder drops (InputRepairs: duplicates, faces of
// other listed simplices) are dropped with them. Every prefix gives each
// simplex it lists the label of an input simplex it stands for.
struct SimplexLabels {
  std::vector<int32_t> edges;
  std::vector<int32_t> triangles;
  std::vector<int32_t> tetrahedra;

  bool empty() const { return edges.empty() && triangles.empty() && tetrahedra.empty(); }
  // The vector of dimension 1..3.
  std::vector<int32_t>& of(int dimension) {
    return dimension == 1 ? edges : dimension == 2 ? triangles : tetrahedra;
  }
  const std::vector<int32_t>& of(int dimension) const {
    return dimension == 1 ? edges : dimension == 2 ? triangles : tetrahedra;
  }
};

struct Complex {
  std::vector<float> positions;  // xyz, 3 floats per vertex
  // Float64 coordinates: empty, or 3 doubles per vertex, the exact values
  // of which `positions` holds the float32 roundings. Readers fill it when
  // ReadOptions::keepDoubles is set and the file holds coordinates that
  // float32 does not; exact encoding (EncodeOptions::exact) of a complex
  // with it makes a float64 stream (Header::float64()), and decoding one
  // fills it.
  std::vector<double> positions64;
  std::vector<uint32_t> points;
  std::vector<uint32_t> edges;
  std::vector<uint32_t> triangles;
  std::vector<uint32_t> tetrahedra;
  std::vector<VertexAttribute> attributes;
  SimplexLabels labels;

  size_t vertexCount() const { return positions.size() / 3; }
  size_t simplexCount(int dimension) const;
  bool hasSimplices() const {
    return !edges.empty() || !triangles.empty() || !tetrahedra.empty();
  }
};

// ---------------------------------------------------------------------------
// Errors
// ---------------------------------------------------------------------------

enum class ErrorCode : uint8_t {
  Ok = 0,
  InvalidArgument,     // an option is out of range
  InvalidInput,        // the complex cannot be encoded (NaN on a grid, bad index, ...)
  Unsupported,         // valid input that this version cannot encode
  BadMagic,            // the bytes are not a kdmesh stream
  UnsupportedVersion,  // a kdmesh stream from a newer format version
  CorruptHeader,       // header checksum or field validation failed
  CorruptChunk,        // chunk checksum or chunk decoding failed
  Truncated,           // finish() was called before the stream was complete
  TrailingBytes,       // bytes after the last chunk
  LimitExceeded,       // the stream asks for more than DecoderLimits allow
};

// Stable lower-case name of an error code ("corrupt-chunk", ...), used by the
// CLI and the JavaScript binding.
const char* errorCodeName(ErrorCode code);

struct Status {
  ErrorCode code = ErrorCode::Ok;
  std::string message;

  bool ok() const { return code == ErrorCode::Ok; }
  static Status success() { return {}; }
  static Status error(ErrorCode code, std::string message) {
    return {code, std::move(message)};
  }
};

// ---------------------------------------------------------------------------
// Stream header
// ---------------------------------------------------------------------------

enum class Quantization : uint8_t {
  Grid = 0,     // isotropic grid over the bounding box, `bits` per longest axis
  Float32 = 1,  // every float32 coordinate bit-exact
};

// Everything a decoder knows once the header has arrived.
// The layout is specified in docs/FORMAT.md.
struct Header {
  uint16_t version = 0;
  uint8_t headerBytes = 0;          // the header's own size (it varies with its values)
  Quantization quantization = Quantization::Grid;
  uint8_t bits = 0;                 // grid bits of the longest axis (Grid);
                                    // 32, or 64 for float64 (Float32)
  uint32_t vertexCount = 0;
  uint8_t maxDimension = 0;         // highest simplex dimension present
  std::array<uint32_t, 4> simplexCounts{};  // per dimension 0..3; [0] counts
                                            // isolated vertices
  std::array<uint32_t, 3> gridMax{};  // largest integer coordinate per axis
  std::array<double, 3> origin{};   // Grid: position of integer coordinate 0
  double step = 0;                  // Grid: distance between grid lines
  std::array<uint32_t, 3> floatImageMin{};  // Float32: see docs/FORMAT.md
  uint64_t bodyBytes = 0;           // bytes after the header
  uint32_t chunkCount = 0;
  // Vertex attributes (up to kMaxAttributes): their names, types and the
  // root vertex's values are in the attribute table that starts the body.
  uint8_t attributeCount = 0;
  // Whether edges, triangles and tetrahedra carry labels; the label table
  // (the distinct labels) follows the attribute table.
  bool labelled = false;
  // Coded for fast decoding (EncodeOptions::fastDecode).
  bool fastDecode = false;

  // Float32 mode with float64 residuals (bits 64): the kd-tree codes each
  // coordinate's float32 rounding, and two hidden attributes at the end of
  // the table (counted in attributeCount) the rest of its float64 bits.
  bool float64() const { return quantization == Quantization::Float32 && bits == 64; }
  // Bits of integer coordinate per axis: the kd-tree refines axis a
  // axisBits(a) times.
  int axisBits(int axis) const;
  // Number of kd-tree levels: the sum of axisBits over the three axes.
  int depth() const;
  // Total stream size in bytes (header plus body).
  uint64_t totalBytes() const;
};

// The header that starts every stream is at most this long; its first
// kHeaderPrefixBytes say how long it is.
constexpr size_t kMaxHeaderBytes = 88;
constexpr size_t kHeaderPrefixBytes = 7;

// ---------------------------------------------------------------------------
// Encoding
// ---------------------------------------------------------------------------

struct EncodeProgress {
  const char* phase;  // "quantize", "sort", "code"
  double fraction;    // 0..1 within the phase
};

struct EncodeOptions {
  // Grid bits of the longest bounding-box axis, 1..30. 16 bits keep the
  // error below 1/131070 of the largest extent: finer than float32 rendering
  // of a typical scan, and half the size of raw float32 coordinates.
  int bits = 16;
  // Preserve every float32 coordinate bit for bit (overrides `bits`),
  // infinities and NaNs (with their payloads) included; grid mode refuses
  // them. A complex with positions64 keeps every float64 bit (a float64
  // stream, whose vertices cost about nothing more while their doubles are
  // float32 values); it may then have at most kMaxAttributes - 2 attributes.
  bool exact = false;
  // Float32 vertex attributes are exact unless these are set (lossy):
  // `attributeBits` (1..24) quantizes each component of every float32
  // attribute to that many bits over its range (the step is never below
  // 2^-22 of the largest magnitude, where float32 values no longer differ);
  // `normalBits` (2..16) codes a float32 × 3 attribute named `normal` as
  // unit vectors in two octahedral coordinates of that many bits, as web
  // codecs do (Draco, meshoptimizer); with triangles, after the positions,
  // predicted from the decoded surface (GeometricOctahedral). Decoding gives
  // float32 values back.
  int attributeBits = 0;
  int normalBits = 0;
  // Largest chunk payload in bytes. The first chunks are smaller (1 KiB,
  // growing by a quarter each up to this size) so that a viewer can show
  // something early and refine it often.
  size_t chunkBytes = 16 * 1024;
  // Predict where vertices lie from their neighbours' positions along the
  // split axis alone, read in one pass over a vertex's edges: the decoder
  // skips the full neighbourhood walks (sums over the triangles, planes,
  // parallelograms) and the mixing of one-vertex splits, the larger share
  // of its work on meshes, for a larger stream (docs/BENCHMARKS.md has
  // both). Point clouds, which have no neighbourhood, code the same either
  // way.
  bool fastDecode = false;
  // Called now and then during long encodes; may be empty.
  std::function<void(const EncodeProgress&)> progress;
  // Working memory encode() may take, in bytes (0: no limit). A complex
  // whose estimate (encodeMemoryEstimate()) is larger is refused with
  // LimitExceeded before anything is allocated.
  uint64_t maxMemoryBytes = 0;
};

// About the peak working memory of encoding `complex`, in bytes, the
// complex itself included: per vertex and per listed simplex of each
// dimension, as measured on point clouds, wireframes, surfaces, soups and
// tetrahedral meshes (docs/SECURITY.md). Within about 20 % on those.
uint64_t encodeMemoryEstimate(const Complex& complex);

// What the splits of one kd-tree level coded, in bits (CodingCost::levels).
struct LevelCost {
  // The axis the level halves its cells along (0..2), or -1 past the
  // geometric levels, where cells of coincident vertices split in halves.
  int axis = 0;
  uint32_t cells = 0;  // cells the level split: the model's vertices before it
  double geometryBits = 0;
  double connectivityBits = 0;  // simplex labels included
};

// Information content of what a stream codes, in bits: the sum of -log2(p)
// over every coded symbol, split by what the symbol describes.
struct CodingCost {
  double geometryBits = 0;
  double connectivityBits = 0;
  std::vector<double> attributeBits;  // per vertex attribute, in the stream's order
  double labelBits = 0;               // simplex labels (not in connectivityBits)
  // The same by kd-tree level, coarse to fine: where the bits of a model go,
  // and so how many a coarser quantization or a prefix of the stream would
  // keep. The decoder lists the levels it has completed.
  std::vector<LevelCost> levels;
};

// Input simplices the encoder dropped, per dimension. A complex holds a
// simplex once, so a simplex listed twice (in any vertex order), or listed
// although it is a face of another listed simplex, is redundant; a simplex
// with a repeated vertex is degenerate. Points ([0]) are redundant when the
// vertex belongs to an edge, triangle or tetrahedron.
struct InputRepairs {
  std::array<uint64_t, 4> degenerate{};
  std::array<uint64_t, 4> duplicate{};
  std::array<uint64_t, 4> redundant{};
};

// What the connectivity coder did (the same on both sides of a stream).
struct ConnectivityStatistics {
  uint64_t vertexSplits = 0;
  // Codes given to star simplices, [dimension][code - 1] (codes 1..4, see
  // docs/FORMAT.md); dimension 0 is the split vertex itself.
  std::array<std::array<uint64_t, 4>, 4> codes{};
  uint64_t orientationBits = 0;          // orientation decisions coded
  uint64_t orientationMispredicted = 0;  // of which the prediction was wrong
  // Vertex splits shaped as an edge expansion: the new edge V1V2, exactly
  // two edges coded 4 and no simplex coded 3 (the paper's cheap operator).
  uint64_t edgeExpansions = 0;
  // Of those, the ones of closed-fan stars coded by where the fan's two
  // cuts lie (streams coded for fast decoding; docs/FORMAT.md).
  uint64_t fanExpansions = 0;
  // Predictions from the current complex (docs/FORMAT.md, "Contexts"):
  uint64_t edgeCodesByDirection = 0;  // edge codes conditioned on the split direction
  uint64_t countPredictions = 0;      // several-vertex cell counts with a neighbourhood class
  uint64_t positionPredictions = 0;   // one-vertex cell splits coded from the neighbours
  // Of the two above, those that also had the parallelogram predictions of
  // triangles across the vertex's link (cell counts: after a one-sided
  // parent split).
  uint64_t parallelogramPredictions = 0;
  // Triangles between two edges coded 3 or 4, coded most constrained first
  // with the count of their edges' code-4 triangles (tetrahedral meshes).
  uint64_t pairedTriangles = 0;
  // Edge codes of stars that are one closed fan, conditioned on the run of
  // uncoded edges around the fan that holds the edge; of those, the codes
  // of one of two candidates for a cut, conditioned on the Delaunay
  // criterion and the two candidates' valences.
  uint64_t closedFanEdgeCodes = 0;
  uint64_t cutCandidatePairs = 0;
  // Cell counts and one-vertex splits from the neighbourhood (the two
  // counters above) with a neighbour in the cell's slab along the split
  // axis that has split at this level already (the refinement class).
  uint64_t refinedNeighbourPredictions = 0;
  // One-vertex splits of vertices in no simplex, predicted from the vertex
  // they split from (its cell's other half at the split that isolated them).
  uint64_t proxyPredictions = 0;
};

struct EncodeResult {
  Status status;
  std::vector<uint8_t> bytes;
  CodingCost cost;
  InputRepairs repairs;
  ConnectivityStatistics statistics;
};

EncodeResult encode(const Complex& complex, const EncodeOptions& options = {});

// ---------------------------------------------------------------------------
// Decoding
// ---------------------------------------------------------------------------

// Caps that keep a hostile header from making the decoder allocate without
// bound. Exceeding one is a LimitExceeded error, never an allocation.
struct DecoderLimits {
  uint32_t maxVertices = 1u << 27;
  uint32_t maxChunkBytes = 1u << 26;
  // Edges, triangles and tetrahedra of the complete complex, together.
  uint32_t maxSimplices = 1u << 28;
  // Vertices and simplices per byte of the whole stream (header and body):
  // what bounds the output a small stream can make. Honest streams take
  // about a byte per vertex; only a cloud of many coincident points comes
  // near the limit, which such a decoder raises.
  uint64_t maxVerticesPerByte = 1024;
  uint64_t maxSimplicesPerByte = 1024;
};

// Where snapshot() puts the vertex of a cell that is not yet a single grid
// point, before the stream is complete.
enum class CoarsePlacement {
  // Moved along its normal halfway from its cell's centre to the plane of
  // its neighbours in the complex, clamped to its cell: a coarse surface
  // looks like the model rather than like voxels. Streams without
  // simplices place at cell centres.
  Predicted,
  // At the centre of its cell.
  CellCentre,
};

struct DecoderOptions {
  DecoderLimits limits;
  CoarsePlacement coarsePlacement = CoarsePlacement::Predicted;
  // Accumulate CodingCost while decoding (costs a little speed).
  bool measureCost = false;
};

struct ChunkInfo {
  uint64_t offset;        // of the chunk, from the start of the stream
  uint32_t payloadBytes;
  uint32_t splitCount;    // kd-tree cells the chunk refines
  uint32_t frameBytes;    // the chunk's bytes besides the payload: its frame and checksum
};

// Where a decoder stands in the stream.
struct DecodeProgress {
  uint64_t bytesReceived = 0;  // pushed so far
  uint64_t bytesConsumed = 0;  // header plus every applied chunk
  uint64_t bytesExpected = 0;  // whole stream, from the header (0 before it)
  uint32_t chunksApplied = 0;
  uint32_t level = 0;          // kd-tree level being refined (0 = root)
  uint32_t cellCount = 0;      // vertices of the current model
  bool complete = false;
};

// Incremental decoder. Feed it the stream in pieces of any size with push();
// every whole chunk is applied at once and the remainder waits for more bytes.
// The current model can be read between pushes at any time.
//
//   kdmesh::Decoder decoder;
//   while (receive(piece)) {
//     if (auto s = decoder.push(piece.data(), piece.size()); !s.ok()) fail(s);
//     if (decoder.hasHeader()) draw(decoder.snapshot());
//   }
//   if (auto s = decoder.finish(); !s.ok()) fail(s);
//
// After an error the decoder keeps returning that error; destroy it or reset().
class Decoder {
 public:
  explicit Decoder(const DecoderOptions& options = {});
  ~Decoder();
  Decoder(Decoder&&) noexcept;
  Decoder& operator=(Decoder&&) noexcept;

  Status push(const uint8_t* data, size_t size);
  // Checks that the stream was complete and nothing followed it.
  Status finish() const;
  void reset();

  bool hasHeader() const;
  const Header& header() const;  // valid once hasHeader()
  bool complete() const;
  DecodeProgress progress() const;
  const std::vector<ChunkInfo>& chunks() const;  // applied so far
  CodingCost cost() const;  // filled when DecoderOptions::measureCost
  ConnectivityStatistics statistics() const;
  // For connectivity streams, vertex ids are stable from prefix to prefix:
  // when a vertex splits, its first half keeps its id and the second half
  // gets the next one. vertexParents()[v] is the vertex that v was split
  // from (0 for vertex 0), so a viewer can animate refinement and any final
  // vertex can be traced to its ancestor at a coarser level.
  const std::vector<uint32_t>& vertexParents() const;
  // The stream's label table: its distinct simplex labels, ascending (the
  // format stores them so). Snapshot labels are values of this table, and a
  // label's index in it does not change from level to level, so a viewer
  // can key a material by it before the label's first simplex arrives.
  // Empty until the table has arrived (right after the header and the
  // attribute table) and for streams without labels.
  const std::vector<int32_t>& labels() const;

  // The model at the current level: one vertex in every current kd-tree
  // cell (clamped to the bounding box), placed as DecoderOptions::
  // coarsePlacement says, or, once complete, every input vertex at its exact
  // (quantized) position. Replaces `out`. A float64 stream's snapshot
  // also fills positions64: the exact doubles once complete, before that
  // the float32 positions widened.
  // With connectivity, vertex v of the snapshot is vertex id v, and the
  // simplices are the maximal simplices of the current complex (the input
  // complex with every vertex replaced by its cell), oriented as the input
  // simplices they stand for.
  void snapshot(Complex& out) const;
  Complex snapshot() const;
  // No input vertex is farther than this from the snapshot vertex of its
  // cell: half the diagonal of the largest current cell with cell-centre
  // placement, the whole diagonal with predicted placement (which may put
  // the vertex in a corner).
  double errorBound() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
  // decode() takes the complete model's lists from its decoder instead of
  // copying them.
  friend Status decode(const uint8_t*, size_t, Complex&, bool, const DecoderOptions&);
};

// Decodes a whole stream, or the longest decodable prefix of it when
// `allowPrefix` is true (a progressive preview of the first bytes).
Status decode(const uint8_t* data, size_t size, Complex& out,
              bool allowPrefix = false, const DecoderOptions& options = {});

}  // namespace kdmesh
