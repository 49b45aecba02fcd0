#include "simplex_store.h"

#include <algorithm>
#include <type_traits>

namespace kdmesh {

void SimplexStore::reset(uint32_t vertexCapacity, bool killable) {
  killable_ = killable;
  labelled_ = false;
  for (int d = 1; d <= kMaxDimension; ++d) {
    pool_[d] = Pool{};
    heads_[d].assign(vertexCapacity, kNoSimplex);
    live_[d] = 0;
  }
}

void SimplexStore::growVertices(uint32_t count) {
  for (int d = 1; d <= kMaxDimension; ++d)
    if (heads_[d].size() < count) heads_[d].resize(count, kNoSimplex);
}

void SimplexStore::setCapacity(int dimension, uint32_t maxSimplices, uint32_t expected) {
  Pool& pool = pool_[dimension];
  pool.capacity = maxSimplices;
  expected = std::min(expected, maxSimplices);
  pool.vertices.reserve(size_t(expected) * size_t(dimension + 1));
  pool.next.reserve(size_t(expected) * size_t(dimension + 1));
  pool.flags.reserve(expected);
  if (labelled_) pool.labels.reserve(expected);
}

void SimplexStore::kill(int dimension, uint32_t simplex) {
  pool_[dimension].flags[simplex] &= uint8_t(~kAlive);
  --live_[dimension];
}

bool SimplexStore::hasIncident(int dimension, uint32_t vertex) const {
  return forEachIncident(dimension, vertex, [](uint32_t, uint32_t) { return true; });
}

void SimplexStore::prefetchStars(const uint32_t* vertices, size_t count) const {
  // The walks count their steps into a volatile store: a loop whose only
  // effects are prefetches may otherwise be deleted (C++ lets the compiler
  // assume that such a loop ends, and a prefetch changes nothing).
  uint32_t steps = 0;
  // The lists are walked side by side, a step of each in turn: the steps
  // of one list depend on each other, those of different lists do not, so
  // the processor overlaps their misses. The arity is a constant: a slot's
  // simplex is then a multiplication away, not a division.
  constexpr size_t kSideBySide = 64;
  auto walk = [this, &steps](auto arity, const uint32_t* batch, size_t batchSize) {
    const Pool& pool = pool_[arity - 1];
    if (pool.flags.size() == 0) return;
    const LargeArray<uint32_t>& heads = heads_[arity - 1];
    uint32_t slots[kSideBySide];
    size_t active = 0;
    for (size_t i = 0; i < batchSize; ++i) {
      if (batch[i] >= heads.size()) continue;
      slots[active] = heads[batch[i]];
      active += slots[active] != kNoSimplex;
    }
    while (active > 0) {
      size_t kept = 0;
      for (size_t i = 0; i < active; ++i) {
        const uint32_t slot = slots[i], simplex = slot / arity;
        __builtin_prefetch(&pool.vertices[size_t(simplex) * arity]);
        __builtin_prefetch(&pool.flags[simplex]);
        ++steps;
        slots[kept] = pool.next[slot];
        kept += slots[kept] != kNoSimplex;
      }
      active = kept;
    }
  };
  for (size_t first = 0; first < count; first += kSideBySide) {
    const size_t batchSize = std::min(kSideBySide, count - first);
    walk(std::integral_constant<uint32_t, 2>(), vertices + first, batchSize);
    walk(std::integral_constant<uint32_t, 3>(), vertices + first, batchSize);
    walk(std::integral_constant<uint32_t, 4>(), vertices + first, batchSize);
  }
  [[maybe_unused]] volatile uint32_t walked = steps;
}

}  // namespace kdmesh
