// The range coder alone: what goes in comes out, and skewed data compresses.
#include <gtest/gtest.h>

#include <random>

#include "range_coder.h"

namespace kdmesh {
namespace {

struct Symbol {
  bool isBit;
  uint32_t value, count;  // count: range of a uniform value
  int model;
};

std::vector<Symbol> randomSymbols(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<Symbol> symbols(n);
  for (Symbol& s : symbols) {
    s.isBit = rng() % 4 != 0;
    s.model = int(rng() % 3);
    if (s.isBit) {
      // model 0 is almost always 0, model 1 fair, model 2 almost always 1
      const uint32_t r = rng() % 100;
      s.value = s.model == 0 ? r < 3 : s.model == 1 ? r < 50 : r < 97;
    } else {
      const uint32_t kinds[] = {1, 2, 3, 255, 65536, 65537, 1000000007u, 0xffffffffu};
      s.count = kinds[rng() % 8];
      s.value = uint32_t(rng() % s.count);
    }
  }
  return symbols;
}

TEST(RangeCoder, RoundTripsBitsAndUniformValuesAcrossBlocks) {
  const std::vector<Symbol> symbols = randomSymbols(200000, 1);
  std::vector<uint8_t> bytes;
  std::vector<size_t> blockEnds;
  RangeEncoder encoder(bytes);
  BitModel encodeModels[3];
  const size_t blockSize = 30011;
  for (size_t i = 0; i < symbols.size(); ++i) {
    const Symbol& s = symbols[i];
    if (s.isBit)
      encoder.bit(encodeModels[s.model], s.value != 0);
    else
      encoder.uniform(s.value, s.count);
    if ((i + 1) % blockSize == 0 || i + 1 == symbols.size()) {
      encoder.finish();
      blockEnds.push_back(bytes.size());
      encoder.restart();
    }
  }
  RangeDecoder decoder;
  BitModel decodeModels[3];
  size_t blockStart = 0;
  for (size_t i = 0; i < symbols.size(); ++i) {
    if (i % blockSize == 0) {
      const size_t end = blockEnds[i / blockSize];
      decoder.start(bytes.data() + blockStart, end - blockStart);
      blockStart = end;
    }
    const Symbol& s = symbols[i];
    const uint32_t got = s.isBit ? decoder.bit(decodeModels[s.model]) : decoder.uniform(0, s.count);
    ASSERT_EQ(got, s.value) << "symbol " << i;
  }
  EXPECT_FALSE(decoder.invalid());
}

TEST(RangeCoder, SkewedBitsCostNearTheirEntropy) {
  std::mt19937 rng(5);
  std::vector<uint8_t> bytes;
  RangeEncoder encoder(bytes);
  encoder.setMeasuring(true);
  BitModel model;
  const size_t n = 100000;
  for (size_t i = 0; i < n; ++i) encoder.bit(model, rng() % 100 < 5);
  encoder.finish();
  const double entropy = n * (-(0.05 * std::log2(0.05) + 0.95 * std::log2(0.95)));
  EXPECT_LT(bytes.size() * 8.0, entropy * 1.07);
  EXPECT_NEAR(encoder.cost(), bytes.size() * 8.0, bytes.size() * 8.0 * 0.01 + 64);
}

TEST(RangeCoder, ReadsPastTheEndAsZerosAndFlagsImpossibleValues) {
  std::vector<uint8_t> bytes(8, 0xff);
  RangeDecoder decoder;
  decoder.start(bytes.data(), bytes.size());
  for (int i = 0; i < 100; ++i) decoder.uniform(0, 3);
  EXPECT_TRUE(decoder.invalid());
  EXPECT_GT(decoder.bytesPastEnd(), 0u);
}

}  // namespace
}  // namespace kdmesh
