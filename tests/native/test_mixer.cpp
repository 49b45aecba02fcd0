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

}  // namespace
}  // namespace kdmesh::test
