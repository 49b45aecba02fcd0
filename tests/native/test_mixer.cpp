// The logistic mixer of the predictions, and the one-byte priors that
// share its logistic functions.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "mixer.h"
#include "model_priors.h"

namespace kdmesh::test {
namespace {

TEST(Logistic, SquashIsMonotoneAndStretchInvertsIt) {
  EXPECT_EQ(Logistic::squash(0), 2048);
  EXPECT_EQ(Logistic::squash(-5000), Logistic::squash(-2047));
  EXPECT_EQ(Logistic::squash(5000), Logistic::squash(2047));
  int previous = 0;
  for (int d = -2047; d <= 2047; ++d) {
    const int p = Logistic::squash(d);
    ASSERT_EQ(p, Logistic::interpolatedSquash(d)) << d;
    ASSERT_GE(p, previous) << d;
    previous = p;
  }
  for (int p = 16; p < 4080; p += 7) {
    // stretch(p) is the smallest d whose squash reaches p.
    const int d = Logistic::stretch(p);
    EXPECT_GE(Logistic::squash(d), p) << p;
    EXPECT_LT(Logistic::squash(d - 1), p) << p;
  }
  // A model's 12-bit probability runs from 0 to 4096: certainty stretches
  // as the nearest probabilities that are not.
  EXPECT_EQ(Logistic::stretch(0), Logistic::stretch(1));
  EXPECT_EQ(Logistic::stretch(4096), Logistic::stretch(4095));
  EXPECT_LT(Logistic::stretch(1), Logistic::stretch(2048));
  EXPECT_GT(Logistic::stretch(4095), Logistic::stretch(2048));
  BitModel certain;
  certain.fast = certain.slow = uint16_t(kProbabilityOne);
  EXPECT_EQ(certain.probabilityOfZero() >> 3, 4096u);
}

// Bits that are 0 nine times in ten: an input model that knows it and one
// stuck at 1/2. The mixer must learn to follow the first.
TEST(Mixer, LearnsToTrustTheInformativeInput) {
  BitModel informed, uninformed;
  informed.fast = informed.slow = uint16_t(0.9 * kProbabilityOne);
  Mixer<2> mixer(1, {1 << 15, 1 << 15});
  uint32_t state = 12345;
  uint32_t p0 = 0;
  for (int i = 0; i < 20000; ++i) {
    state = state * 1664525u + 1013904223u;
    const bool bit = (state >> 8) % 10 == 0;
    p0 = mixer.mix(0, {&informed, &uninformed});
    mixer.update(bit);
  }
  EXPECT_GT(p0, uint32_t(0.85 * kProbabilityOne));
  EXPECT_LT(p0, uint32_t(0.95 * kProbabilityOne));
}

// Learned starting weights come vector by vector; each vector counts its
// uses, which is what training averages them by.
TEST(Mixer, StartsFromGivenWeightsAndCountsUses) {
  const int32_t learned[6] = {1 << 16, 0, 0, 1 << 16, 1 << 15, 1 << 15};
  Mixer<2> mixer(3, learned);
  ASSERT_EQ(mixer.weights().size(), 3u);
  EXPECT_EQ(mixer.weights()[1][1], 1 << 16);
  EXPECT_EQ(mixer.weights()[2][0], 1 << 15);
  BitModel sure, unsure;
  sure.fast = sure.slow = uint16_t(0.95 * kProbabilityOne);
  // Vector 0 follows the first input alone, vector 1 the second.
  EXPECT_GT(mixer.mix(0, {&sure, &unsure}), uint32_t(0.9 * kProbabilityOne));
  mixer.update(false);
  EXPECT_NEAR(double(mixer.mix(1, {&sure, &unsure})), 0.5 * kProbabilityOne, 0.02 * kProbabilityOne);
  mixer.update(false);
  mixer.mix(1, {&sure, &unsure});
  EXPECT_EQ(mixer.uses()[0], 1u);
  EXPECT_EQ(mixer.uses()[1], 2u);
  EXPECT_EQ(mixer.uses()[2], 0u);
}

// Priors are stored as one-byte logits (model_priors.h): 1/2 exactly at the
// middle code, monotone, and writing a prior back gives a code of the same
// probability, so retraining one family leaves the others as they were.
TEST(ModelPriors, OneByteCodesRoundTrip) {
  EXPECT_EQ(priorOfCode(kHalfPriorCode), kProbabilityOne / 2);
  EXPECT_EQ(priorCode(kProbabilityOne / 2), kHalfPriorCode);
  for (int code = 1; code <= 255; ++code) {
    const uint16_t prior = priorOfCode(uint8_t(code));
    EXPECT_GE(prior, 31u);
    EXPECT_LE(prior, kProbabilityOne - 31);
    if (code > 1) {
      EXPECT_GE(prior, priorOfCode(uint8_t(code - 1)));
    }
    EXPECT_EQ(priorOfCode(priorCode(prior)), prior);
  }
  // Near certainty (models stop at 1 − 31/2^15, 99.9 %) the codes still
  // tell 99 % from 99.9 %.
  EXPECT_LT(priorOfCode(priorCode(uint32_t(kProbabilityOne * 0.99))), uint32_t(kProbabilityOne * 0.995));
  EXPECT_GT(priorOfCode(priorCode(uint32_t(kProbabilityOne * 0.999))), uint32_t(kProbabilityOne * 0.995));
}

// Runs of 1/2 anywhere: first, after literals (three literals once read as
// a run and had their bytes overwritten), last, and longer than one run can
// hold. Each run costs three bytes.
TEST(ModelPriors, RunLengthCodingRoundTrips) {
  constexpr uint8_t kHalf = kHalfPriorCode;
  const std::vector<std::vector<uint8_t>> families = {
      {},
      {kHalf},
      {7, 9, 11, kHalf, kHalf, 13},
      {kHalf, kHalf, 5, kHalf, 6, 7, 8, kHalf, kHalf, kHalf},
      {1, 255, kHalf - 1, kHalf + 1},
  };
  auto expand = [](const std::vector<uint8_t>& coded) {
    std::vector<uint8_t> codes;
    forEachPriorCode(coded.data(), coded.size(), [&codes](uint8_t code) { codes.push_back(code); });
    return codes;
  };
  for (const std::vector<uint8_t>& codes : families) EXPECT_EQ(expand(runLengthCodePriors(codes)), codes);
  EXPECT_EQ(runLengthCodePriors({7, 9, 11, kHalf, kHalf, 13}),
            (std::vector<uint8_t>{7, 9, 11, kPriorRunMarker, 2, 0, 13}));
  constexpr size_t kLong = 70000, kRest = kLong - 0xffff;
  std::vector<uint8_t> longRun(kLong, kHalf);
  longRun.push_back(3);
  const std::vector<uint8_t> coded = runLengthCodePriors(longRun);
  EXPECT_EQ(coded, (std::vector<uint8_t>{kPriorRunMarker, 0xff, 0xff, kPriorRunMarker, kRest & 0xff, kRest >> 8, 3}));
  EXPECT_EQ(expand(coded), longRun);
}

// A coder that keeps the probability it was given.
struct ProbeCoder {
  uint32_t probabilityOfZero = 0;
  bool bitWithProbability(uint32_t p0, bool bit) {
    probabilityOfZero = p0;
    return bit;
  }
};

TEST(Mixer, SeveralMixersCodeWithTheMeanOfTheirLogits) {
  BitModel likelyZero, likelyOne;
  likelyZero.fast = likelyZero.slow = uint16_t(0.8 * kProbabilityOne);
  likelyOne.fast = likelyOne.slow = uint16_t(0.3 * kProbabilityOne);
  // The first mixer's vector 1 follows the first input, the second mixer's
  // only vector the second input.
  const int32_t first[4] = {0, 0, 1 << 16, 0}, second[2] = {0, 1 << 16};
  Mixer<2> byFirst(2, first), bySecond(1, second);
  const int stretchedZero = Logistic::stretch(int(likelyZero.probabilityOfZero() >> 3));
  const int stretchedOne = Logistic::stretch(int(likelyOne.probabilityOfZero() >> 3));
  ProbeCoder probe;
  EXPECT_FALSE(codeWithMixers(probe, std::array<Mixer<2>*, 2>{&byFirst, &bySecond}, {1, 0},
                              {&likelyZero, &likelyOne}, false));
  EXPECT_EQ(probe.probabilityOfZero,
            Mixer<2>::probabilityOfZero(Logistic::squash((stretchedZero + stretchedOne) / 2)));
  // Each mixer used and trained the vector its context chose; the inputs learned the 0.
  EXPECT_EQ(byFirst.uses()[0], 0u);
  EXPECT_EQ(byFirst.uses()[1], 1u);
  EXPECT_EQ(bySecond.uses()[0], 1u);
  EXPECT_EQ(byFirst.weights()[0][0], 0);
  EXPECT_GT(byFirst.weights()[1][0], 1 << 16);
  EXPECT_GT(likelyZero.probabilityOfZero(), uint32_t(0.8 * kProbabilityOne));
}

// What the encoder codes with the mean of three mixers, the decoder reads
// back, whatever the contexts.
TEST(Mixer, SeveralMixersRoundTripThroughTheRangeCoder) {
  auto run = [](auto& coder, std::vector<bool>& bits) {
    std::array<BitModel, 8> models;
    Mixer<2> a(4, {1 << 15, 1 << 15}), b(3, {1 << 16, 0}), c(5, {0, 1 << 16});
    uint32_t state = 99;
    for (size_t i = 0; i < bits.size(); ++i) {
      state = state * 1664525u + 1013904223u;
      const uint32_t context = state >> 24;
      bits[i] = codeWithMixers(coder, std::array<Mixer<2>*, 3>{&a, &b, &c},
                               {int(context % 4), int(context % 3), int(context % 5)},
                               {&models[context % 8], &models[(context >> 3) % 8]}, bits[i]);
    }
  };
  // Bits that are 1 with probability (context % 8) / 8, the context being
  // the one run() derives.
  std::vector<bool> sent(5000), received(5000);
  uint32_t state = 99, noise = 7;
  for (size_t i = 0; i < sent.size(); ++i) {
    state = state * 1664525u + 1013904223u;
    noise = noise * 22695477u + 1u;
    sent[i] = (noise >> 16) % 8 < (state >> 24) % 8;
  }
  std::vector<uint8_t> stream;
  RangeEncoder encoder(stream);
  encoder.restart();
  std::vector<bool> coded = sent;
  run(encoder, coded);
  encoder.finish();
  EXPECT_EQ(coded, sent);
  EXPECT_LT(stream.size(), sent.size() / 8);  // the contexts carry information
  RangeDecoder decoder;
  decoder.start(stream.data(), stream.size());
  run(decoder, received);
  EXPECT_EQ(received, sent);
  EXPECT_FALSE(decoder.invalid());
}

}  // namespace
}  // namespace kdmesh::test
