#include "simplex_store.h"

#include <algorithm>

namespace kdmesh {
namespace {

void sortSmall(uint32_t* v, int n) {
  for (int i = 1; i < n; ++i)
    for (int j = i; j > 0 && v[j - 1] > v[j]; --j) std::swap(v[j - 1], v[j]);
}

}  // namespace

void SimplexStore::reset(uint32_t vertexCapacity, bool indexed) {
  indexed_ = indexed;
  for (int d = 1; d <= kMaxDimension; ++d) {
    pool_[d] = Pool{};
    if (indexed) pool_[d].table.assign(16, kNoSimplex);
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
}

uint64_t SimplexStore::hashOf(int dimension, const uint32_t* vertices) {
  uint32_t v[4];
  std::copy(vertices, vertices + dimension + 1, v);
  sortSmall(v, dimension + 1);
  uint64_t h = 0x9e3779b97f4a7c15ull * uint64_t(dimension + 1);
  for (int i = 0; i <= dimension; ++i) {
    h ^= v[i];
    h *= 0xff51afd7ed558ccdull;
    h ^= h >> 32;
  }
  return h;
}

bool SimplexStore::sameSet(int dimension, uint32_t simplex, const uint32_t* vertices) const {
  const uint32_t* mine = this->vertices(dimension, simplex);
  for (int i = 0; i <= dimension; ++i)
    if (std::find(mine, mine + dimension + 1, vertices[i]) == mine + dimension + 1) return false;
  return true;
}

void SimplexStore::grow(int dimension) {
  Pool& pool = pool_[dimension];
  std::vector<uint32_t> old(pool.table.size() * 2, kNoSimplex);
  old.swap(pool.table);
  for (const uint32_t simplex : old)
    if (simplex != kNoSimplex) insertIndex(dimension, simplex);
}

void SimplexStore::insertIndex(int dimension, uint32_t simplex) {
  Pool& pool = pool_[dimension];
  const size_t mask = pool.table.size() - 1;
  size_t at = size_t(hashOf(dimension, vertices(dimension, simplex))) & mask;
  while (pool.table[at] != kNoSimplex) at = (at + 1) & mask;
  pool.table[at] = simplex;
}

// Linear probing with backward-shift deletion: no tombstones, so lookups stay
// short however many simplices the decimation kills.
void SimplexStore::eraseIndex(int dimension, uint32_t simplex) {
  Pool& pool = pool_[dimension];
  const size_t mask = pool.table.size() - 1;
  size_t at = size_t(hashOf(dimension, vertices(dimension, simplex))) & mask;
  while (pool.table[at] != simplex) at = (at + 1) & mask;
  for (size_t next = (at + 1) & mask;; next = (next + 1) & mask) {
    const uint32_t moving = pool.table[next];
    if (moving == kNoSimplex) break;
    const size_t home = size_t(hashOf(dimension, vertices(dimension, moving))) & mask;
    // `moving` may fill the hole unless its home lies cyclically in (at, next].
    const bool homeInRange = at <= next ? (home > at && home <= next) : (home > at || home <= next);
    if (!homeInRange) {
      pool.table[at] = moving;
      at = next;
    }
  }
  pool.table[at] = kNoSimplex;
}

uint32_t SimplexStore::add(int dimension, const uint32_t* vertices, uint8_t flags) {
  Pool& pool = pool_[dimension];
  const uint32_t simplex = uint32_t(pool.flags.size());
  const size_t arity = size_t(dimension + 1);
  // Slots are simplex * arity + position in 32 bits.
  if (simplex >= pool.capacity || simplex >= 0xfffffff0u / arity) return kNoSimplex;
  pool.vertices.insert(pool.vertices.end(), vertices, vertices + arity);
  pool.flags.push_back(uint8_t(flags | kAlive));
  ++live_[dimension];
  if (indexed_) {
    if (size_t(live_[dimension]) * 2 > pool.table.size()) grow(dimension);
    insertIndex(dimension, simplex);
  }
  // Slots pushed one by one: resize() was an out-of-line call in the
  // decoder's third most frequent function.
  for (uint32_t i = 0; i < arity; ++i) {
    pool.next.push_back(kNoSimplex);
    link(dimension, simplex, i);
  }
  return simplex;
}

uint32_t SimplexStore::find(int dimension, const uint32_t* vertices) const {
  const Pool& pool = pool_[dimension];
  const size_t mask = pool.table.size() - 1;
  for (size_t at = size_t(hashOf(dimension, vertices)) & mask;; at = (at + 1) & mask) {
    const uint32_t simplex = pool.table[at];
    if (simplex == kNoSimplex) return kNoSimplex;
    if (sameSet(dimension, simplex, vertices)) return simplex;
  }
}

void SimplexStore::kill(int dimension, uint32_t simplex) {
  if (indexed_) eraseIndex(dimension, simplex);
  pool_[dimension].flags[simplex] &= uint8_t(~kAlive);
  --live_[dimension];
}

void SimplexStore::replaceVertex(int dimension, uint32_t simplex, uint32_t from, uint32_t to) {
  if (indexed_) eraseIndex(dimension, simplex);
  uint32_t* v = &pool_[dimension].vertices[size_t(simplex) * size_t(dimension + 1)];
  for (int i = 0; i <= dimension; ++i) v[i] = v[i] == from ? to : v[i];  // no branch to mispredict
  if (indexed_) insertIndex(dimension, simplex);
}

bool SimplexStore::hasIncident(int dimension, uint32_t vertex) const {
  return forEachIncident(dimension, vertex, [](uint32_t, uint32_t) { return true; });
}

bool SimplexStore::isFace(int dimension, uint32_t simplex) const {
  if (dimension >= kMaxDimension) return false;
  const uint32_t* mine = vertices(dimension, simplex);
  const int arity = dimension + 2;
  return forEachIncident(dimension + 1, mine[0], [&](uint32_t candidate, uint32_t) {
    const uint32_t* theirs = vertices(dimension + 1, candidate);
    bool all = true;
    for (int i = 1; i <= dimension && all; ++i) all = std::find(theirs, theirs + arity, mine[i]) != theirs + arity;
    return all;
  });
}

void SimplexStore::link(int dimension, uint32_t simplex, uint32_t position) {
  Pool& pool = pool_[dimension];
  const uint32_t slot = simplex * uint32_t(dimension + 1) + position;
  const uint32_t vertex = pool.vertices[slot];
  pool.next[slot] = heads_[dimension][vertex];
  heads_[dimension][vertex] = slot;
}

}  // namespace kdmesh
