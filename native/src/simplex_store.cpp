#include "simplex_store.h"

#include <algorithm>

namespace kdmesh {

void SimplexStore::reset(uint32_t vertexCapacity, bool indexed) {
  indexed_ = indexed;
  labelled_ = false;
  for (int d = 1; d <= kMaxDimension; ++d) {
    pool_[d] = Pool{};
    if (indexed) pool_[d].table.assign(16, IndexSlot{});
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

// Order-independent: the sum of the vertices' mixed ids, so no sort.
uint32_t SimplexStore::hashOf(int dimension, const uint32_t* vertices) {
  uint64_t sum = uint64_t(dimension) << 56;
  for (int i = 0; i <= dimension; ++i) {
    uint64_t h = (vertices[i] + 0x9e3779b97f4a7c15ull) * 0xff51afd7ed558ccdull;
    sum += h ^ h >> 29;
  }
  sum *= 0xc4ceb9fe1a85ec53ull;
  return uint32_t(sum >> 32);
}

// Each of the simplex's vertices among `vertices` (both hold distinct ids),
// without a branch per comparison.
bool SimplexStore::sameSet(int dimension, uint32_t simplex, const uint32_t* vertices) const {
  const uint32_t* mine = this->vertices(dimension, simplex);
  int found = 0;
  for (int i = 0; i <= dimension; ++i)
    for (int j = 0; j <= dimension; ++j) found += mine[i] == vertices[j];
  return found == dimension + 1;
}

// Sized for three times the live simplices at least, a table takes half as
// many insertions again before it is half full: the rebuilds' work sums to
// a few times the largest live count.
void SimplexStore::rebuildIndex(int dimension) {
  Pool& pool = pool_[dimension];
  size_t slots = 16;
  while (slots < size_t(live_[dimension]) * 3 + 4) slots *= 2;
  pool.table.assign(slots, IndexSlot{});
  pool.tableEntries = 0;
  for (uint32_t simplex = 0; simplex < size(dimension); ++simplex)
    if (pool.flags[simplex] & kAlive) insertIndex(dimension, simplex);
}

void SimplexStore::insertIndex(int dimension, uint32_t simplex) {
  Pool& pool = pool_[dimension];
  if (size_t(pool.tableEntries + 1) * 2 > pool.table.size()) return rebuildIndex(dimension);
  const uint32_t hash = hashOf(dimension, vertices(dimension, simplex));
  const size_t mask = pool.table.size() - 1;
  size_t at = hash & mask;
  while (pool.table[at].simplex != kNoSimplex) at = (at + 1) & mask;
  pool.table[at] = {simplex, hash};
  ++pool.tableEntries;
}

uint32_t SimplexStore::add(int dimension, const uint32_t* vertices, uint8_t flags, uint32_t label) {
  Pool& pool = pool_[dimension];
  const uint32_t simplex = uint32_t(pool.flags.size());
  const size_t arity = size_t(dimension + 1);
  // Slots are simplex * arity + position in 32 bits.
  if (simplex >= pool.capacity || simplex >= 0xfffffff0u / arity) return kNoSimplex;
  pool.vertices.insert(pool.vertices.end(), vertices, vertices + arity);
  pool.flags.push_back(uint8_t(flags | kAlive));
  if (labelled_) pool.labels.push_back(label);
  ++live_[dimension];
  if (!pool.table.empty()) insertIndex(dimension, simplex);
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
  if (pool.table.empty()) return kNoSimplex;
  const size_t mask = pool.table.size() - 1;
  const uint32_t hash = hashOf(dimension, vertices);
  for (size_t at = hash & mask;; at = (at + 1) & mask) {
    const IndexSlot& entry = pool.table[at];
    if (entry.simplex == kNoSimplex) return kNoSimplex;
    if (entry.hash == hash && (pool.flags[entry.simplex] & kAlive) && sameSet(dimension, entry.simplex, vertices))
      return entry.simplex;
  }
}

void SimplexStore::dropIndex() {
  for (int d = 1; d <= kMaxDimension; ++d) {
    pool_[d].table = LargeArray<IndexSlot>();
    pool_[d].tableEntries = 0;
  }
}

void SimplexStore::kill(int dimension, uint32_t simplex) {
  pool_[dimension].flags[simplex] &= uint8_t(~kAlive);
  --live_[dimension];
}

void SimplexStore::replaceVertex(int dimension, uint32_t simplex, uint32_t from, uint32_t to) {
  uint32_t* v = &pool_[dimension].vertices[size_t(simplex) * size_t(dimension + 1)];
  for (int i = 0; i <= dimension; ++i) v[i] = v[i] == from ? to : v[i];  // no branch to mispredict
  if (!pool_[dimension].table.empty()) insertIndex(dimension, simplex);
}

bool SimplexStore::hasIncident(int dimension, uint32_t vertex) const {
  return forEachIncident(dimension, vertex, [](uint32_t, uint32_t) { return true; });
}

void SimplexStore::link(int dimension, uint32_t simplex, uint32_t position) {
  Pool& pool = pool_[dimension];
  const uint32_t slot = simplex * uint32_t(dimension + 1) + position;
  const uint32_t vertex = pool.vertices[slot];
  pool.next[slot] = heads_[dimension][vertex];
  heads_[dimension][vertex] = slot;
}

}  // namespace kdmesh
