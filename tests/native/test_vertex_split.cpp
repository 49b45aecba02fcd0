// The vertex split's context from how a cell's vertices divide.
#include <gtest/gtest.h>

#include <set>

#include "vertex_split.h"

namespace kdmesh {
namespace {

TEST(VertexSplit, BalanceClassesFollowTheHalvesSizes) {
  EXPECT_EQ(splitBalance(2, 1, true), 1);
  EXPECT_EQ(splitBalance(7, 1, true), 2);
  EXPECT_EQ(splitBalance(7, 6, true), 3);
  EXPECT_EQ(splitBalance(7, 2, true), 4);
  EXPECT_EQ(splitBalance(7, 5, true), 5);
  EXPECT_EQ(splitBalance(3, 1, true), 2);  // a single vertex is named before a pair
  EXPECT_EQ(splitBalance(3, 2, true), 3);
  EXPECT_EQ(splitBalance(100, 34, true), 6);
  EXPECT_EQ(splitBalance(100, 35, true), 7);
  EXPECT_EQ(splitBalance(100, 65, true), 7);
  EXPECT_EQ(splitBalance(100, 66, true), 8);
  // Coincident vertices, past the geometric levels, have no halves in space.
  EXPECT_EQ(splitBalance(100, 50, false), 0);
  // Every class a geometric split can take is a model row of its own.
  std::set<int> seen;
  for (uint32_t population = 2; population < 40; ++population)
    for (uint32_t first = 1; first < population; ++first) seen.insert(splitBalance(population, first, true));
  EXPECT_EQ(seen, (std::set<int>{1, 2, 3, 4, 5, 6, 7, 8}));
}

}  // namespace
}  // namespace kdmesh
