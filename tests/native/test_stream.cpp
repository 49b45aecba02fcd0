// The progressive stream: every prefix decodes to a coarser model, pushes of
// any size give the same result, and damaged streams are refused.
#include <gtest/gtest.h>

#include <random>

#include "container.h"
#include "crc32.h"
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
    cuts.push_back(c.offset + kChunkFrameBytes + c.payloadBytes);
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
    if (cut < kHeaderBytes) {
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
  Decoder d;
  EXPECT_EQ(d.progress().bytesExpected, 0u);
  ASSERT_TRUE(d.push(bytes.data(), kHeaderBytes).ok());
  EXPECT_TRUE(d.hasHeader());
  EXPECT_EQ(d.header().vertexCount, 8000u);
  EXPECT_EQ(d.progress().bytesExpected, bytes.size());
  EXPECT_EQ(d.progress().cellCount, 1u);
  EXPECT_EQ(d.snapshot().vertexCount(), 1u);
  ASSERT_TRUE(d.push(bytes.data() + kHeaderBytes, bytes.size() - kHeaderBytes).ok());
  const DecodeProgress p = d.progress();
  EXPECT_TRUE(p.complete);
  EXPECT_EQ(p.bytesConsumed, bytes.size());
  EXPECT_EQ(p.chunksApplied, d.header().chunkCount);
  EXPECT_EQ(int(p.level), d.header().depth());
  // Chunks start small and grow to the configured size.
  ASSERT_GE(d.chunks().size(), 4u);
  EXPECT_NEAR(d.chunks()[0].payloadBytes, 1024, 16);
  EXPECT_NEAR(d.chunks()[1].payloadBytes, 2048, 16);
  EXPECT_NEAR(d.chunks()[2].payloadBytes, 4096, 16);
  EXPECT_NEAR(d.chunks()[3].payloadBytes, 4096, 16);
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
      uint8_t* payload = hostile.data() + c.offset + kChunkFrameBytes;
      for (uint32_t i = 0; i < c.payloadBytes; ++i)
        if (rng() % 4 == 0) payload[i] = uint8_t(rng());
      ChunkFrame frame = readChunkFrame(hostile.data() + c.offset);
      frame.checksum = crc32(payload, c.payloadBytes);
      writeChunkFrame(frame, hostile.data() + c.offset);
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

Header validHeader() {
  const std::vector<uint8_t> bytes = sphereStream(100, 256);
  Header h;
  EXPECT_TRUE(readHeader(bytes.data(), DecoderLimits{}, h).ok());
  return h;
}

TEST(Stream, HostileHeadersAreRefusedBeforeAnyAllocation) {
  uint8_t buffer[kHeaderBytes];
  Header h = validHeader();
  h.vertexCount = 2000000000u;
  writeHeader(h, buffer);
  Decoder d;
  EXPECT_EQ(d.push(buffer, sizeof buffer).code, ErrorCode::LimitExceeded);
  // The error sticks.
  EXPECT_EQ(d.push(buffer, 1).code, ErrorCode::LimitExceeded);

  h = validHeader();
  h.bits = 31;
  writeHeader(h, buffer);
  Decoder d2;
  EXPECT_EQ(d2.push(buffer, sizeof buffer).code, ErrorCode::CorruptHeader);

  h = validHeader();
  h.chunkCount = uint32_t(h.bodyBytes);  // more chunks than frames could fit
  writeHeader(h, buffer);
  Decoder d3;
  EXPECT_EQ(d3.push(buffer, sizeof buffer).code, ErrorCode::CorruptHeader);

  const uint8_t text[kHeaderBytes] = "ply\nformat ascii 1.0\n";
  Decoder d4;
  EXPECT_EQ(d4.push(text, sizeof text).code, ErrorCode::BadMagic);
}

TEST(Stream, ChunkFramesLargerThanTheLimitAreRefusedEarly) {
  std::vector<uint8_t> bytes = sphereStream(100, 256);
  ChunkFrame frame = readChunkFrame(bytes.data() + kHeaderBytes);
  frame.payloadBytes = 0x7fffffff;
  writeChunkFrame(frame, bytes.data() + kHeaderBytes);
  Decoder d;
  EXPECT_EQ(d.push(bytes.data(), kHeaderBytes + kChunkFrameBytes).code, ErrorCode::CorruptChunk);
}

// The frame's split count is not under the payload checksum: a count that no
// payload of that size can hold is refused before any work.
TEST(Stream, ChunkFramesClaimingMoreSplitsThanTheirBytesCanCodeAreRefused) {
  std::vector<uint8_t> bytes = sphereStream(100, 256);
  ChunkFrame frame = readChunkFrame(bytes.data() + kHeaderBytes);
  frame.splitCount = 0xffffffffu;
  writeChunkFrame(frame, bytes.data() + kHeaderBytes);
  Decoder d;
  EXPECT_EQ(d.push(bytes.data(), kHeaderBytes + kChunkFrameBytes).code, ErrorCode::CorruptChunk);
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
