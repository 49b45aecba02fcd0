// The logistic mixer of the one-vertex split predictions.
#include <gtest/gtest.h>

#include <cstdint>

#include "mixer.h"

namespace kdmesh::test {
namespace {

TEST(Logistic, SquashIsMonotoneAndStretchInvertsIt) {
  EXPECT_EQ(Logistic::squash(0), 2048);
  int previous = 0;
  for (int d = -2047; d <= 2047; ++d) {
    const int p = Logistic::squash(d);
    ASSERT_GE(p, previous) << d;
    previous = p;
  }
  for (int p = 16; p < 4080; p += 7) {
    // stretch(p) is the smallest d whose squash reaches p.
    const int d = Logistic::stretch(p);
    EXPECT_GE(Logistic::squash(d), p) << p;
    EXPECT_LT(Logistic::squash(d - 1), p) << p;
  }
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

}  // namespace
}  // namespace kdmesh::test
