// The simplex store's walks against a plain set of vertex sets, through the
// adds and kills that the decimation makes; the input complex's search for
// repeated vertex sets against a map.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <set>
#include <vector>

#include "decimation.h"
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

// Every vertex's walk lists exactly the live simplices that hold it, through
// adds and kills in random order; walks that unlink killed slots as they
// pass and walks that only skip them agree.
TEST(SimplexStore, WalksListTheLiveSimplicesThroughKills) {
  std::mt19937 random(7);
  constexpr uint32_t kVertices = 40;
  for (int dimension = 1; dimension <= 3; ++dimension) {
    SimplexStore store;
    store.reset(kVertices, true);
    std::map<VertexSet, uint32_t> live;  // vertex set -> simplex
    for (int step = 0; step < 4000; ++step) {
      if (random() % 3 != 0 || live.empty()) {
        std::vector<uint32_t> all(kVertices);
        for (uint32_t i = 0; i < kVertices; ++i) all[i] = i;
        std::shuffle(all.begin(), all.end(), random);
        const VertexSet tuple(all.begin(), all.begin() + dimension + 1);
        VertexSet key = tuple;
        std::sort(key.begin(), key.end());
        if (live.count(key)) continue;
        const uint32_t simplex = store.add(dimension, tuple.data(), 0);
        ASSERT_NE(simplex, kNoSimplex);
        live[key] = simplex;
      } else {
        auto it = live.begin();
        std::advance(it, random() % live.size());
        store.kill(dimension, it->second);
        live.erase(it);
      }
      if (step % 250 != 0) continue;
      for (uint32_t v = 0; v < kVertices; ++v) {
        std::set<uint32_t> expected;
        for (const auto& [key, simplex] : live)
          if (std::count(key.begin(), key.end(), v)) expected.insert(simplex);
        std::set<uint32_t> skipping, unlinking;
        std::as_const(store).forEachIncident(dimension, v, [&](uint32_t simplex, uint32_t position) {
          EXPECT_EQ(store.vertices(dimension, simplex)[position], v);
          skipping.insert(simplex);
        });
        store.forEachIncident(dimension, v, [&](uint32_t simplex, uint32_t) { unlinking.insert(simplex); });
        ASSERT_EQ(skipping, expected) << "vertex " << v;
        ASSERT_EQ(unlinking, expected) << "vertex " << v;
      }
      ASSERT_EQ(store.liveCount(dimension), live.size());
    }
  }
}

// A vertex set in a tuple changes it in place, orientation kept; lists are
// the caller's to relink.
TEST(SimplexStore, SetVertexKeepsTheOrientation) {
  SimplexStore store;
  store.reset(8, true);
  const uint32_t a[3] = {0, 1, 2}, b[3] = {0, 2, 3};
  const uint32_t first = store.add(2, a, 0);
  const uint32_t second = store.add(2, b, SimplexStore::kFlipped);
  const int parity = store.parity(2, second);
  store.kill(2, first);
  store.setVertex(2, second, 2, 5);  // 3 is at position 2 of 0 2 3
  EXPECT_EQ(sortedVertices(store, 2, second), (VertexSet{0, 2, 5}));
  EXPECT_EQ(store.parity(2, second), parity);  // 0 2 3 and 0 2 5: same rank order
  std::vector<uint32_t> around;
  store.forEachIncident(2, 0, [&](uint32_t simplex, uint32_t) { around.push_back(simplex); });
  EXPECT_EQ(around, (std::vector<uint32_t>{second}));
  EXPECT_EQ(store.liveCount(2), 1u);
}

// firstWithSameVertices() against a map of sorted vertex sets, on tuples
// drawn from few vertices (so sets repeat, in any vertex order) and with one
// vertex in most of them (one long run to sort).
TEST(InputComplex, FirstWithSameVerticesAgreesWithAMap) {
  std::mt19937 random(11);
  for (int arity = 2; arity <= 4; ++arity)
    for (const uint32_t vertices : {6u, 30u, 400u}) {
      SCOPED_TRACE(std::to_string(arity) + " vertices per tuple of " + std::to_string(vertices));
      LargeArray<uint32_t> tuples;
      for (int t = 0; t < 3000; ++t) {
        std::vector<uint32_t> all(vertices);
        for (uint32_t i = 0; i < vertices; ++i) all[i] = i;
        std::shuffle(all.begin(), all.end(), random);
        if (t % 2 == 0 && std::find(all.begin(), all.begin() + arity, 0u) == all.begin() + arity) all[0] = 0;
        tuples.insert(tuples.end(), all.begin(), all.begin() + arity);
      }
      const LargeArray<uint32_t> first = firstWithSameVertices(tuples, arity, vertices);
      ASSERT_EQ(first.size(), tuples.size() / size_t(arity));
      std::map<VertexSet, uint32_t> seen;
      size_t repeats = 0;
      for (uint32_t i = 0; i < first.size(); ++i) {
        VertexSet key(tuples.begin() + i * arity, tuples.begin() + (i + 1) * arity);
        std::sort(key.begin(), key.end());
        const auto [it, inserted] = seen.emplace(key, i);
        repeats += !inserted;
        ASSERT_EQ(first[i], it->second) << "tuple " << i;
      }
      if (vertices <= 30) {
        EXPECT_GT(repeats, 100u);  // the case the function exists for
      }
    }
}

}  // namespace
}  // namespace kdmesh
