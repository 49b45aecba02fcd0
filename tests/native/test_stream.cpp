// The progressive stream: every prefix decodes to a coarser model, pushes of
// any size give the same result, and damaged streams are refused.
#include <gtest/gtest.h>

#include <cfloat>
#include <limits>
#include <random>

#include "complexes.h"
#include "container.h"
#include "crc32.h"
#include "mutations.h"
#include "shapes.h"
#include "test_support.h"

namespace kdmesh::test {
namespace {

std::vector<uint8_t> sphereStream(size_t n, size_t chunkBytes, bool exact = false) {
  EncodeOptions options;
  options.bits = 14;
  options.exact = exact;
  options.chunkBytes = chunkBytes;
  return encodeOrDie(pointCloud(sphereSurface(n, 21)), options);
}

std::vector<size_t> cutPoints(const Decoder& full, size_t total, size_t arbitrary, uint32_t seed) {
  std::vector<size_t> cuts;
  for (const ChunkInfo& c : full.chunks()) {
    cuts.push_back(c.offset);
    cuts.push_back(c.offset + c.frameBytes + c.payloadBytes);
  }
  std::mt19937 rng(seed);
  for (size_t i = 0; i < arbitrary; ++i) cuts.push_back(rng() % (total + 1));
  std::sort(cuts.begin(), cuts.end());
  return cuts;
}

TEST(Stream, EveryPrefixDecodesToACoarserValidCloud) {
  const std::vector<float> input = sphereSurface(10000, 21);
  const std::vector<uint8_t> bytes = sphereStream(10000, 1024);
  Decoder full;
  ASSERT_TRUE(full.push(bytes.data(), bytes.size()).ok());
  ASSERT_GT(full.chunks().size(), 10u);
  const Header& h = full.header();

  double previousBound = INFINITY;
  size_t previousCount = 0;
  for (size_t cut : cutPoints(full, bytes.size(), 200, 5)) {
    SCOPED_TRACE("prefix of " + std::to_string(cut) + " bytes");
    Decoder d;
    ASSERT_TRUE(d.push(bytes.data(), cut).ok());
    if (cut < h.headerBytes) {
      EXPECT_FALSE(d.hasHeader());
      continue;
    }
    const Complex c = d.snapshot();
    ASSERT_GE(c.vertexCount(), 1u);
    ASSERT_LE(c.vertexCount(), input.size() / 3);
    ASSERT_GE(c.vertexCount(), previousCount);
    for (size_t i = 0; i < c.positions.size(); ++i) {
      const double lo = h.origin[i % 3], hi = lo + h.gridMax[i % 3] * h.step;
      ASSERT_GE(c.positions[i], lo - 1e-6);
      ASSERT_LE(c.positions[i], hi + 1e-6);
    }
    const double bound = d.errorBound();
    ASSERT_LE(bound, previousBound);
    // Every input point lies within the bound of some decoded point.
    const double measured = maxNearestDistance(input, c.positions, bound * (1 + 1e-6) + 1e-6);
    ASSERT_LE(measured, bound * (1 + 1e-6) + 1e-6);
    previousBound = bound;
    previousCount = c.vertexCount();
  }
  EXPECT_EQ(previousCount, input.size() / 3);
}

TEST(Stream, PushingInPiecesOfAnySizeMatchesDecodingThePrefixAtOnce) {
  const std::vector<uint8_t> bytes = sphereStream(4000, 256, true);
  std::mt19937 rng(8);
  for (int trial = 0; trial < 4; ++trial) {
    Decoder streaming;
    size_t at = 0;
    while (at < bytes.size()) {
      const size_t piece = trial == 0 ? 1 : std::min<size_t>(1 + rng() % 700, bytes.size() - at);
      ASSERT_TRUE(streaming.push(bytes.data() + at, piece).ok());
      at += piece;
      if (rng() % (trial == 0 ? 512 : 8) == 0 || at == bytes.size()) {
        Decoder atOnce;
        ASSERT_TRUE(atOnce.push(bytes.data(), at).ok());
        EXPECT_EQ(streaming.progress().bytesConsumed, atOnce.progress().bytesConsumed);
        EXPECT_EQ(streaming.snapshot().positions, atOnce.snapshot().positions);
      }
    }
    EXPECT_TRUE(streaming.finish().ok());
    EXPECT_TRUE(streaming.complete());
  }
}

TEST(Stream, ProgressReportsBytesLevelsAndChunks) {
  const std::vector<uint8_t> bytes = sphereStream(8000, 4096);
  size_t headerBytes = 0;
  ASSERT_TRUE(headerSize(bytes.data(), headerBytes).ok());
  Decoder d;
  EXPECT_EQ(d.progress().bytesExpected, 0u);
  ASSERT_TRUE(d.push(bytes.data(), headerBytes - 1).ok());
  EXPECT_FALSE(d.hasHeader());
  ASSERT_TRUE(d.push(bytes.data() + headerBytes - 1, 1).ok());
  EXPECT_TRUE(d.hasHeader());
  EXPECT_EQ(d.header().vertexCount, 8000u);
  EXPECT_EQ(d.progress().bytesExpected, bytes.size());
  EXPECT_EQ(d.progress().cellCount, 1u);
  EXPECT_EQ(d.snapshot().vertexCount(), 1u);
  EXPECT_EQ(d.header().headerBytes, headerBytes);
  ASSERT_TRUE(d.push(bytes.data() + headerBytes, bytes.size() - headerBytes).ok());
  const DecodeProgress p = d.progress();
  EXPECT_TRUE(p.complete);
  EXPECT_EQ(p.bytesConsumed, bytes.size());
  EXPECT_EQ(p.chunksApplied, d.header().chunkCount);
  EXPECT_EQ(int(p.level), d.header().depth());
  // Chunks start at 1 KiB and grow by a quarter to the configured size
  // (docs/FORMAT.md); the last may be shorter.
  const std::vector<double> targets = {1024, 1280, 1600, 2000, 2500, 3125, 3906, 4096, 4096};
  ASSERT_GE(d.chunks().size(), targets.size());
  for (size_t i = 0; i + 1 < d.chunks().size(); ++i)
    EXPECT_NEAR(d.chunks()[i].payloadBytes, targets[std::min(i, targets.size() - 1)], 16) << "chunk " << i;
}

// The bits of every level, as the encoder counts them while coding and the
// decoder while decoding: the same, level by level, and summing to the
// totals; a prefix lists the levels it completed.
TEST(Stream, CostsByLevelAddUpAndAgreeOnBothSides) {
  struct Case {
    const char* name;
    Complex complex;
    int bits;
  };
  const Case cases[] = {{"point cloud", pointCloud(torusSurface(3000, 34)), 10},
                        {"surface", torusMesh(12, 20), 12},
                        {"tetrahedra", tetrahedralBlock(4, 5), 12},
                        {"coincident vertices, all dimensions", randomComplex(7, 60, 120), 3}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    EncodeOptions options;
    options.bits = c.bits;
    options.chunkBytes = 64;
    const EncodeResult encoded = encode(c.complex, options);
    ASSERT_TRUE(encoded.status.ok()) << encoded.status.message;
    DecoderOptions measuring;
    measuring.measureCost = true;
    Decoder decoder(measuring);
    ASSERT_TRUE(decoder.push(encoded.bytes.data(), encoded.bytes.size()).ok());
    ASSERT_TRUE(decoder.complete());
    const Header& h = decoder.header();
    const std::vector<LevelCost>& mine = encoded.cost.levels;
    const std::vector<LevelCost> theirs = decoder.cost().levels;
    ASSERT_EQ(theirs.size(), mine.size());
    // Every geometric level halves one axis, each axis as often as it has
    // bits; only cells of coincident vertices split further.
    ASSERT_GE(mine.size(), size_t(h.depth()));
    std::array<int, 3> halvings{};
    double geometryBits = 0, connectivityBits = 0;
    for (size_t l = 0; l < mine.size(); ++l) {
      SCOPED_TRACE("level " + std::to_string(l));
      EXPECT_EQ(theirs[l].axis, mine[l].axis);
      EXPECT_EQ(theirs[l].cells, mine[l].cells);
      EXPECT_EQ(theirs[l].geometryBits, mine[l].geometryBits);
      EXPECT_EQ(theirs[l].connectivityBits, mine[l].connectivityBits);
      EXPECT_GE(mine[l].geometryBits, 0.0);
      EXPECT_GE(mine[l].connectivityBits, 0.0);
      if (l < size_t(h.depth())) {
        ASSERT_GE(mine[l].axis, 0);
        ++halvings[size_t(mine[l].axis)];
        EXPECT_GE(mine[l].cells, l == 0 ? 1u : mine[l - 1].cells);
      } else {
        EXPECT_EQ(mine[l].axis, -1);
      }
      geometryBits += mine[l].geometryBits;
      connectivityBits += mine[l].connectivityBits;
    }
    EXPECT_EQ(mine[0].cells, 1u);
    for (int a = 0; a < 3; ++a) EXPECT_EQ(halvings[size_t(a)], h.axisBits(a));
    EXPECT_NEAR(geometryBits, encoded.cost.geometryBits, 1e-9 * encoded.cost.geometryBits);
    EXPECT_NEAR(connectivityBits, encoded.cost.connectivityBits, 1e-9 * encoded.cost.connectivityBits + 1e-12);
    if (c.complex.edges.empty() && c.complex.triangles.empty() && c.complex.tetrahedra.empty()) {
      EXPECT_EQ(connectivityBits, 0.0);
    } else {
      EXPECT_GT(connectivityBits, 0.0);
    }
    if (std::string(c.name).find("coincident") != std::string::npos) {
      EXPECT_GT(mine.size(), size_t(h.depth()));
    }

    ASSERT_GE(decoder.chunks().size(), 2u);
    const ChunkInfo& middle = decoder.chunks()[decoder.chunks().size() / 2];
    Decoder prefix(measuring);
    ASSERT_TRUE(prefix.push(encoded.bytes.data(), middle.offset).ok());
    const std::vector<LevelCost> completed = prefix.cost().levels;
    EXPECT_LT(completed.size(), mine.size());
    EXPECT_EQ(completed.size(), size_t(prefix.progress().level));
    for (size_t l = 0; l < completed.size(); ++l) EXPECT_EQ(completed[l].geometryBits, mine[l].geometryBits);
  }
}

TEST(Stream, TruncatedStreamsAreReportedByFinish) {
  const std::vector<uint8_t> bytes = sphereStream(2000, 256);
  for (size_t cut = 0; cut < bytes.size(); cut += 7) {
    Decoder d;
    ASSERT_TRUE(d.push(bytes.data(), cut).ok());
    const Status s = d.finish();
    EXPECT_EQ(s.code, ErrorCode::Truncated) << cut;
    Complex out;
    EXPECT_EQ(decode(bytes.data(), cut, out).code, ErrorCode::Truncated);
  }
}

TEST(Stream, EveryFlippedByteIsDetected) {
  const std::vector<uint8_t> bytes = sphereStream(1500, 256);
  std::mt19937 rng(3);
  for (size_t i = 0; i < bytes.size(); ++i) {
    std::vector<uint8_t> damaged = bytes;
    damaged[i] ^= uint8_t(1 + rng() % 255);
    Complex out;
    const Status s = decode(damaged.data(), damaged.size(), out);
    ASSERT_FALSE(s.ok()) << "flip at byte " << i << " went unnoticed";
    ASSERT_FALSE(s.message.empty());
  }
}

TEST(Stream, TrailingBytesAreRefused) {
  std::vector<uint8_t> bytes = sphereStream(500, 256);
  bytes.push_back(0);
  Complex out;
  EXPECT_EQ(decode(bytes.data(), bytes.size(), out).code, ErrorCode::TrailingBytes);
}

// Chunks swapped, dropped or repeated keep their own checksums but fail
// them where they land: a chunk's checksum covers its index.
TEST(Stream, ChunksOutOfPlaceAreCorrupt) {
  const std::vector<uint8_t> bytes = sphereStream(3000, 256);
  Decoder reference;
  ASSERT_TRUE(reference.push(bytes.data(), bytes.size()).ok());
  const std::vector<ChunkInfo>& chunks = reference.chunks();
  ASSERT_GT(chunks.size(), 4u);
  auto piece = [&](size_t i) {
    const uint64_t end = i + 1 < chunks.size() ? chunks[i + 1].offset : bytes.size();
    return std::vector<uint8_t>(bytes.begin() + std::ptrdiff_t(chunks[i].offset), bytes.begin() + std::ptrdiff_t(end));
  };
  for (size_t at = 0; at + 1 < chunks.size(); ++at) {
    std::vector<uint8_t> swapped(bytes.begin(), bytes.begin() + std::ptrdiff_t(chunks[at].offset));
    for (const size_t i : {at + 1, at})
      for (const uint8_t b : piece(i)) swapped.push_back(b);
    swapped.insert(swapped.end(), bytes.begin() + std::ptrdiff_t(swapped.size()), bytes.end());
    ASSERT_EQ(swapped.size(), bytes.size());
    Complex out;
    EXPECT_EQ(decode(swapped.data(), swapped.size(), out).code, ErrorCode::CorruptChunk) << "swapped at " << at;
    std::vector<uint8_t> repeated(bytes.begin(), bytes.begin() + std::ptrdiff_t(chunks[at + 1].offset));
    for (const uint8_t b : piece(at)) repeated.push_back(b);
    Decoder d;
    EXPECT_EQ(d.push(repeated.data(), repeated.size()).code, ErrorCode::CorruptChunk) << "repeated at " << at;
    std::vector<uint8_t> dropped(bytes.begin(), bytes.begin() + std::ptrdiff_t(chunks[at].offset));
    dropped.insert(dropped.end(), bytes.begin() + std::ptrdiff_t(chunks[at + 1].offset), bytes.end());
    EXPECT_EQ(decode(dropped.data(), dropped.size(), out).code, ErrorCode::CorruptChunk) << "dropped at " << at;
  }
}

// A header announcing a longer body than its chunks fill is corrupt once
// the last chunk is in, whatever bytes follow.
TEST(Stream, ABodyLongerThanItsChunksIsCorrupt) {
  const std::vector<uint8_t> bytes = sphereStream(3000, 256);
  Header h;
  size_t size = 0;
  ASSERT_TRUE(headerSize(bytes.data(), size).ok());
  ASSERT_TRUE(readHeader(bytes.data(), size, DecoderLimits{}, h).ok());
  for (const uint64_t extra : {uint64_t(1), uint64_t(0xffffffffu) - h.bodyBytes}) {
    Header longer = h;
    longer.bodyBytes += extra;
    uint8_t buffer[kMaxHeaderBytes];
    std::vector<uint8_t> forged(buffer, buffer + writeHeader(longer, buffer));
    forged.insert(forged.end(), bytes.begin() + std::ptrdiff_t(size), bytes.end());
    forged.resize(forged.size() + 8, 0);
    Decoder d;
    const Status s = d.push(forged.data(), forged.size());
    EXPECT_EQ(s.code, ErrorCode::CorruptChunk) << extra;
    EXPECT_NE(s.message.find("the header announced"), std::string::npos) << s.message;
  }
}

// Payloads replaced by noise with recomputed checksums: what a hostile server
// could send. The decoder must refuse or decode a cloud of the declared
// size, and never crash or read out of bounds (run under ASan in CI's fuzz job).
TEST(Stream, NoiseWithValidChecksumsNeverBreaksTheDecoder) {
  const std::vector<uint8_t> bytes = sphereStream(3000, 256);
  Decoder reference;
  ASSERT_TRUE(reference.push(bytes.data(), bytes.size()).ok());
  std::mt19937 rng(17);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<uint8_t> hostile = bytes;
    for (const ChunkInfo& c : reference.chunks()) {
      uint8_t* chunk = hostile.data() + c.offset;
      const size_t checked = c.frameBytes - kChunkChecksumBytes + c.payloadBytes;
      for (size_t i = c.frameBytes - kChunkChecksumBytes; i < checked; ++i)
        if (rng() % 4 == 0) chunk[i] = uint8_t(rng());
      writeChunkChecksum(chunk, checked, uint32_t(&c - reference.chunks().data()), chunk + checked);
    }
    Complex out;
    const Status s = decode(hostile.data(), hostile.size(), out);
    if (s.ok()) {
      EXPECT_EQ(out.vertexCount(), 3000u);
    } else {
      EXPECT_EQ(s.code, ErrorCode::CorruptChunk) << s.message;
    }
  }
}

// A mutation suite: 600 streams of a mesh, each with one kind of change
// and checksums made valid again (mutations.h). Every one must decode to a
// valid complex of the header's counts or fail with a documented code,
// never crash (ASan and UBSan run this in CI), and its work is bounded by
// the splits the chunk frames allow. tests/js/mutations.test.mjs gives the
// same streams to the WebAssembly decoder.
TEST(Stream, MutatedStreamsWithValidChecksumsFailCleanly) {
  const std::vector<MutatedStream> streams = mutatedStreams(mutationSubject(), 600, 29);
  ASSERT_EQ(streams.size(), 600u);
  int decoded = 0;
  for (size_t trial = 0; trial < streams.size(); ++trial) {
    const std::vector<uint8_t>& hostile = streams[trial].bytes;
    Complex out;
    const Status s = decode(hostile.data(), hostile.size(), out);
    if (s.ok()) {
      ++decoded;
      Header h;
      size_t size = 0;
      ASSERT_TRUE(headerSize(hostile.data(), size).ok());
      ASSERT_TRUE(readHeader(hostile.data(), size, DecoderLimits{}, h).ok());
      EXPECT_EQ(out.vertexCount(), h.vertexCount) << trial;
      EXPECT_EQ(out.simplexCount(2), h.simplexCounts[2]) << trial;
    } else {
      EXPECT_TRUE(s.code == ErrorCode::CorruptHeader || s.code == ErrorCode::CorruptChunk ||
                  s.code == ErrorCode::LimitExceeded || s.code == ErrorCode::TrailingBytes ||
                  s.code == ErrorCode::Truncated)
          << trial << " (" << streams[trial].kind << "): " << errorCodeName(s.code) << " " << s.message;
    }
  }
  EXPECT_LT(decoded, 600);  // the mutations are not all harmless
}

Header validHeader() {
  const std::vector<uint8_t> bytes = sphereStream(100, 256);
  Header h;
  size_t size = 0;
  EXPECT_TRUE(headerSize(bytes.data(), size).ok());
  EXPECT_TRUE(readHeader(bytes.data(), size, DecoderLimits{}, h).ok());
  return h;
}

TEST(Stream, HostileHeadersAreRefusedBeforeAnyAllocation) {
  uint8_t buffer[kMaxHeaderBytes];
  Header h = validHeader();
  h.vertexCount = 2000000000u;
  size_t size = writeHeader(h, buffer);
  Decoder d;
  EXPECT_EQ(d.push(buffer, size).code, ErrorCode::LimitExceeded);
  // The error sticks.
  EXPECT_EQ(d.push(buffer, 1).code, ErrorCode::LimitExceeded);

  h = validHeader();
  h.bits = 31;
  size = writeHeader(h, buffer);
  Decoder d2;
  EXPECT_EQ(d2.push(buffer, size).code, ErrorCode::CorruptHeader);

  h = validHeader();
  h.chunkCount = uint32_t(h.bodyBytes);  // more chunks than frames could fit
  size = writeHeader(h, buffer);
  Decoder d3;
  EXPECT_EQ(d3.push(buffer, size).code, ErrorCode::CorruptHeader);

  // A grid whose far corner is no finite float32 would decode to infinities.
  for (const double step : {1e38, 1e300}) {
    h = validHeader();
    h.step = step;
    size = writeHeader(h, buffer);
    Decoder far;
    const Status s = far.push(buffer, size);
    EXPECT_EQ(s.code, ErrorCode::CorruptHeader) << step;
    EXPECT_NE(s.message.find("not a finite float32"), std::string::npos) << s.message;
  }

  // Float32 ranges may cover every image, infinities and NaNs included, but
  // not run past the largest.
  h = validHeader();
  h.quantization = Quantization::Float32;
  h.bits = 32;
  h.floatImageMin = {0, 0x7f800000u, 2};
  h.gridMax = {0xffffffffu, 5, 0xfffffffdu};
  size = writeHeader(h, buffer);
  Decoder everyFloat;
  EXPECT_TRUE(everyFloat.push(buffer, size).ok());
  h.gridMax[2] = 0xfffffffeu;
  size = writeHeader(h, buffer);
  Decoder pastTheEnd;
  const Status past = pastTheEnd.push(buffer, size);
  EXPECT_EQ(past.code, ErrorCode::CorruptHeader);
  EXPECT_NE(past.message.find("runs past the largest float image"), std::string::npos) << past.message;

  // More vertices or simplices than the stream's size can justify (a
  // 49-byte stream announcing 2^27 − 1 coincident points was a 3.7 GB
  // decompression bomb); within the ratio DecoderLimits allows, accepted.
  h = validHeader();
  h.maxDimension = 0;
  h.simplexCounts = {0, 0, 0, 0};
  h.vertexCount = h.simplexCounts[0] = uint32_t(1024 * (h.bodyBytes + kMaxHeaderBytes)) + 1;
  size = writeHeader(h, buffer);
  Decoder bomb;
  EXPECT_EQ(bomb.push(buffer, size).code, ErrorCode::LimitExceeded);
  DecoderOptions generous;
  generous.limits.maxVerticesPerByte = 2048;
  Decoder raised(generous);
  EXPECT_TRUE(raised.push(buffer, size).ok());
  h = validHeader();
  h.maxDimension = 2;
  h.simplexCounts[2] = uint32_t(1024 * (h.bodyBytes + kMaxHeaderBytes)) + 1;
  size = writeHeader(h, buffer);
  Decoder simplexBomb;
  EXPECT_EQ(simplexBomb.push(buffer, size).code, ErrorCode::LimitExceeded);

  const uint8_t text[] = "ply\nformat ascii 1.0\n";
  Decoder d4;
  EXPECT_EQ(d4.push(text, sizeof text).code, ErrorCode::BadMagic);

  // A size byte that says the header is longer or shorter than its fields.
  h = validHeader();
  size = writeHeader(h, buffer);
  for (const int change : {-1, 1, 80}) {
    uint8_t resized[kMaxHeaderBytes + 1] = {};
    std::copy(buffer, buffer + size, resized);
    resized[kHeaderPrefixBytes - 1] = uint8_t(int(size) + change);
    Decoder d5;
    EXPECT_EQ(d5.push(resized, sizeof resized).code, ErrorCode::CorruptHeader) << change;
  }

  // Coding flags this decoder does not know, under a valid checksum.
  for (const uint8_t flags : {uint8_t(2), uint8_t(0x81)}) {
    h = validHeader();
    size = writeHeader(h, buffer);
    buffer[kHeaderPrefixBytes + 2] = flags;
    const uint32_t checksum = crc32(buffer, size - 4);
    for (int i = 0; i < 4; ++i) buffer[size - 4 + size_t(i)] = uint8_t(checksum >> (8 * i));
    Decoder unknown;
    const Status s = unknown.push(buffer, size);
    EXPECT_EQ(s.code, ErrorCode::CorruptHeader) << int(flags);
    EXPECT_NE(s.message.find("unknown coding flags"), std::string::npos) << s.message;
  }
}

// Every field's largest value fits the header's largest size, and every
// field reads back as written, in both quantization modes.
TEST(Stream, HeadersRoundTripWithTheirLargestValues) {
  DecoderLimits limits;
  limits.maxVertices = 0xffffffffu;
  limits.maxSimplices = 0xffffffffu;
  for (const Quantization mode : {Quantization::Grid, Quantization::Float32}) {
    Header h;
    h.quantization = mode;
    h.fastDecode = mode == Quantization::Float32;
    h.bits = mode == Quantization::Grid ? 30 : 32;
    h.vertexCount = (1u << 31) - 1;
    h.maxDimension = 3;
    h.simplexCounts = {h.vertexCount, 1u << 30, 1u << 30, 1u << 30};
    h.gridMax = {(1u << 30) - 1, 5, 0};
    h.origin = {-double(FLT_MAX), double(std::numeric_limits<float>::denorm_min()), 0};
    h.step = 1e29;  // the far corner, origin + gridMax · step, still a finite float32
    h.floatImageMin = {0x00800000u, 0x7f000000u, 0x80000000u};
    h.bodyBytes = (uint64_t(1) << 62) - 1;
    h.chunkCount = 0xffffffffu;
    uint8_t buffer[kMaxHeaderBytes];
    const size_t size = writeHeader(h, buffer);
    ASSERT_LE(size, kMaxHeaderBytes);
    Header back;
    const Status read = readHeader(buffer, size, limits, back);
    ASSERT_TRUE(read.ok()) << read.message;
    EXPECT_EQ(back.headerBytes, size);
    EXPECT_EQ(back.vertexCount, h.vertexCount);
    EXPECT_EQ(back.simplexCounts, h.simplexCounts);
    EXPECT_EQ(back.gridMax, h.gridMax);
    EXPECT_EQ(back.bodyBytes, h.bodyBytes);
    EXPECT_EQ(back.chunkCount, h.chunkCount);
    EXPECT_EQ(back.fastDecode, h.fastDecode);
    if (mode == Quantization::Grid) {
      EXPECT_EQ(back.origin, h.origin);
      EXPECT_EQ(back.step, h.step);
    } else {
      EXPECT_EQ(back.floatImageMin, h.floatImageMin);
    }
  }
}

// The header, then a chunk frame of these counts and nothing more.
std::vector<uint8_t> headerAndFrame(const std::vector<uint8_t>& stream, const ChunkFrame& frame) {
  size_t size = 0;
  EXPECT_TRUE(headerSize(stream.data(), size).ok());
  std::vector<uint8_t> bytes(stream.begin(), stream.begin() + std::ptrdiff_t(size));
  uint8_t framed[kMaxChunkFrameBytes];
  bytes.insert(bytes.end(), framed, framed + writeChunkFrame(frame, framed));
  return bytes;
}

TEST(Stream, ChunkFramesLargerThanTheLimitAreRefusedEarly) {
  const std::vector<uint8_t> bytes = headerAndFrame(sphereStream(100, 256), {0x7fffffff, 1});
  Decoder d;
  EXPECT_EQ(d.push(bytes.data(), bytes.size()).code, ErrorCode::CorruptChunk);
}

// Counts are varints of at most five bytes: a longer one, or one above
// 2^32 - 1, is refused; one cut short waits for its next byte.
TEST(Stream, MalformedChunkFramesAreRefusedAndPartialOnesWait) {
  const std::vector<uint8_t> stream = sphereStream(100, 256);
  size_t size = 0;
  ASSERT_TRUE(headerSize(stream.data(), size).ok());
  const std::vector<uint8_t> header(stream.begin(), stream.begin() + std::ptrdiff_t(size));
  const std::vector<std::vector<uint8_t>> malformed = {{0x80, 0x80, 0x80, 0x80, 0x80, 0x01},
                                                       {0xff, 0xff, 0xff, 0xff, 0x1f}};
  for (const std::vector<uint8_t>& frame : malformed) {
    std::vector<uint8_t> bytes = header;
    bytes.insert(bytes.end(), frame.begin(), frame.end());
    Decoder d;
    EXPECT_EQ(d.push(bytes.data(), bytes.size()).code, ErrorCode::CorruptChunk);
  }
  std::vector<uint8_t> partial = header;
  partial.insert(partial.end(), {0x80, 0x80});
  Decoder d;
  EXPECT_TRUE(d.push(partial.data(), partial.size()).ok());
  EXPECT_EQ(d.progress().bytesConsumed, size);
  EXPECT_EQ(d.finish().code, ErrorCode::Truncated);
}

// A frame is judged before the rest of its chunk (and the checksum at the
// end) has arrived: a split count that no payload of that size can hold is
// refused before any work.
TEST(Stream, ChunkFramesClaimingMoreSplitsThanTheirBytesCanCodeAreRefused) {
  const std::vector<uint8_t> bytes = headerAndFrame(sphereStream(100, 256), {20, 0xffffffffu});
  Decoder d;
  EXPECT_EQ(d.push(bytes.data(), bytes.size()).code, ErrorCode::CorruptChunk);
}

// Streams decode alike everywhere only if the encoder and every decoder
// round each floating-point operation alike: the build must not fuse a
// multiply and an add (CMakeLists.txt), as GCC does by default for targets
// with FMA. Here x*y is 1 - 2^-60 exactly, 1 once rounded; fused, the sum
// keeps the -2^-60.
TEST(Stream, BuildRoundsMultiplyAndAddSeparately) {
  volatile double loaded[3] = {1.0 + 0x1p-30, 1.0 - 0x1p-30, -1.0};
  const double x = loaded[0], y = loaded[1], z = loaded[2];
  EXPECT_EQ(x * y + z, 0.0);
}

}  // namespace
}  // namespace kdmesh::test
