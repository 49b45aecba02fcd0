#include "simplex_store.h"

#include <algorithm>

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

}  // namespace kdmesh
