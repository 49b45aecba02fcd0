// The incremental decoder: buffers pushed bytes, applies every whole chunk,
// and keeps the kd-tree's current level as flat arrays of cells.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <string>

#include "attributes.h"
#include "container.h"
#include "count_coder.h"
#include "kdmesh/kdmesh.h"
#include "labels.h"
#include "large_array.h"
#include "position_predictor.h"
#include "quantizer.h"
#include "range_coder.h"
#include "simplex_store.h"
#include "split_schedule.h"
#include "vertex_split.h"

namespace kdmesh {
namespace {

// A kd-tree cell: the leading bits of its integer coordinates (as many per
// axis as the splits above it fixed) and how many vertices it holds.
struct Cell {
  uint32_t prefix[3];
  uint32_t population : 31;
  uint32_t parentOneSided : 1;
  // How many one-vertex cells precede this cell in kd-tree order; for a new
  // one-vertex cell, where it goes among those of the previous level.
  uint32_t singlesBefore;
  uint32_t vertex;  // id in the complex (streams with connectivity or attributes)
};

// Every split codes at least one binary decision, and a decision costs at
// least -log2(1 - 31/32768) = 0.00137 bits (models never go closer to
// certainty), so a chunk can hold at most ~5,860 splits per byte of payload
// (plus the few zero bytes the range decoder reads past its end). A frame
// that claims more is corrupt; refusing it bounds the work a chunk can ask for
// by its size.
constexpr uint64_t kMaxSplitsPerByte = 6000;

}  // namespace

struct Decoder::State {
  DecoderOptions options;
  Status error;
  std::vector<uint8_t> pending;  // received, not yet applied
  uint64_t bytesReceived = 0;
  uint64_t bytesConsumed = 0;

  bool hasHeader = false;
  Header header;
  std::optional<SplitSchedule> schedule;
  std::optional<Dequantizer> dequantizer;
  std::optional<CountCoder> counts;
  RangeDecoder coder;
  std::vector<ChunkInfo> chunks;
  CodingCost cost;

  // Cells of `level` holding several vertices that are not yet split are
  // cells[cursor..]; their children so far are in `children`, one level
  // finer. Cells of one vertex live in `singles`, in kd-tree order, and are
  // refined in place after the other cells of the level (so one level costs
  // no copy of them): singles[singleCursor..singleLevelEnd) are still at
  // `level`, the rest one level finer. One-vertex children born during the
  // level wait in `newSingles` and are merged in at its end; keeping kd-tree
  // order lets the adaptive models follow local regularity.
  LargeArray<Cell> cells, children, singles, newSingles;
  size_t cursor = 0, singleCursor = 0, singleLevelEnd = 0;
  int level = 0;
  LevelCostTally levelCosts;

  // Connectivity: the complex on the current cells. Levels past the last
  // geometric one split cells of coincident vertices in halves.
  bool connectivity = false;
  // Vertices have ids (and coincident ones their own levels) in streams
  // with connectivity or attributes.
  bool named = false;
  // The attributes' descriptors and values by vertex id; the table that
  // starts the body has the root vertex's.
  std::vector<VertexAttribute> attributes;
  std::optional<AttributeCoder> attributeCoder;
  bool attributeTableRead = false;
  std::vector<uint32_t> neighbours;  // of the vertex whose attributes are decoded
  // Attributes coded after the kd-tree (GeometricOctahedral): the next
  // vertex whose values come, the last one's id + 1 once all have (vertex
  // 0's are in the table), and triangleNormals() of the final complex.
  bool afterGeometry = false;
  uint32_t nextAfterGeometry = 1;
  std::vector<double> triangleNormalsByVertex;
  // Simplex labels: the table after the attribute table; the store holds
  // indices into it.
  std::vector<int32_t> labelTable;
  bool labelTableRead = false;
  SimplexStore store;
  std::optional<VertexSplitter> splitter;
  std::optional<PositionPredictor> predictor;
  uint32_t nextVertex = 1;
  std::vector<uint32_t> parents{0};  // the vertex each vertex was split from
  Complex finalComplex;              // simplices, once complete

  // Working memory of snapshots, kept from one to the next: a large
  // complex's arrays, allocated anew each time, cost a page fault per 4 KiB.
  struct SnapshotScratch {
    // facesOfHigher(): lists of facets by lowest vertex, per dimension.
    std::vector<uint32_t> facetStart, edgeFacets;
    std::vector<uint64_t> triangleFacets;
    std::vector<uint8_t> isFace;
    std::vector<float> centre, low, high, sum, normal;  // placeOnNeighbourPlanes(), holdTriangleNormals()
    std::vector<uint32_t> degree;
  } scratch;

  explicit State(const DecoderOptions& o) : options(o) {}

  // Every cell split, down to the last level (and coincident vertices apart).
  bool kdTreeComplete() const {
    return hasHeader && attributeTableRead && labelTableRead && level >= schedule->levels &&
           (!named || cells.empty());
  }

  bool complete() const { return kdTreeComplete() && afterGeometryComplete(); }
  bool afterGeometryComplete() const { return !afterGeometry || nextAfterGeometry >= header.vertexCount; }

  Status fail(Status status) {
    error = status;
    return status;
  }

  // `available`: bytes of the stream already at hand (those of this push).
  Status startBody(size_t available) {
    schedule.emplace(header);
    dequantizer.emplace(header);
    connectivity = header.maxDimension > 0;
    named = connectivity || header.attributeCount > 0;
    attributeTableRead = header.attributeCount == 0;
    labelTableRead = !header.labelled;
    counts.emplace(schedule->levels, connectivity);
    coder.setMeasuring(options.measureCost);
    const Cell root{{0, 0, 0}, header.vertexCount, 0, 0, 0};
    (header.vertexCount == 1 ? singles : cells).push_back(root);
    singleLevelEnd = singles.size();
    if (connectivity) {
      // Vertex lists grow with the vertices actually decoded, not with the
      // count a (possibly hostile) header announces.
      store.reset(std::min<uint32_t>(header.vertexCount, 1024), false);
      if (header.labelled) store.enableLabels();
      const std::array<uint64_t, 4> caps = simplexCaps(header);
      // The header's counts cap the pools; memory is reserved up front only
      // in proportion to the bytes already received (a whole file pushed at
      // once reserves its final size; a hostile 100-byte header, next to
      // nothing), and otherwise grows with the simplices actually decoded.
      const uint64_t plausible = 16 * uint64_t(available);
      for (int d = 1; d <= 3; ++d) {
        const uint32_t cap = uint32_t(std::min<uint64_t>(caps[size_t(d)], 0xffffffffu));
        store.setCapacity(d, cap, uint32_t(std::min<uint64_t>(cap, plausible)));
      }
      predictor.emplace(*schedule, store, header.fastDecode);
      splitter.emplace(store, *predictor);
      predictor->place(0, root.prefix, 0);
    }
    hasHeader = true;
    return Status::success();
  }

  // `chunk`: the whole chunk, frameBytes of frame first.
  Status applyChunk(const uint8_t* chunk, size_t frameBytes, const ChunkFrame& frame) {
    const std::string where = "chunk " + std::to_string(chunks.size());
    if (!chunkChecksumMatches(chunk, frameBytes + frame.payloadBytes, uint32_t(chunks.size())))
      return Status::error(ErrorCode::CorruptChunk, where + ": checksum mismatch");
    coder.start(chunk + frameBytes, frame.payloadBytes);
    for (uint32_t left = frame.splitCount; left > 0;) {
      const bool treeComplete = kdTreeComplete();
      if (treeComplete && afterGeometryComplete())
        return Status::error(ErrorCode::CorruptChunk,
                             where + ": more splits than the kd-tree has cells");
      if (treeComplete) {
        decodeAfterGeometry();
        --left;
        continue;
      }
      if (cursor < cells.size()) {
        prefetchNeighbourhoods(cells, cursor);
        if (!splitCell(cells[cursor++]))
          return Status::error(ErrorCode::CorruptChunk,
                               where + ": inconsistent connectivity codes or a label outside the table");
        --left;
      } else {
        const size_t count = std::min<size_t>(left, singleLevelEnd - singleCursor);
        refineSingles(singleCursor, singleCursor + count);
        singleCursor += count;
        left -= uint32_t(count);
      }
      if (cursor == cells.size() && singleCursor == singleLevelEnd) nextLevel();
    }
    if (coder.invalid())
      return Status::error(ErrorCode::CorruptChunk, where + ": undecodable data");
    double attributeBits = 0;
    for (const double bits : cost.attributeBits) attributeBits += bits;
    cost.geometryBits = coder.cost() - cost.connectivityBits - cost.labelBits - attributeBits;
    if (complete() && connectivity) return checkFinalCounts();
    return Status::success();
  }

  // The complete complex must have the maximal simplices the header
  // announced: a last line of defence against corrupt streams with valid
  // checksums. The complex is kept for snapshot().
  Status checkFinalCounts() {
    Complex& complex = finalComplex;
    appendSimplices(complex);
    for (int d = 0; d <= 3; ++d)
      if (complex.simplexCount(d) != header.simplexCounts[size_t(d)])
        return Status::error(ErrorCode::CorruptChunk,
                             "the decoded complex has " + std::to_string(complex.simplexCount(d)) +
                                 " maximal simplices of dimension " + std::to_string(d) +
                                 ", the header announced " +
                                 std::to_string(header.simplexCounts[size_t(d)]));
    return Status::success();
  }

  // Returns false on connectivity codes that contradict each other.
  bool splitCell(const Cell& cell) {
    const uint32_t population = cell.population;
    const bool geometric = level < schedule->levels;
    const uint32_t firstHalf =
        geometric ? counts->code(coder, population, level, cell.parentOneSided, 0,
                                 connectivity ? predictor->countContext(cell.vertex, level, cell.parentOneSided)
                                              : CountContext{})
                  : population / 2;
    const bool oneSided = firstHalf == 0 || firstHalf == population;
    Cell child = cell;
    child.parentOneSided = oneSided;
    const int axis = geometric ? schedule->axis[size_t(level)] : 0;
    if (geometric) child.prefix[axis] = cell.prefix[axis] << 1;
    uint32_t added = cell.vertex;
    if (named && !oneSided) {
      added = nextVertex++;
      parents.push_back(cell.vertex);
    }
    if (connectivity && !oneSided) {
      if (added >= store.vertexCapacity())
        store.growVertices(std::min<uint32_t>(header.vertexCount, 2 * store.vertexCapacity()));
      const double before = coder.cost(), labelsBefore = splitter->labelBits();
      if (!splitter->split(coder, cell.vertex, added, level, splitBalance(population, firstHalf, geometric),
                           NoRecords{}, [] { return kNoLabel; }))
        return false;
      const double labelBits = splitter->labelBits() - labelsBefore;
      cost.labelBits += labelBits;
      cost.connectivityBits += coder.cost() - before - labelBits;
    }
    if (!attributes.empty() && !oneSided) decodeAttributes(cell.vertex, added);
    for (const uint32_t half : {firstHalf, population - firstHalf}) {
      if (half == 1) {
        child.population = 1;
        child.singlesBefore = cell.singlesBefore;
        newSingles.push_back(child);
      } else if (half > 1) {
        child.population = half;
        child.singlesBefore = cell.singlesBefore + uint32_t(newSingles.size());
        children.push_back(child);
      }
      if (connectivity && geometric && half > 0) predictor->place(child.vertex, child.prefix, level + 1);
      if (geometric) child.prefix[axis] |= 1;
      child.vertex = added;
    }
    return true;
  }

  // The values of a new vertex, against its neighbours' (or its parent's).
  // Those of attributes coded after the kd-tree are its parent's until then.
  void decodeAttributes(uint32_t parent, uint32_t vertex) {
    neighbours.clear();
    if (connectivity)
      store.forEachIncident(1, vertex, [&](uint32_t edge, uint32_t position) {
        neighbours.push_back(store.vertices(1, edge)[1 - position]);
      });
    for (size_t a = 0; a < attributes.size(); ++a) {
      std::vector<uint8_t>& values = attributes[a].values;
      const size_t bytes = attributes[a].valueBytes();
      if (values.size() < (size_t(vertex) + 1) * bytes)
        values.resize(std::min<size_t>(header.vertexCount, std::max<size_t>(vertex + 1, 2 * values.size() / bytes)) *
                      bytes);
      if (attributeCoder->codedAfterGeometry(a)) {
        std::memcpy(values.data() + size_t(vertex) * bytes, values.data() + size_t(parent) * bytes, bytes);
        continue;
      }
      AttributeCoder::Prediction prediction;
      attributeCoder->predict(a, neighbours, values.data() + size_t(parent) * bytes,
                              [&](uint32_t id) { return values.data() + size_t(id) * bytes; }, prediction);
      const double before = coder.cost();
      attributeCoder->code(coder, a, prediction, values.data() + size_t(vertex) * bytes);
      cost.attributeBits[a] += coder.cost() - before;
    }
  }

  // The values of the next vertex of the attributes coded after the
  // kd-tree, against its triangles' normal; the first call finds the
  // normals of all vertices.
  void decodeAfterGeometry() {
    std::vector<double>& normals = triangleNormalsByVertex;
    if (normals.empty()) {
      if (connectivity) {
        std::vector<float> positions;
        cellPositions(positions);
        triangleNormals(store, positions, normals);
      } else {
        normals.assign(size_t(nextVertex) * 4, 0.0);
      }
    }
    const uint32_t vertex = nextAfterGeometry++;
    neighbours.clear();  // those of lower ids, decoded
    if (connectivity) earlierNeighbours(store, vertex, neighbours);
    for (size_t a = 0; a < attributes.size(); ++a) {
      if (!attributeCoder->codedAfterGeometry(a)) continue;
      const size_t bytes = attributes[a].valueBytes();
      const uint8_t* values = attributes[a].values.data();
      AttributeCoder::Prediction prediction;
      attributeCoder->predictFromTriangles(
          a, normals, vertex, neighbours, [&](uint32_t n) { return values + size_t(n) * bytes; }, prediction);
      const double before = coder.cost();
      attributeCoder->code(coder, a, prediction, attributes[a].values.data() + size_t(vertex) * bytes);
      cost.attributeBits[a] += coder.cost() - before;
    }
    if (nextAfterGeometry == header.vertexCount) normals = {};
  }

  // Streams coded for fast decoding, at every kPrefetchBatch-th cell of a
  // level's list: the neighbourhoods of the vertices of that cell and the
  // next ones, whose predictions come soon, are prefetched
  // (PositionPredictor::prefetchNeighbourhoods()). Batches are aligned in
  // the list, not to the splits a chunk holds, so a chunk that ends in a
  // batch leaves the rest of it prefetched for the next. Only at geometric
  // levels: there the predictions are made, and every vertex has a cell
  // centre (those split apart at the coincident levels after them have
  // none).
  static constexpr size_t kPrefetchBatch = 32;
  void prefetchNeighbourhoods(const LargeArray<Cell>& list, size_t at) {
    if (at % kPrefetchBatch != 0 || level >= schedule->levels || !connectivity || !predictor->fastDecode()) return;
    uint32_t vertices[kPrefetchBatch];
    const size_t count = std::min(kPrefetchBatch, list.size() - at);
    for (size_t k = 0; k < count; ++k) vertices[k] = list[at + k].vertex;
    predictor->prefetchNeighbourhoods(vertices, count);
  }

  void refineSingles(size_t begin, size_t end) {
    const int axis = schedule->axis[size_t(level)];
    for (size_t i = begin; i < end; ++i) {
      prefetchNeighbourhoods(singles, i);
      Cell& cell = singles[i];
      const bool upperHalf =
          connectivity ? !predictor->codeSingle(coder, *counts, cell.vertex, level,
                                                cell.parentOneSided, false)
                       : !counts->codeSingle(coder, level, cell.parentOneSided, false);
      cell.prefix[axis] = cell.prefix[axis] << 1 | upperHalf;
      cell.parentOneSided = 1;
    }
  }

  void nextLevel() {
    // The level split its cells and, at geometric levels, its one-vertex cells.
    if (options.measureCost)
      levelCosts.close(*schedule, level, uint32_t(cells.size() + (level < schedule->levels ? singleLevelEnd : 0)),
                       coder.cost(), cost.connectivityBits + cost.labelBits, cost.levels);
    // Merge from the back, so that each one-vertex cell moves once.
    size_t old = singles.size(), out = old + newSingles.size();
    singles.resize(out);
    for (size_t j = newSingles.size(); j > 0; --j) {
      for (const size_t insertAt = newSingles[j - 1].singlesBefore; old > insertAt;)
        singles[--out] = singles[--old];
      singles[--out] = newSingles[j - 1];
    }
    newSingles.clear();
    std::swap(cells, children);
    children.clear();
    cursor = 0;
    ++level;
    // Past the geometric levels one-vertex cells are final.
    singleCursor = level < schedule->levels ? 0 : singles.size();
    singleLevelEnd = singles.size();
  }

  // Which simplices of dimension d (1 or 2) are faces of one of dimension
  // d + 1, indexed by simplex (in scratch.isFace). The facets of every
  // simplex one dimension up are listed under their lowest vertex by a
  // counting sort in flat arrays, each as its other vertices (one id for an
  // edge, two packed in a word for a triangle); a simplex is a face if its
  // other vertices are in its lowest vertex's list. Flat passes, since
  // walking the vertices' linked incidence lists instead is a chain of
  // dependent cache misses per vertex on a large complex. Long lists (a
  // vertex in very many simplices) are sorted and searched by bisection,
  // so the test stays O(n log n) however the simplices gather.
  template <int d, class Rest>
  const std::vector<uint8_t>& facesOfHigher(std::vector<Rest>& rests) {
    static_assert(d == 1 || d == 2);
    std::vector<uint32_t>& start = scratch.facetStart;
    start.assign(size_t(nextVertex) + 1, 0);
    // The vertices of a simplex of dimension d, ascending, split into the
    // lowest and the rest.
    auto split = [](const uint32_t* v, uint32_t& low, Rest& rest) {
      uint32_t sorted[3] = {v[0], v[1], d == 2 ? v[2] : 0};
      std::sort(sorted, sorted + d + 1);
      low = sorted[0];
      rest = d == 1 ? Rest(sorted[1]) : Rest(uint64_t(sorted[1]) << 32 | sorted[2]);
    };
    auto forEachFacet = [this, &split](auto&& visit) {
      for (uint32_t higher = 0; higher < store.size(d + 1); ++higher) {
        if (!(store.flags(d + 1, higher) & SimplexStore::kAlive)) continue;
        const uint32_t* v = store.vertices(d + 1, higher);
        for (int skip = 0; skip <= d + 1; ++skip) {
          uint32_t facet[3] = {0, 0, 0};
          for (int k = 0, n = 0; k <= d + 1; ++k)
            if (k != skip) facet[n++] = v[k];
          uint32_t low;
          Rest rest;
          split(facet, low, rest);
          visit(low, rest);
        }
      }
    };
    forEachFacet([&](uint32_t low, Rest) { ++start[size_t(low) + 1]; });
    for (size_t v = 1; v < start.size(); ++v) start[v] += start[v - 1];
    rests.resize(start.back());
    // Filling moves each list's start to its end: list v is then
    // [start[v - 1], start[v]).
    forEachFacet([&](uint32_t low, Rest rest) { rests[start[low]++] = rest; });
    auto list = [&](uint32_t low) {
      return std::make_pair(rests.data() + (low == 0 ? 0 : start[low - 1]), rests.data() + start[low]);
    };
    for (uint32_t v = 0; v < nextVertex; ++v) {
      const auto [first, last] = list(v);
      if (last - first > kLongFacetList) std::sort(first, last);
    }
    std::vector<uint8_t>& isFace = scratch.isFace;
    isFace.assign(store.size(d), 0);
    for (uint32_t simplex = 0; simplex < store.size(d); ++simplex) {
      if (!(store.flags(d, simplex) & SimplexStore::kAlive)) continue;
      uint32_t low;
      Rest rest;
      split(store.vertices(d, simplex), low, rest);
      const auto [first, last] = list(low);
      isFace[simplex] = last - first > kLongFacetList ? std::binary_search(first, last, rest)
                                                       : std::find(first, last, rest) != last;
    }
    return isFace;
  }
  static constexpr ptrdiff_t kLongFacetList = 32;

  // Appends the maximal simplices of the current complex, oriented, and its
  // isolated vertices.
  void appendSimplices(Complex& out) {
    std::vector<uint32_t>* lists[4] = {nullptr, &out.edges, &out.triangles, &out.tetrahedra};
    for (int d = 1; d <= 3; ++d) {
      std::vector<uint32_t>& list = *lists[d];
      std::vector<int32_t>& labels = out.labels.of(d);
      // Once complete, the header says how many simplices of a dimension
      // are maximal: none, or all of them, spares the test (a pure triangle
      // mesh has no maximal edges and only maximal triangles).
      const uint32_t maximal = header.simplexCounts[size_t(d)];
      const bool finished = complete();
      if (finished && maximal == 0) continue;
      // A simplex can be a face only while simplices one dimension up exist.
      const bool testFaces = d < 3 && store.liveCount(d + 1) > 0 && (!finished || maximal != store.liveCount(d));
      list.reserve(size_t(finished ? maximal : store.liveCount(d)) * size_t(d + 1));
      if (header.labelled) labels.reserve(finished ? maximal : store.liveCount(d));
      const std::vector<uint8_t>& isFace = !testFaces ? scratch.isFace
                                           : d == 1      ? facesOfHigher<1>(scratch.edgeFacets)
                                                         : facesOfHigher<2>(scratch.triangleFacets);
      for (uint32_t simplex = 0; simplex < store.size(d); ++simplex) {
        if (!(store.flags(d, simplex) & SimplexStore::kAlive)) continue;
        if (testFaces && isFace[simplex]) continue;
        const uint32_t* v = store.vertices(d, simplex);
        const size_t at = list.size();
        list.insert(list.end(), v, v + d + 1);
        if (store.flags(d, simplex) & SimplexStore::kFlipped) std::swap(list[at], list[at + 1]);
        if (header.labelled) {
          // A split that failed on corrupt data may have left a simplex
          // without a label: a snapshot after the error still shows it.
          const uint32_t index = store.label(d, simplex);
          labels.push_back(index < labelTable.size() ? labelTable[index] : 0);
        }
      }
    }
    for (uint32_t v = 0; v < nextVertex; ++v)
      if (!store.hasIncident(1, v)) out.points.push_back(v);
  }

  // Integer coordinate range [lo, hi] along `axis` of a cell at `cellLevel`,
  // clamped to the coded bounding box.
  void cellRange(const Cell& cell, int cellLevel, int axis, uint32_t& lo, uint32_t& hi) const {
    cellLevel = std::min(cellLevel, schedule->levels);
    const int free = schedule->bits[size_t(axis)] - schedule->consumed[size_t(cellLevel)][size_t(axis)];
    const uint64_t low = uint64_t(cell.prefix[axis]) << free;
    const uint64_t high = low + ((uint64_t(1) << free) - 1);
    lo = uint32_t(low);
    hi = uint32_t(std::min<uint64_t>(high, header.gridMax[size_t(axis)]));
  }

  template <class Visit>
  void forEachCurrentCell(Visit visit) const {
    for (const Cell& c : children) visit(c, level + 1);
    for (size_t i = cursor; i < cells.size(); ++i) visit(cells[i], level);
    for (size_t i = 0; i < singles.size(); ++i)
      visit(singles[i], i >= singleCursor && i < singleLevelEnd ? level : level + 1);
    for (const Cell& c : newSingles) visit(c, level + 1);
  }

  // Each vertex at its cell's centre (once its cell is a grid point, where
  // it is), by vertex id (streams whose vertices have ids).
  void cellPositions(std::vector<float>& positions) const {
    positions.resize(size_t(nextVertex) * 3);
    forEachCurrentCell([&](const Cell& cell, int cellLevel) {
      for (int a = 0; a < 3; ++a) {
        uint32_t lo, hi;
        cellRange(cell, cellLevel, a, lo, hi);
        positions[size_t(cell.vertex) * 3 + size_t(a)] = dequantizer->position(a, lo, hi);
      }
    });
  }

  // Cells of the current level; once complete, the vertices.
  uint32_t cellCount() const {
    if (complete()) return header.vertexCount;
    return uint32_t(children.size() + cells.size() - cursor + singles.size() + newSingles.size());
  }

  // The vertices of an unfinished complex where their neighbours say they
  // lie (CoarsePlacement::Predicted): each cell centre moved along the
  // vertex's normal (the sum of its triangles' oriented area vectors)
  // halfway to the plane through its neighbours' centroid, then clamped to
  // the cell. Moving along the normal alone keeps the surface from
  // shrinking tangentially, as a plain neighbour average would at
  // boundaries and tips; moving halfway, since the plane through coarse
  // neighbours cuts across convex parts and spans concave ones, where the
  // surface lies between it and the cell centre. A vertex in no triangle
  // goes halfway to its neighbours' centroid; one in no edge stays at its
  // cell's centre. Float32 streams place in float values, whose cells are
  // intervals too.
  static constexpr double kPlaneShare = 0.5;
  void placeOnNeighbourPlanes(std::vector<float>& positions) {
    const size_t n = nextVertex;
    // Floats: the cells' bounds are floats, and the sums need no more for
    // a picture (half the memory to touch).
    std::vector<float>&centre = scratch.centre, &low = scratch.low, &high = scratch.high;
    std::vector<float>&sum = scratch.sum, &normal = scratch.normal;
    std::vector<uint32_t>& degree = scratch.degree;
    centre.resize(n * 3);
    low.resize(n * 3);
    high.resize(n * 3);
    sum.assign(n * 3, 0.0f);
    degree.assign(n, 0);
    forEachCurrentCell([&](const Cell& cell, int cellLevel) {
      for (int a = 0; a < 3; ++a) {
        uint32_t lo, hi;
        cellRange(cell, cellLevel, a, lo, hi);
        const size_t i = size_t(cell.vertex) * 3 + size_t(a);
        low[i] = dequantizer->position(a, lo, lo);
        high[i] = dequantizer->position(a, hi, hi);
        centre[i] = dequantizer->position(a, lo, hi);
      }
    });
    for (uint32_t edge = 0; edge < store.size(1); ++edge) {
      if (!(store.flags(1, edge) & SimplexStore::kAlive)) continue;
      const uint32_t* v = store.vertices(1, edge);
      const size_t i = size_t(v[0]) * 3, j = size_t(v[1]) * 3;
      for (size_t a = 0; a < 3; ++a) {
        sum[i + a] += centre[j + a];
        sum[j + a] += centre[i + a];
      }
      ++degree[v[0]];
      ++degree[v[1]];
    }
    sumTriangleNormals(centre, normal);
    positions.resize(n * 3);
    for (size_t v = 0; v < n; ++v) {
      const size_t i = v * 3;
      double target[3] = {centre[i], centre[i + 1], centre[i + 2]};
      if (degree[v] > 0) {
        double offset[3];
        for (size_t a = 0; a < 3; ++a) offset[a] = sum[i + a] / double(degree[v]) - centre[i + a];
        const double m[3] = {normal[i], normal[i + 1], normal[i + 2]};
        const double squared = m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
        const double along = squared > 0 ? (m[0] * offset[0] + m[1] * offset[1] + m[2] * offset[2]) / squared : 0;
        for (size_t a = 0; a < 3; ++a) target[a] += kPlaneShare * (squared > 0 ? along * m[a] : offset[a]);
      }
      // A float32 stream's infinite or NaN neighbours make no target: the
      // vertex stays at its cell's centre. A cell bound that is not finite
      // compares false, which leaves that side open, as the cell is.
      for (size_t a = 0; a < 3; ++a)
        positions[i + a] = std::isfinite(target[a])
                               ? float(std::clamp(target[a], double(low[i + a]), double(high[i + a])))
                               : centre[i + a];
    }
  }

  // Per vertex in `normal` (3 floats), the sum of the oriented area
  // vectors of the complex's triangles around it, over `positions`.
  void sumTriangleNormals(const std::vector<float>& positions, std::vector<float>& normal) {
    normal.assign(positions.size(), 0.0f);
    for (uint32_t triangle = 0; triangle < store.size(2); ++triangle) {
      const uint8_t flags = store.flags(2, triangle);
      if (!(flags & SimplexStore::kAlive)) continue;
      const uint32_t* v = store.vertices(2, triangle);
      const float* p = &positions[size_t(v[0]) * 3];
      const float* q = &positions[size_t(v[1]) * 3];
      const float* r = &positions[size_t(v[2]) * 3];
      const double u[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]}, w[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
      const double sign = flags & SimplexStore::kFlipped ? -1.0 : 1.0;
      const double area[3] = {sign * (u[1] * w[2] - u[2] * w[1]), sign * (u[2] * w[0] - u[0] * w[2]),
                              sign * (u[0] * w[1] - u[1] * w[0])};
      for (int k = 0; k < 3; ++k)
        for (size_t a = 0; a < 3; ++a) normal[size_t(v[k]) * 3 + a] += float(area[a]);
    }
  }

  // Until their values arrive, the vertices of attributes coded after the
  // kd-tree show the normals of their triangles in the snapshot `out` (a
  // vertex in none keeps its parent's values).
  void holdTriangleNormals(Complex& out, size_t attributeCount) {
    if (!afterGeometry || nextAfterGeometry >= nextVertex) return;
    std::vector<float>& normal = scratch.normal;
    sumTriangleNormals(out.positions, normal);
    for (size_t a = 0; a < attributeCount; ++a) {
      if (!attributeCoder->codedAfterGeometry(a)) continue;
      const size_t bytes = attributes[a].valueBytes();
      for (uint32_t v = nextAfterGeometry; v < nextVertex; ++v) {
        const double direction[3] = {normal[size_t(v) * 3], normal[size_t(v) * 3 + 1], normal[size_t(v) * 3 + 2]};
        if (direction[0] != 0 || direction[1] != 0 || direction[2] != 0)
          attributeCoder->holdDirection(a, direction, out.attributes[a].values.data() + size_t(v) * bytes);
      }
    }
  }

  // Replaces `out` with the model at the current level (Decoder::snapshot):
  // snapshotStream's, then, in a float64 stream, the doubles from the
  // residual attributes (exact once complete; the float32 positions widened
  // before that), which are left out of the attributes (and, before
  // completion, not copied at all).
  void snapshot(Complex& out, bool takeFinal) {
    const bool float64 = hasHeader && header.float64();
    const bool residuals = float64 && attributes.size() >= 2;  // the attribute table has arrived
    const bool join = residuals && complete();
    snapshotStream(out, takeFinal, residuals && !join ? attributes.size() - 2 : attributes.size());
    out.positions64.clear();
    if (!float64) return;
    if (!join) {
      out.positions64.assign(out.positions.begin(), out.positions.end());
      return;
    }
    const size_t user = out.attributes.size() - 2;
    joinFloat64(out.positions, out.attributes[user], out.attributes[user + 1], out.positions64);
    out.attributes.resize(user);
  }

  // The stream's vertices (float32 positions), simplices and first
  // `attributeCount` attributes; once complete, `takeFinal` moves the
  // simplex lists out instead of copying them, for decode(), whose decoder
  // is discarded next (the copy was 12 bytes per triangle of peak memory).
  void snapshotStream(Complex& out, bool takeFinal, size_t attributeCount) {
    // Emptied, not replaced: a caller that snapshots level after level into
    // one Complex reuses its memory.
    for (std::vector<uint32_t>* list : {&out.points, &out.edges, &out.triangles, &out.tetrahedra}) list->clear();
    for (int d = 1; d <= 3; ++d) out.labels.of(d).clear();
    out.positions.clear();
    if (!hasHeader) return;
    const bool finished = complete();
    // Attributes: the descriptors, then values vertex by vertex in the
    // snapshot's order (by id with connectivity, else by cell).
    out.attributes.resize(attributeCount);
    for (size_t a = 0; a < attributeCount; ++a) {
      out.attributes[a].name = attributes[a].name;
      out.attributes[a].type = attributes[a].type;
      out.attributes[a].components = attributes[a].components;
      out.attributes[a].quantization = attributes[a].quantization;
      out.attributes[a].values.clear();
      if (connectivity) {
        const uint8_t* values = attributes[a].values.data();
        out.attributes[a].values.assign(values, values + size_t(nextVertex) * attributes[a].valueBytes());
      }
    }
    if (connectivity) {
      if (!kdTreeComplete() && options.coarsePlacement == CoarsePlacement::Predicted) {
        placeOnNeighbourPlanes(out.positions);
        appendSimplices(out);
        holdTriangleNormals(out, attributeCount);
        return;
      }
      cellPositions(out.positions);
      if (!finished) {
        appendSimplices(out);
        holdTriangleNormals(out, attributeCount);
        return;
      }
      std::vector<uint32_t>* from[4] = {&finalComplex.points, &finalComplex.edges, &finalComplex.triangles,
                                        &finalComplex.tetrahedra};
      std::vector<uint32_t>* to[4] = {&out.points, &out.edges, &out.triangles, &out.tetrahedra};
      for (int i = 0; i < 4; ++i) *to[i] = takeFinal ? std::move(*from[i]) : *from[i];
      for (int d = 1; d <= 3; ++d)
        out.labels.of(d) = takeFinal ? std::move(finalComplex.labels.of(d)) : finalComplex.labels.of(d);
      return;
    }
    out.positions.reserve(size_t(cellCount()) * 3);
    forEachCurrentCell([&](const Cell& cell, int cellLevel) {
      float position[3];
      for (int a = 0; a < 3; ++a) {
        uint32_t lo, hi;
        cellRange(cell, cellLevel, a, lo, hi);
        position[a] = dequantizer->position(a, lo, hi);
      }
      // A finished cell holds coincident vertices; before that it is one
      // vertex. (With attributes, coincident vertices have cells of their own.)
      const uint32_t copies = finished ? cell.population : 1;
      for (uint32_t i = 0; i < copies; ++i) out.positions.insert(out.positions.end(), position, position + 3);
      for (size_t a = 0; a < attributeCount; ++a) {
        const size_t bytes = attributes[a].valueBytes();
        const uint8_t* values = attributes[a].values.data() + size_t(cell.vertex) * bytes;
        out.attributes[a].values.insert(out.attributes[a].values.end(), values, values + bytes);
      }
    });
    const uint32_t n = uint32_t(out.vertexCount());
    out.points.resize(n);
    for (uint32_t i = 0; i < n; ++i) out.points[i] = i;
  }

  // Applies the header and every whole chunk at the start of `data`; returns
  // in `offset` how many bytes that used.
  Status process(const uint8_t* data, size_t size, size_t& offset) {
    offset = 0;
    Status status;
    while (status.ok()) {
      const size_t available = size - offset;
      const uint8_t* at = data + offset;
      if (!hasHeader) {
        if (available < kHeaderPrefixBytes) break;
        size_t headerBytes = 0;
        status = headerSize(at, headerBytes);
        if (!status.ok() || available < headerBytes) break;
        status = readHeader(at, headerBytes, options.limits, header);
        if (status.ok()) status = startBody(available);
        offset += headerBytes;
        bytesConsumed += headerBytes;
        continue;
      }
      if (!attributeTableRead) {
        size_t tableBytes = 0;
        const Parsed read = readAttributeTable(at, available, header.attributeCount, attributes, tableBytes, status);
        if (read == Parsed::Incomplete) break;
        if (read == Parsed::Malformed) break;
        if (header.float64() && !areResidualAttributes(attributes[attributes.size() - 2], attributes.back())) {
          status = Status::error(ErrorCode::CorruptHeader,
                                 "corrupt attribute table: a float64 stream must end it with its residuals");
          break;
        }
        attributeCoder.emplace(attributes);
        for (size_t a = 0; a < attributes.size(); ++a) afterGeometry |= attributeCoder->codedAfterGeometry(a);
        cost.attributeBits.assign(attributes.size(), 0.0);
        attributeTableRead = true;
        offset += tableBytes;
        bytesConsumed += tableBytes;
        if (header.chunkCount == 0 && bytesConsumed != header.totalBytes())
          status = Status::error(ErrorCode::CorruptHeader, "corrupt attribute table: the header announced " +
                                                               std::to_string(header.totalBytes()) + " bytes");
        continue;
      }
      if (!labelTableRead) {
        size_t tableBytes = 0;
        const uint64_t simplices = uint64_t(header.simplexCounts[1]) + header.simplexCounts[2] + header.simplexCounts[3];
        const Parsed read = readLabelTable(at, available, simplices, labelTable, tableBytes, status);
        if (read != Parsed::Complete) break;
        splitter->enableLabels(uint32_t(labelTable.size()));
        labelTableRead = true;
        offset += tableBytes;
        bytesConsumed += tableBytes;
        continue;
      }
      if (chunks.size() == header.chunkCount) {
        if (available > 0)
          status = Status::error(ErrorCode::TrailingBytes,
                                 std::to_string(available) + " bytes after the end of the stream");
        break;
      }
      ChunkFrame frame;
      size_t frameBytes = 0;
      const Parsed read = readChunkFrame(at, available, frame, frameBytes);
      if (read == Parsed::Incomplete) break;
      const uint64_t chunkBytes = frameBytes + uint64_t(frame.payloadBytes) + kChunkChecksumBytes;
      const uint64_t end = bytesConsumed + chunkBytes;
      if (read == Parsed::Malformed || frame.payloadBytes > options.limits.maxChunkBytes ||
          end > header.totalBytes() || frame.splitCount == 0 ||
          frame.splitCount > kMaxSplitsPerByte * (uint64_t(frame.payloadBytes) + 8)) {
        status = Status::error(ErrorCode::CorruptChunk,
                               "chunk " + std::to_string(chunks.size()) + ": invalid frame");
        break;
      }
      if (available < chunkBytes) break;
      status = applyChunk(at, frameBytes, frame);
      if (!status.ok()) break;
      chunks.push_back({bytesConsumed, frame.payloadBytes, frame.splitCount,
                        uint32_t(frameBytes + kChunkChecksumBytes)});
      offset += size_t(chunkBytes);
      bytesConsumed = end;
      if (chunks.size() == header.chunkCount && !complete())
        status = Status::error(ErrorCode::CorruptChunk,
                               "the last chunk ends before the kd-tree is complete");
      else if (chunks.size() == header.chunkCount && end != header.totalBytes())
        status = Status::error(ErrorCode::CorruptChunk,
                               "the last chunk ends at byte " + std::to_string(end) + ", the header announced " +
                                   std::to_string(header.totalBytes()));
    }
    return status;
  }
};

Decoder::Decoder(const DecoderOptions& options) : state_(std::make_unique<State>(options)) {}
Decoder::~Decoder() = default;
Decoder::Decoder(Decoder&&) noexcept = default;
Decoder& Decoder::operator=(Decoder&&) noexcept = default;

void Decoder::reset() { state_ = std::make_unique<State>(state_->options); }

Status Decoder::push(const uint8_t* data, size_t size) {
  State& s = *state_;
  if (!s.error.ok()) return s.error;
  s.bytesReceived += size;
  size_t used = 0;
  Status status;
  if (s.pending.empty()) {
    // The usual case of whole chunks in one piece: decode in place, keep the tail.
    status = s.process(data, size, used);
    if (status.ok()) s.pending.assign(data + used, data + size);
  } else {
    s.pending.insert(s.pending.end(), data, data + size);
    status = s.process(s.pending.data(), s.pending.size(), used);
    s.pending.erase(s.pending.begin(), s.pending.begin() + std::ptrdiff_t(used));
  }
  return status.ok() ? status : s.fail(status);
}

Status Decoder::finish() const {
  const State& s = *state_;
  if (!s.error.ok()) return s.error;
  if (!s.complete()) {
    std::string message = "stream truncated: received " + std::to_string(s.bytesReceived) + " bytes";
    if (s.hasHeader) message += " of " + std::to_string(s.header.totalBytes());
    return Status::error(ErrorCode::Truncated, message);
  }
  return Status::success();
}

bool Decoder::hasHeader() const { return state_->hasHeader; }
const Header& Decoder::header() const { return state_->header; }
bool Decoder::complete() const { return state_->complete(); }
const std::vector<ChunkInfo>& Decoder::chunks() const { return state_->chunks; }
CodingCost Decoder::cost() const {
  CodingCost cost = state_->cost;
  // A float64 stream's residual attributes are geometry.
  if (state_->hasHeader && state_->header.float64() && cost.attributeBits.size() >= 2) {
    cost.geometryBits += cost.attributeBits[cost.attributeBits.size() - 1] + cost.attributeBits[cost.attributeBits.size() - 2];
    cost.attributeBits.resize(cost.attributeBits.size() - 2);
  }
  return cost;
}
const std::vector<uint32_t>& Decoder::vertexParents() const { return state_->parents; }
const std::vector<int32_t>& Decoder::labels() const { return state_->labelTable; }
ConnectivityStatistics Decoder::statistics() const {
  if (!state_->splitter) return {};
  ConnectivityStatistics statistics = state_->splitter->statistics();
  state_->predictor->addStatistics(statistics);
  return statistics;
}

DecodeProgress Decoder::progress() const {
  const State& s = *state_;
  DecodeProgress p;
  p.bytesReceived = s.bytesReceived;
  p.bytesConsumed = s.bytesConsumed;
  p.bytesExpected = s.hasHeader ? s.header.totalBytes() : 0;
  p.chunksApplied = uint32_t(s.chunks.size());
  p.level = uint32_t(s.level);
  p.complete = s.complete();
  if (s.hasHeader) p.cellCount = s.cellCount();
  return p;
}

void Decoder::snapshot(Complex& out) const { state_->snapshot(out, false); }

Complex Decoder::snapshot() const {
  Complex c;
  snapshot(c);
  return c;
}

double Decoder::errorBound() const {
  const State& s = *state_;
  if (!s.hasHeader) return INFINITY;
  const double halfStep = s.header.quantization == Quantization::Grid ? s.header.step * 0.5 : 0;
  // A predicted vertex may lie anywhere in its cell; a centre, in its middle.
  const double share = s.connectivity && s.options.coarsePlacement == CoarsePlacement::Predicted ? 1.0 : 0.5;
  double worst = 0;
  s.forEachCurrentCell([&](const Cell& cell, int cellLevel) {
    double squared = 0;
    for (int a = 0; a < 3; ++a) {
      uint32_t lo, hi;
      s.cellRange(cell, cellLevel, a, lo, hi);
      const double half =
          (double(s.dequantizer->position(a, hi, hi)) - double(s.dequantizer->position(a, lo, lo))) * share +
          halfStep;
      // A float32 cell that holds NaNs has no bound.
      squared += std::isnan(half) ? INFINITY : half * half;
    }
    worst = std::max(worst, squared);
  });
  return std::sqrt(worst);
}

Status decode(const uint8_t* data, size_t size, Complex& out, bool allowPrefix,
              const DecoderOptions& options) {
  Decoder decoder(options);
  Status status = decoder.push(data, size);
  if (!status.ok()) return status;
  if (!allowPrefix)
    if (status = decoder.finish(); !status.ok()) return status;
  decoder.state_->snapshot(out, true);
  return Status::success();
}

}  // namespace kdmesh
