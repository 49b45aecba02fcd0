// The vertex split's context from how a cell's vertices divide.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <vector>

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

// findInStar() against a map from each simplex's other vertices, on random
// stars of a vertex: few simplices (ranked sort) and many (std::sort), each
// dimension, and other-vertex sets that are not in the star.
TEST(VertexSplit, FindInStarFindsEverySimplexOfTheStarByItsOtherVertices) {
  std::mt19937 random(11);
  constexpr uint32_t kCentre = 0, kVertices = 30;
  for (int trial = 0; trial < 40; ++trial) {
    SimplexStore store;
    store.reset(kVertices, true);
    std::map<std::vector<uint32_t>, uint32_t> expected[4];  // per dimension: others -> simplex
    const int wanted = trial % 2 == 0 ? 6 : 40;
    for (int d = 1; d <= 3; ++d)
      for (int attempt = 0; attempt < wanted; ++attempt) {
        std::vector<uint32_t> all;
        for (uint32_t v = 1; v < kVertices; ++v) all.push_back(v);
        std::shuffle(all.begin(), all.end(), random);
        std::vector<uint32_t> others(all.begin(), all.begin() + d);
        std::sort(others.begin(), others.end());
        if (expected[d].count(others)) continue;
        std::vector<uint32_t> tuple = others;
        tuple.insert(tuple.begin() + std::ptrdiff_t(random() % (d + 1)), kCentre);
        expected[d][others] = store.add(d, tuple.data(), 0);
      }
    std::vector<StarEntry> star;
    std::array<size_t, 5> begin{};
    gatherStar(store, kCentre, star, begin);
    EXPECT_EQ(findInStar(star, begin, 0, nullptr), &star[0]);
    for (int d = 1; d <= 3; ++d) {
      for (const auto& [others, simplex] : expected[d]) {
        const StarEntry* entry = findInStar(star, begin, d, others.data());
        ASSERT_NE(entry, nullptr);
        EXPECT_EQ(entry->simplex, simplex);
        EXPECT_EQ(entry->dimension, d);
      }
      for (int probe = 0; probe < 50; ++probe) {
        std::vector<uint32_t> others;
        for (int i = 0; i < d; ++i) others.push_back(uint32_t(random() % (kVertices + 5)));
        std::sort(others.begin(), others.end());
        const auto it = expected[d].find(others);
        const StarEntry* entry = findInStar(star, begin, d, others.data());
        if (it == expected[d].end()) {
          EXPECT_EQ(entry, nullptr);
        } else {
          ASSERT_NE(entry, nullptr);
          EXPECT_EQ(entry->simplex, it->second);
        }
      }
    }
  }
}

}  // namespace
}  // namespace kdmesh
