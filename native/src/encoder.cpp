// The encoder: quantize, order the vertices along the kd-tree, then code the
// count of every cell split, level by level, into checksummed chunks.
#include <algorithm>
#include <cstring>
#include <string>

#include "attributes.h"
#include "container.h"
#include "count_coder.h"
#include "decimation.h"
#include "encoder_internal.h"
#include "kd_order.h"
#include "labels.h"
#include "large_array.h"
#include "kdmesh/kdmesh.h"
#include "position_predictor.h"
#include "quantizer.h"
#include "range_coder.h"
#include "simplex_store.h"
#include "split_schedule.h"
#include "vertex_split.h"

namespace kdmesh {
namespace {

constexpr size_t kFirstChunkBytes = 1024;
constexpr size_t kMinChunkBytes = 64;
constexpr size_t kMaxChunkBytes = size_t(1) << 26;

// LimitExceeded when encodeMemoryEstimate() exceeds options.maxMemoryBytes.
Status checkMemory(const Complex& complex, const EncodeOptions& options) {
  const uint64_t needed = encodeMemoryEstimate(complex);
  if (options.maxMemoryBytes != 0 && needed > options.maxMemoryBytes)
    return Status::error(ErrorCode::LimitExceeded,
                         "encoding " + std::to_string(complex.vertexCount()) + " vertices and " +
                             std::to_string(complex.edges.size() / 2 + complex.triangles.size() / 3 +
                                            complex.tetrahedra.size() / 4) +
                             " simplices needs about " + std::to_string(needed >> 20) +
                             " MiB of working memory, more than the limit of " +
                             std::to_string(options.maxMemoryBytes >> 20) + " MiB");
  return Status::success();
}

Status checkOptions(const Complex& complex, const EncodeOptions& options) {
  if (!options.exact && (options.bits < 1 || options.bits > 30))
    return Status::error(ErrorCode::InvalidArgument,
                         "bits must be between 1 and 30, got " + std::to_string(options.bits));
  if (options.chunkBytes < kMinChunkBytes || options.chunkBytes > kMaxChunkBytes)
    return Status::error(ErrorCode::InvalidArgument,
                         "chunk size must be between " + std::to_string(kMinChunkBytes) +
                             " and " + std::to_string(kMaxChunkBytes) + " bytes");
  if (complex.positions.size() % 3 != 0)
    return Status::error(ErrorCode::InvalidArgument, "positions must hold 3 floats per vertex");
  if (complex.vertexCount() == 0)
    return Status::error(ErrorCode::InvalidInput, "the input has no vertices");
  if (complex.vertexCount() >= (size_t(1) << 31))
    return Status::error(ErrorCode::InvalidInput, "more than 2^31 - 1 vertices");
  if (Status status = checkLabels(complex); !status.ok()) return status;
  if (Status status = checkAttributes(complex); !status.ok()) return status;
  return checkMemory(complex, options);
}

// Writes chunks into the stream body: a frame, then the payload that the
// range coder produces, closed when it reaches the current target size,
// which starts at 1 KiB and grows by a quarter each chunk up to the largest
// chunk size. A prefix decodes whole chunks only, so the bytes of the last,
// partial chunk wait: growing by a quarter keeps them under a fifth of what
// has arrived (doubling, up to half), at some 12 bytes of frame, checksum
// and coder flush per chunk.
class ChunkWriter {
 public:
  ChunkWriter(std::vector<uint8_t>& body, size_t maxBytes)
      : body_(body), coder_(body), target_(std::min(kFirstChunkBytes, maxBytes)),
        maxBytes_(maxBytes) {
    coder_.setMeasuring(true);
    begin();
  }

  RangeEncoder& coder() { return coder_; }

  // Call after each split; closes the chunk once it is big enough.
  void splitDone() {
    ++splits_;
    if (coder_.blockBytes() >= target_) {
      end();
      target_ = std::min(target_ + target_ / 4, maxBytes_);
      begin();
    }
  }

  uint32_t finish() {
    if (splits_ > 0) end();
    body_.resize(frameAt_);  // drop the frame reserved for a chunk never used
    return chunks_;
  }

 private:
  // The payload is written after room for the longest frame; the frame,
  // once known, goes right before it.
  void begin() {
    frameAt_ = body_.size();
    body_.resize(frameAt_ + kMaxChunkFrameBytes);
    coder_.restart();
    splits_ = 0;
  }

  void end() {
    coder_.finish();
    const size_t payloadAt = frameAt_ + kMaxChunkFrameBytes;
    const ChunkFrame frame{uint32_t(body_.size() - payloadAt), splits_};
    const size_t frameBytes = writeChunkFrame(frame, body_.data() + frameAt_);
    body_.erase(body_.begin() + std::ptrdiff_t(frameAt_ + frameBytes), body_.begin() + std::ptrdiff_t(payloadAt));
    const size_t checked = body_.size() - frameAt_;
    body_.resize(body_.size() + kChunkChecksumBytes);
    writeChunkChecksum(body_.data() + frameAt_, checked, chunks_, body_.data() + frameAt_ + checked);
    ++chunks_;
    frameAt_ = body_.size();
  }

  std::vector<uint8_t>& body_;
  RangeEncoder coder_;
  size_t target_;
  size_t maxBytes_;
  size_t frameAt_ = 0;
  uint32_t splits_ = 0;
  uint32_t chunks_ = 0;
};

// Visits the kd-tree splits in the decoder's order (docs/FORMAT.md) and names
// the vertices as the decoder will: the root is vertex 0, and a cell that
// splits into two non-empty halves gives its id to the first half and the
// next unused id to the second. With `coincidentLevels`, cells that still
// hold several vertices after the last level go on splitting in halves, so
// that coincident vertices get their own ids.
//
// The visitor sees cell(level, geometric, population, firstHalf,
// parentOneSided, keptId, addedId, firstKey) for cells of several vertices
// (addedId is kNoSimplex for a one-sided split; the cell holds the keys from
// index firstKey on), placed(id, prefix, level) for each
// non-empty half of a geometric split, single(level, parentOneSided,
// inFirstHalf, id) for one-vertex cells, named(keyIndex, id) when a vertex
// gets its final id, splitDone() after each split, and levelDone(level,
// cells) after the last split of each level, whose cells it counts. At
// geometric levels, coming(ids, count) precedes every kComingBatch-th cell
// of each list with the vertices of that cell and the next ones, for
// prefetching.
template <class Visitor>
void traverseKdTree(const std::vector<KdKey>& keys, const SplitSchedule& schedule,
                    bool coincidentLevels, Visitor&& visitor) {
  struct Cell {
    uint32_t begin, end, id;
    bool parentOneSided;
    uint32_t prefix[3];
  };
  struct Single {
    uint32_t key, id;
    bool parentOneSided;
  };
  // The vertices of the kComingBatch cells (or one-vertex cells) of a
  // geometric level's list from `at` on go to visitor.coming().
  static constexpr size_t kComingBatch = 32;
  auto announce = [&visitor](const auto& list, size_t at) {
    uint32_t ids[kComingBatch];
    const size_t count = std::min(kComingBatch, list.size() - at);
    for (size_t k = 0; k < count; ++k) ids[k] = list[at + k].id;
    visitor.coming(ids, count);
  };
  const uint32_t n = uint32_t(keys.size());
  LargeArray<Cell> cells, children;
  LargeArray<Single> singles;
  uint32_t nextId = 1;
  if (n == 1) {
    singles.push_back({0, 0, false});
    visitor.named(0, 0);
  } else {
    cells.push_back({0, n, 0, false, {0, 0, 0}});
  }
  const uint32_t root[3] = {0, 0, 0};
  visitor.placed(0, root, 0);
  for (int level = 0;; ++level) {
    const bool geometric = level < schedule.levels;
    if (!geometric && (!coincidentLevels || cells.empty())) break;
    const int bit = schedule.levels - 1 - level;
    const size_t oldSingles = singles.size();
    const size_t singleLevelEnd = geometric ? oldSingles : 0;
    children.clear();
    for (size_t c = 0; c < cells.size(); ++c) {
      const Cell& cell = cells[c];
      if (geometric && c % kComingBatch == 0) announce(cells, c);
      const uint32_t population = cell.end - cell.begin;
      const uint32_t split =
          geometric ? uint32_t(std::partition_point(keys.begin() + cell.begin, keys.begin() + cell.end,
                                                    [bit](KdKey k) { return ((k >> bit) & 1) == 0; }) -
                               keys.begin())
                    : cell.begin + population / 2;
      const uint32_t firstHalf = split - cell.begin;
      const bool oneSided = firstHalf == 0 || firstHalf == population;
      const uint32_t addedId = oneSided ? kNoSimplex : nextId++;
      visitor.cell(level, geometric, population, firstHalf, cell.parentOneSided, cell.id, addedId, cell.begin);
      Cell halves[2] = {{cell.begin, split, cell.id, oneSided, {cell.prefix[0], cell.prefix[1], cell.prefix[2]}},
                        {split, cell.end, oneSided ? cell.id : addedId, oneSided,
                         {cell.prefix[0], cell.prefix[1], cell.prefix[2]}}};
      if (geometric) {
        const int axis = schedule.axis[size_t(level)];
        halves[0].prefix[axis] = cell.prefix[axis] << 1;
        halves[1].prefix[axis] = cell.prefix[axis] << 1 | 1;
        for (const Cell& half : halves)
          if (half.end > half.begin) visitor.placed(half.id, half.prefix, level + 1);
      }
      for (const Cell& half : halves) {
        if (half.end - half.begin == 1) {
          singles.push_back({half.begin, half.id, oneSided});
          visitor.named(half.begin, half.id);
        } else if (half.end > half.begin) {
          children.push_back(half);
        }
      }
      visitor.splitDone();
    }
    for (size_t i = 0; i < singleLevelEnd; ++i) {
      if (i % kComingBatch == 0) announce(singles, i);
      Single& single = singles[i];
      visitor.single(level, single.parentOneSided, ((keys[single.key] >> bit) & 1) == 0, single.id);
      single.parentOneSided = true;
      visitor.splitDone();
    }
    visitor.levelDone(level, uint32_t(cells.size() + singleLevelEnd));
    std::inplace_merge(singles.begin(), singles.begin() + std::ptrdiff_t(oldSingles),
                       singles.end(), [](const Single& a, const Single& b) { return a.key < b.key; });
    std::swap(cells, children);
  }
}

// Supplies the decimation's records of one split, in order.
template <class T>
struct RecordReader {
  const T* next;
  T operator()() { return *next++; }
};

// The final states of the models and mixers, for learning their priors
// (tools/train_priors.cpp).
void exportModels(PositionPredictor& predictor, CountCoder& counts, VertexSplitter& splitter,
                  TrainedModels& out) {
  auto keep = [&out](ModelFamily family, const BitModel* models) {
    out.families[size_t(family)].assign(models, models + kFamilySize[size_t(family)]);
  };
  auto keepMixer = [&out](MixerFamily family, const auto& mixer) {
    std::vector<int32_t>& weights = out.mixerWeights[size_t(family)];
    weights.clear();
    mixer.appendWeights(weights);
    out.mixerUses[size_t(family)] = mixer.uses();
  };
  predictor.forEachFamily(keep);
  counts.forEachFamily(keep);
  splitter.forEachFamily(keep);
  predictor.forEachMixer(keepMixer);
  counts.forEachMixer(keepMixer);
  splitter.forEachMixer(keepMixer);
}

}  // namespace

uint64_t encodeMemoryEstimate(const Complex& complex) {
  // Peak resident bytes per vertex and per listed edge, triangle and
  // tetrahedron (their faces included), fitted to kdmesh encode runs.
  constexpr uint64_t kPerVertex = 110, kPerEdge = 150, kPerTriangle = 200, kPerTetrahedron = 360;
  uint64_t bytes = uint64_t(complex.vertexCount()) * kPerVertex + uint64_t(complex.edges.size() / 2) * kPerEdge +
                   uint64_t(complex.triangles.size() / 3) * kPerTriangle +
                   uint64_t(complex.tetrahedra.size() / 4) * kPerTetrahedron;
  for (const VertexAttribute& attribute : complex.attributes) bytes += attribute.values.size();
  // Labels: the input's and the store's, 4 bytes each.
  bytes += 8 * uint64_t(complex.labels.edges.size() + complex.labels.triangles.size() +
                        complex.labels.tetrahedra.size());
  // Float64: the doubles, and the copy that exact encoding codes (float32
  // positions, 24 bytes of residuals per vertex, lists, labels, values).
  if (!complex.positions64.empty()) {
    bytes += 8 * uint64_t(complex.positions64.size()) + uint64_t(complex.vertexCount()) * (12 + 24) +
             4 * uint64_t(complex.edges.size() + complex.triangles.size() + complex.tetrahedra.size() +
                          complex.points.size() + complex.labels.edges.size() + complex.labels.triangles.size() +
                          complex.labels.tetrahedra.size());
    for (const VertexAttribute& attribute : complex.attributes) bytes += attribute.values.size();
  }
  return bytes;
}

EncodeResult encode(const Complex& complex, const EncodeOptions& options) {
  return encode(complex, options, nullptr);
}

namespace {

// Encodes `complex`'s float32 positions; a float64 stream (`float64`) has
// its residual attributes last among complex.attributes.
EncodeResult encodeStream(const Complex& complex, const EncodeOptions& options, TrainedModels* finalModels,
                          bool float64) {
  EncodeResult result;
  if (result.status = checkOptions(complex, options); !result.status.ok()) return result;
  std::vector<AttributeQuantization> quantization;  // how each attribute is coded
  if (result.status = chooseQuantization(complex, options, quantization); !result.status.ok()) return result;
  auto report = [&](const char* phase, double fraction) {
    if (options.progress) options.progress({phase, fraction});
  };

  Header header;
  header.version = kFormatVersion;
  header.vertexCount = uint32_t(complex.vertexCount());
  std::vector<uint32_t> coords;
  report("quantize", 0);
  if (result.status = quantize(complex.positions, options, header, coords); !result.status.ok())
    return result;
  if (float64) header.bits = 64;
  const SplitSchedule schedule(header);
  report("sort", 0);
  KdOrder order = kdOrder(coords, schedule);
  bool afterGeometry = false;  // attributes coded once the kd-tree is complete, which need the positions
  for (const AttributeQuantization& q : quantization)
    afterGeometry |= q.kind == AttributeQuantization::GeometricOctahedral;
  if (!afterGeometry) coords = {};

  // Connectivity, fine to coarse: name the vertices as the decoder will,
  // build the input complex on those names, and merge cells in the reverse
  // of the split order.
  SplitRecords records;
  std::vector<int32_t> labelTable;  // of the kept simplices
  bool connectivity = complex.hasSimplices();
  // Vertices with attributes need ids, and coincident ones ids of their own.
  const bool named = !complex.attributes.empty();
  std::vector<uint32_t> inputOfId;  // with connectivity and attributes
  if (connectivity) {
    report("connectivity", 0);
    std::vector<uint32_t> ids(header.vertexCount);
    std::vector<VertexSplitIds> splits;
    struct Naming {
      std::vector<uint32_t>& ids;
      std::vector<VertexSplitIds>& splits;
      const std::vector<uint32_t>& vertexOfKey;
      void cell(int, bool, uint32_t, uint32_t, bool, uint32_t kept, uint32_t added, uint32_t) {
        if (added != kNoSimplex) splits.push_back({kept, added});
      }
      void placed(uint32_t, const uint32_t*, int) {}
      void single(int, bool, bool, uint32_t) {}
      void coming(const uint32_t*, size_t) {}
      void named(uint32_t key, uint32_t id) { ids[vertexOfKey[key]] = id; }
      void splitDone() {}
      void levelDone(int, uint32_t) {}
    } naming{ids, splits, order.vertices};
    traverseKdTree(order.keys, schedule, true, naming);
    if (named) {
      inputOfId.resize(ids.size());
      for (uint32_t input = 0; input < ids.size(); ++input) inputOfId[ids[input]] = input;
    }
    std::vector<uint32_t> kdRank(ids.size());
    for (uint32_t r = 0; r < order.vertices.size(); ++r) kdRank[ids[order.vertices[r]]] = r;
    SimplexStore store;
    InputSummary summary;
    if (result.status = buildInputComplex(complex, ids, kdRank, store, summary); !result.status.ok())
      return result;
    result.repairs = summary.repairs;
    connectivity = summary.maxDimension > 0;
    header.maxDimension = uint8_t(summary.maxDimension);
    for (size_t d = 0; d < 4; ++d) header.simplexCounts[d] = summary.maximal[d];
    if (connectivity) labelTable = std::move(summary.labelTable);
    header.labelled = !labelTable.empty();
    if (connectivity)
      decimate(store, splits, records, [&](double f) { report("connectivity", f); });
  }
  if (!connectivity) header.simplexCounts[0] = header.vertexCount;

  // Coarse to fine: the counts and, after each vertex split, its codes and
  // its new vertex's attributes. The attribute table comes first.
  std::vector<uint8_t> body;
  header.attributeCount = uint8_t(complex.attributes.size());
  if (named) writeAttributeTable(complex.attributes, quantization, order.vertices[0], body);
  if (header.labelled) writeLabelTable(labelTable, body);
  AttributeCoder attributeCoder(complex.attributes, &quantization);
  const std::vector<std::vector<uint8_t>> held = heldValues(complex.attributes, quantization);
  result.cost.attributeBits.assign(complex.attributes.size(), 0.0);
  ChunkWriter chunks(body, options.chunkBytes);
  RangeEncoder& coder = chunks.coder();
  header.fastDecode = options.fastDecode;
  CountCoder counts(schedule.levels, connectivity);
  SimplexStore forward;
  forward.reset(header.vertexCount, false);
  PositionPredictor predictor(schedule, forward, header.fastDecode);
  VertexSplitter splitter(forward, predictor);
  if (header.labelled) {
    forward.enableLabels();
    splitter.enableLabels(uint32_t(labelTable.size()));
  }
  size_t splitIndex = 0;
  double connectivityBits = 0;
  struct Coding {
    const Header& header;
    const SplitSchedule& schedule;
    CountCoder& counts;
    RangeEncoder& coder;
    ChunkWriter& chunks;
    VertexSplitter& splitter;
    SimplexStore& forward;
    PositionPredictor& predictor;
    const SplitRecords& records;
    size_t& splitIndex;
    double& connectivityBits;
    bool connectivity;
    std::function<void(const char*, double)> report;
    std::vector<LevelCost>& levels;
    const std::vector<VertexAttribute>& attributes;
    const std::vector<std::vector<uint8_t>>& held;  // heldValues() of the attributes
    const std::vector<uint32_t>& vertexOfKey;
    AttributeCoder& attributeCoder;
    std::vector<double>& attributeBits;
    const std::vector<uint32_t>& inputOfId;  // connectivity streams
    std::vector<uint32_t> neighbours{};
    int reportedLevel = -1;
    LevelCostTally levelCosts{};

    void cell(int level, bool geometric, uint32_t population, uint32_t firstHalf,
              bool parentOneSided, uint32_t kept, uint32_t added, uint32_t firstKey) {
      if (level != reportedLevel) {
        reportedLevel = level;
        report("code", double(level) / double(schedule.levels + 1));
      }
      if (geometric)
        counts.code(coder, population, level, parentOneSided, firstHalf,
                    connectivity ? predictor.countContext(kept, level, parentOneSided) : CountContext{});
      if (connectivity && added != kNoSimplex) {
        const double before = coder.cost();
        splitter.split(coder, kept, added, level, splitBalance(population, firstHalf, geometric),
                       RecordReader<uint8_t>{&records.bytes[records.begin[splitIndex]]},
                       RecordReader<uint32_t>{records.labelBegin.empty()
                                                  ? nullptr
                                                  : records.labels.data() + records.labelBegin[splitIndex]});
        ++splitIndex;
        connectivityBits += coder.cost() - before;
      }
      // The second half's vertex: the values of its first input vertex,
      // against those of the cell's first (attributes coded after the
      // kd-tree wait).
      if (added != kNoSimplex && !attributes.empty()) {
        const uint32_t parent = vertexOfKey[firstKey], child = vertexOfKey[firstKey + firstHalf];
        neighbours.clear();
        if (connectivity)
          forward.forEachIncident(1, added, [&](uint32_t edge, uint32_t position) {
            neighbours.push_back(forward.vertices(1, edge)[1 - position]);
          });
        for (size_t a = 0; a < attributes.size(); ++a) {
          if (attributeCoder.codedAfterGeometry(a)) continue;
          const uint8_t* values = held[a].empty() ? attributes[a].values.data() : held[a].data();
          const size_t bytes = attributes[a].valueBytes();
          AttributeCoder::Prediction prediction;
          uint8_t coded[16];
          attributeCoder.predict(a, neighbours, values + size_t(parent) * bytes,
                                 [&](uint32_t id) { return values + size_t(inputOfId[id]) * bytes; }, prediction);
          std::memcpy(coded, values + size_t(child) * bytes, bytes);
          const double before = coder.cost();
          attributeCoder.code(coder, a, prediction, coded);
          attributeBits[a] += coder.cost() - before;
        }
      }
    }
    void placed(uint32_t id, const uint32_t* prefix, int level) {
      if (connectivity) predictor.place(id, prefix, level);
    }
    void single(int level, bool parentOneSided, bool inFirstHalf, uint32_t id) {
      if (connectivity)
        predictor.codeSingle(coder, counts, id, level, parentOneSided, inFirstHalf);
      else
        counts.codeSingle(coder, level, parentOneSided, inFirstHalf);
    }
    // Fast streams: the predictions of these vertices come soon.
    void coming(const uint32_t* ids, size_t count) {
      if (connectivity && header.fastDecode) predictor.prefetchNeighbourhoods(ids, count);
    }
    void named(uint32_t, uint32_t) {}
    void splitDone() { chunks.splitDone(); }
    void levelDone(int level, uint32_t cells) {
      levelCosts.close(schedule, level, cells, coder.cost(), connectivityBits, levels);
    }
  } coding{header,      schedule,          counts,     coder,       chunks,     splitter,
           forward,     predictor,         records,    splitIndex,  connectivityBits, connectivity,
           report,      result.cost.levels, complex.attributes, held, order.vertices, attributeCoder,
           result.cost.attributeBits, inputOfId};
  traverseKdTree(order.keys, schedule, connectivity || named, coding);
  if (afterGeometry) {
    // Vertex by vertex, all but the root (whose values are in the table),
    // against the normal of its triangles at the decoded positions.
    const Dequantizer dequantizer(header);
    std::vector<float> positions(size_t(header.vertexCount) * 3);
    for (uint32_t id = 0; id < header.vertexCount; ++id)
      for (int a = 0; a < 3; ++a) {
        const uint32_t c = coords[size_t(inputOfId[id]) * 3 + size_t(a)];
        positions[size_t(id) * 3 + size_t(a)] = dequantizer.position(a, c, c);
      }
    std::vector<double> normals;
    triangleNormals(forward, positions, normals);
    std::vector<uint32_t> decoded;  // neighbours of lower ids
    for (uint32_t id = 1; id < header.vertexCount; ++id) {
      earlierNeighbours(forward, id, decoded);
      for (size_t a = 0; a < complex.attributes.size(); ++a) {
        if (!attributeCoder.codedAfterGeometry(a)) continue;
        const size_t bytes = complex.attributes[a].valueBytes();
        AttributeCoder::Prediction prediction;
        attributeCoder.predictFromTriangles(
            a, normals, id, decoded, [&](uint32_t n) { return held[a].data() + size_t(inputOfId[n]) * bytes; },
            prediction);
        uint8_t coded[16];
        std::memcpy(coded, held[a].data() + size_t(inputOfId[id]) * bytes, bytes);
        const double before = coder.cost();
        attributeCoder.code(coder, a, prediction, coded);
        result.cost.attributeBits[a] += coder.cost() - before;
      }
      chunks.splitDone();
    }
  }
  header.chunkCount = chunks.finish();
  header.bodyBytes = body.size();
  result.cost.labelBits = splitter.labelBits();
  result.cost.connectivityBits = connectivityBits - result.cost.labelBits;
  double attributeBits = 0;
  for (const double bits : result.cost.attributeBits) attributeBits += bits;
  result.cost.geometryBits = coder.cost() - connectivityBits - attributeBits;  // labels among connectivityBits
  result.statistics = splitter.statistics();
  if (finalModels && connectivity) exportModels(predictor, counts, splitter, *finalModels);

  predictor.addStatistics(result.statistics);
  report("code", 1);

  result.bytes.resize(kMaxHeaderBytes + body.size());
  const size_t headerBytes = writeHeader(header, result.bytes.data());
  result.bytes.resize(headerBytes);
  result.bytes.insert(result.bytes.end(), body.begin(), body.end());
  return result;
}

}  // namespace

EncodeResult encode(const Complex& complex, const EncodeOptions& options, TrainedModels* finalModels) {
  if (!options.exact || complex.positions64.empty()) return encodeStream(complex, options, finalModels, false);
  EncodeResult result;
  auto fail = [&](ErrorCode code, std::string message) {
    result.status = Status::error(code, std::move(message));
    return result;
  };
  if (complex.positions64.size() != complex.positions.size())
    return fail(ErrorCode::InvalidArgument, "positions64 must be empty or hold 3 doubles per vertex, as positions");
  if (complex.attributes.size() > kMaxAttributes - 2)
    return fail(ErrorCode::InvalidInput, "a float64 stream holds at most " + std::to_string(kMaxAttributes - 2) +
                                             " attributes (its coordinates' residuals take two)");
  for (const VertexAttribute& a : complex.attributes)
    if (a.name == kResidualNames[0] || a.name == kResidualNames[1])
      return fail(ErrorCode::InvalidInput, "the attribute name '" + a.name + "' is reserved for float64 residuals");
  // The copy below is counted in the estimate: refuse before making it.
  if (result.status = checkMemory(complex, options); !result.status.ok()) return result;
  // The kd-tree codes the float32 roundings; the residuals go last among
  // the attributes, and their bits count as geometry.
  Complex widened;
  widened.points = complex.points;
  widened.edges = complex.edges;
  widened.triangles = complex.triangles;
  widened.tetrahedra = complex.tetrahedra;
  widened.labels = complex.labels;
  widened.attributes = complex.attributes;
  widened.attributes.resize(complex.attributes.size() + 2);
  splitFloat64(complex.positions64, widened.positions, widened.attributes[complex.attributes.size()],
               widened.attributes[complex.attributes.size() + 1]);
  result = encodeStream(widened, options, finalModels, true);
  if (result.status.ok()) {
    std::vector<double>& bits = result.cost.attributeBits;
    result.cost.geometryBits += bits[bits.size() - 1] + bits[bits.size() - 2];
    bits.resize(bits.size() - 2);
  }
  return result;
}

}  // namespace kdmesh
