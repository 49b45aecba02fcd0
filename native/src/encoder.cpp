// The encoder: quantize, order the vertices along the kd-tree, then code the
// count of every cell split, level by level, into checksummed chunks.
#include <algorithm>
#include <cstring>
#include <string>

#include "container.h"
#include "count_coder.h"
#include "crc32.h"
#include "kd_order.h"
#include "kdmesh/kdmesh.h"
#include "quantizer.h"
#include "range_coder.h"
#include "split_schedule.h"

namespace kdmesh {
namespace {

constexpr size_t kFirstChunkBytes = 1024;
constexpr size_t kMinChunkBytes = 64;
constexpr size_t kMaxChunkBytes = size_t(1) << 26;

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
  if (complex.hasSimplices())
    return Status::error(ErrorCode::Unsupported,
                         "connectivity coding is not implemented yet: this version "
                         "encodes vertices only (drop the edges, triangles and tetrahedra)");
  return Status::success();
}

// Writes chunks into the stream body: a frame, then the payload that the
// range coder produces, closed when it reaches the current target size.
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
      target_ = std::min(target_ * 2, maxBytes_);
      begin();
    }
  }

  uint32_t finish() {
    if (splits_ > 0) end();
    body_.resize(frameAt_);  // drop the frame reserved for a chunk never used
    return chunks_;
  }

 private:
  void begin() {
    frameAt_ = body_.size();
    body_.resize(frameAt_ + kChunkFrameBytes);
    coder_.restart();
    splits_ = 0;
  }

  void end() {
    coder_.finish();
    const size_t payloadAt = frameAt_ + kChunkFrameBytes;
    ChunkFrame frame;
    frame.payloadBytes = uint32_t(body_.size() - payloadAt);
    frame.splitCount = splits_;
    frame.checksum = crc32(body_.data() + payloadAt, frame.payloadBytes);
    writeChunkFrame(frame, body_.data() + frameAt_);
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

}  // namespace

EncodeResult encode(const Complex& complex, const EncodeOptions& options) {
  EncodeResult result;
  if (result.status = checkOptions(complex, options); !result.status.ok()) return result;
  auto report = [&](const char* phase, double fraction) {
    if (options.progress) options.progress({phase, fraction});
  };

  Header header;
  header.version = kFormatVersion;
  header.vertexCount = uint32_t(complex.vertexCount());
  header.simplexCounts[0] = header.vertexCount;
  std::vector<uint32_t> coords;
  report("quantize", 0);
  if (result.status = quantize(complex.positions, options, header, coords); !result.status.ok())
    return result;
  const SplitSchedule schedule(header);
  report("sort", 0);
  const std::vector<KdKey> keys = kdOrder(coords, schedule).keys;
  coords = {};

  std::vector<uint8_t> body;
  ChunkWriter chunks(body, options.chunkBytes);
  CountCoder counts(schedule.levels);
  // The decoder's order: per level, first the cells of several vertices,
  // then the one-vertex cells, each group in kd-tree order.
  struct Cell {
    uint32_t begin, end;  // range of `keys`
    bool parentOneSided;
  };
  struct Single {
    uint32_t key;  // index into `keys`
    bool parentOneSided;
  };
  std::vector<Cell> cells, children;
  std::vector<Single> singles;
  if (header.vertexCount == 1)
    singles.push_back({0, false});
  else
    cells.push_back({0, header.vertexCount, false});
  for (int level = 0; level < schedule.levels; ++level) {
    report("code", double(level) / schedule.levels);
    const int bit = schedule.levels - 1 - level;
    const size_t singleLevelEnd = singles.size();
    children.clear();
    for (const Cell& cell : cells) {
      const uint32_t split = uint32_t(
          std::partition_point(keys.begin() + cell.begin, keys.begin() + cell.end,
                               [bit](KdKey k) { return ((k >> bit) & 1) == 0; }) -
          keys.begin());
      const uint32_t population = cell.end - cell.begin, firstHalf = split - cell.begin;
      counts.code(chunks.coder(), population, level, cell.parentOneSided, firstHalf);
      const bool oneSided = firstHalf == 0 || firstHalf == population;
      for (const Cell half : {Cell{cell.begin, split, oneSided}, Cell{split, cell.end, oneSided}}) {
        if (half.end - half.begin == 1)
          singles.push_back({half.begin, oneSided});
        else if (half.end > half.begin)
          children.push_back(half);
      }
      chunks.splitDone();
    }
    for (size_t i = 0; i < singleLevelEnd; ++i) {
      Single& single = singles[i];
      const bool inFirstHalf = ((keys[single.key] >> bit) & 1) == 0;
      counts.codeSingle(chunks.coder(), level, single.parentOneSided, inFirstHalf);
      single.parentOneSided = true;
      chunks.splitDone();
    }
    std::inplace_merge(singles.begin(), singles.begin() + std::ptrdiff_t(singleLevelEnd),
                       singles.end(),
                       [](const Single& a, const Single& b) { return a.key < b.key; });
    std::swap(cells, children);
  }
  header.chunkCount = chunks.finish();
  header.bodyBytes = body.size();
  result.cost.geometryBits = chunks.coder().cost();
  report("code", 1);

  result.bytes.resize(kHeaderBytes + body.size());
  writeHeader(header, result.bytes.data());
  if (!body.empty()) std::memcpy(result.bytes.data() + kHeaderBytes, body.data(), body.size());
  return result;
}

}  // namespace kdmesh
