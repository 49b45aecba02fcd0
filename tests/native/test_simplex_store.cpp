// The simplex store's index against a plain set of vertex sets, through the
// adds, kills and vertex replacements that the decimation makes.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <vector>

#include "simplex_store.h"

namespace kdmesh {
namespace {

using VertexSet = std::vector<uint32_t>;  // sorted

VertexSet sortedVertices(const SimplexStore& store, int dimension, uint32_t simplex) {
  const uint32_t* v = store.vertices(dimension, simplex);
  VertexSet set(v, v + dimension + 1);
  std::sort(set.begin(), set.end());
  return set;
}

TEST(SimplexStore, FindAgreesWithASetModelThroughKillsAndReplacements) {
  std::mt19937 random(7);
  constexpr uint32_t kVertices = 40;
  for (int dimension = 1; dimension <= 3; ++dimension) {
    SimplexStore store;
    store.reset(kVertices, true);
    std::map<VertexSet, uint32_t> live;  // vertex set -> simplex
    auto randomSet = [&] {
      std::vector<uint32_t> all(kVertices);
      for (uint32_t i = 0; i < kVertices; ++i) all[i] = i;
      std::shuffle(all.begin(), all.end(), random);
      return VertexSet(all.begin(), all.begin() + dimension + 1);
    };
    // Many more operations than the table has slots at first, so that it is
    // rebuilt while growing and while shrinking.
    for (int step = 0; step < 20000; ++step) {
      const int action = int(random() % 10);
      if (action < 5 || live.empty()) {
        VertexSet tuple = randomSet();
        VertexSet key = tuple;
        std::sort(key.begin(), key.end());
        if (live.count(key)) continue;
        const uint32_t simplex = store.add(dimension, tuple.data(), 0);
        ASSERT_NE(simplex, kNoSimplex);
        live[key] = simplex;
      } else {
        auto it = live.begin();
        std::advance(it, random() % live.size());
        const uint32_t simplex = it->second;
        if (action < 8) {
          store.kill(dimension, simplex);
          live.erase(it);
        } else {
          // Replace one vertex by one the simplex lacks, if that set is free.
          const VertexSet before = it->first;
          const uint32_t from = before[random() % before.size()];
          const uint32_t to = uint32_t(random() % kVertices);
          if (std::count(before.begin(), before.end(), to)) continue;
          VertexSet after = before;
          *std::find(after.begin(), after.end(), from) = to;
          std::sort(after.begin(), after.end());
          if (live.count(after)) continue;
          store.replaceVertex(dimension, simplex, from, to);
          live.erase(it);
          live[after] = simplex;
          ASSERT_EQ(sortedVertices(store, dimension, simplex), after);
        }
      }
      // Every so often, every live set and as many absent ones are looked up.
      if (step % 500 != 0) continue;
      for (const auto& [key, simplex] : live) {
        VertexSet shuffled = key;
        std::shuffle(shuffled.begin(), shuffled.end(), random);
        ASSERT_EQ(store.find(dimension, shuffled.data()), simplex);
      }
      for (int probe = 0; probe < 200; ++probe) {
        VertexSet key = randomSet();
        VertexSet sorted = key;
        std::sort(sorted.begin(), sorted.end());
        const auto it = live.find(sorted);
        ASSERT_EQ(store.find(dimension, key.data()), it == live.end() ? kNoSimplex : it->second);
      }
      ASSERT_EQ(store.liveCount(dimension), live.size());
    }
  }
}

// After dropIndex() a store keeps its kills (walks skip killed simplices)
// and takes adds and vertex replacements without an index.
TEST(SimplexStore, DroppedIndexKeepsKillsAndWalks) {
  SimplexStore store;
  store.reset(8, true);
  const uint32_t a[3] = {0, 1, 2}, b[3] = {0, 2, 3}, c[3] = {0, 3, 4};
  const uint32_t first = store.add(2, a, 0);
  const uint32_t second = store.add(2, b, 0);
  store.dropIndex();
  EXPECT_EQ(store.find(2, a), kNoSimplex);  // no index to ask
  store.kill(2, first);
  const uint32_t third = store.add(2, c, 0);
  store.replaceVertex(2, second, 3, 5);
  std::vector<uint32_t> around;
  store.forEachIncident(2, 0, [&](uint32_t simplex, uint32_t) { around.push_back(simplex); });
  std::sort(around.begin(), around.end());
  EXPECT_EQ(around, (std::vector<uint32_t>{second, third}));
  EXPECT_EQ(sortedVertices(store, 2, second), (VertexSet{0, 2, 5}));
  EXPECT_EQ(store.liveCount(2), 2u);
}

}  // namespace
}  // namespace kdmesh
