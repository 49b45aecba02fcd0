// The robust statistics of the parallelogram predictions and the placing of
// neighbours along the split axis (position_predictor.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "position_predictor.h"

namespace kdmesh::test {
namespace {

// The definition, spelled out: sort, take the middle (or the mean of the
// two middle values), then the same for the absolute deviations.
void referenceMedianAndDeviation(std::vector<double> values, double& median, double& deviation) {
  auto middle = [](std::vector<double>& v) {
    std::sort(v.begin(), v.end());
    const size_t half = v.size() / 2;
    return v.size() % 2 == 1 ? v[half] : 0.5 * (v[half - 1] + v[half]);
  };
  median = middle(values);
  for (double& value : values) value = std::fabs(value - median);
  deviation = middle(values);
}

TEST(MedianAndDeviation, SmallCases) {
  double values[4] = {3, -1, 2, 10};
  double median = 0, deviation = 0;
  medianAndDeviation(values, 1, median, deviation);
  EXPECT_EQ(median, 3);
  EXPECT_EQ(deviation, 0);
  double pair[2] = {3, -1};
  medianAndDeviation(pair, 2, median, deviation);
  EXPECT_EQ(median, 1);  // mean of the two
  EXPECT_EQ(deviation, 2);
  double four[4] = {3, -1, 2, 10};
  medianAndDeviation(four, 4, median, deviation);
  EXPECT_EQ(median, 2.5);      // (2 + 3) / 2
  EXPECT_EQ(deviation, 2.0);   // deviations 0.5, 0.5, 3.5, 7.5
  // One outlier moves a mean, not the median: a crease's parallelogram.
  double crease[5] = {0.5, 0.25, 40, 0.5, 0.75};
  medianAndDeviation(crease, 5, median, deviation);
  EXPECT_EQ(median, 0.5);
  EXPECT_EQ(deviation, 0.25);
}

// Every path (sorting networks for three to eight values, a sort
// otherwise) against the definition, with ties, signed zeros and halves as
// the decoder's offsets have them.
TEST(MedianAndDeviation, MatchesTheDefinitionForEveryCount) {
  uint32_t state = 2024;
  auto next = [&] {
    state = state * 1664525u + 1013904223u;
    return state >> 8;
  };
  for (uint32_t count = 1; count <= 40; ++count) {
    for (int trial = 0; trial < 200; ++trial) {
      std::vector<double> values(count);
      for (double& value : values) {
        const uint32_t r = next();
        value = r % 7 == 0 ? 0.0 : r % 11 == 0 ? -0.0 : (double(int(r % 257) - 128) * 0.5);
      }
      double expectedMedian = 0, expectedDeviation = 0;
      referenceMedianAndDeviation(values, expectedMedian, expectedDeviation);
      double median = 1, deviation = 1;
      medianAndDeviation(values.data(), count, median, deviation);
      ASSERT_EQ(median, expectedMedian) << count << " values, trial " << trial;
      ASSERT_EQ(deviation, expectedDeviation) << count << " values, trial " << trial;
    }
  }
}

// Neighbours placed as the decoder places them: cell centres of one level
// (p·w + (w − 1)/2), some moved a quarter width into the half they split
// to, offsets from the cell at hand in its half widths.
TEST(AlongBin, PlacesNeighboursBySlabAndSide) {
  for (const double width : {1.0, 2.0, 64.0, 1048576.0}) {
    const double halfWidth = width / 2, quarter = width / 4;
    const double mine = 37 * width + (width - 1) / 2;
    for (int slab = -4; slab <= 4; ++slab) {
      for (int side = -1; side <= 1; ++side) {
        const double theirs = (37 + slab) * width + (width - 1) / 2 + side * quarter;
        const int expected = slab >= -1 && slab <= 1 ? 3 * (slab + 1) + side + 1 : 9;
        EXPECT_EQ(alongBin((theirs - mine) * (1 / halfWidth)), expected) << width << " " << slab << " " << side;
      }
    }
  }
  // Half a width off the grid (not a place the decoder gives a cell):
  // the lower of the two slabs it lies between, not split.
  EXPECT_EQ(alongBin(1.0), 4);
  EXPECT_EQ(alongBin(-1.0), 1);
  EXPECT_EQ(alongBin(3.0), 7);
  EXPECT_EQ(alongBin(-3.0), 9);
  // Far off on a 30-bit grid, with no overflow.
  EXPECT_EQ(alongBin(std::ldexp(1.0, 31) + 0.5), 9);
  EXPECT_EQ(alongBin(-std::ldexp(1.0, 31) - 0.5), 9);
}

}  // namespace
}  // namespace kdmesh::test
