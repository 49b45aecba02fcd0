// A simplicial complex that changes one vertex star at a time: the encoder
// merges vertices (decimation), the decoder splits them.
//
// Simplices of dimension 1..3 live in flat per-dimension pools. A simplex
// stores its vertices as an oriented tuple (for triangles and tetrahedra the
// tuple order, corrected by a `flipped` bit, is the orientation). Each
// vertex has, per dimension, a singly linked list of the incidence slots
// (simplex, position in tuple) that hold it, so a star is walked without
// scanning the complex. Killed simplices leave their slots in the lists of
// other vertices; walks drop them as they pass.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "large_array.h"

namespace kdmesh {

constexpr uint32_t kNoSimplex = 0xffffffffu;
// A simplex's label is an index into the stream's label table; kNoLabel on
// the encoder marks a simplex whose label is free (a face that the closure
// added, whose label nothing depends on).
constexpr uint32_t kNoLabel = 0xffffffffu;

// Parity of the permutation that sorts the n vertex ids v[0..n) ascending:
// 0 even, 1 odd.
inline int tupleParity(const uint32_t* v, int n) {
  int inversions = 0;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) inversions += v[i] > v[j];
  return inversions & 1;
}

// Whether vertex is one of vertices[0..arity): a plain loop, without a
// branch per id (std::find over at most four ids was an out-of-line call).
inline bool containsVertex(const uint32_t* vertices, int arity, uint32_t vertex) {
  bool found = false;
  for (int i = 0; i < arity; ++i) found |= vertices[i] == vertex;
  return found;
}

// Sorts the n ≤ 4 vertex ids v[0..n) ascending by a network of minima and
// maxima: no branch on the ids, whose order is a coin toss for the branch
// predictor.
inline void sortFewVertices(uint32_t* v, int n) {
  auto order = [v](int a, int b) {
    const uint32_t x = v[a], y = v[b];
    v[a] = std::min(x, y);
    v[b] = std::max(x, y);
  };
  if (n == 2) {
    order(0, 1);
  } else if (n == 3) {
    order(0, 1), order(1, 2), order(0, 1);
  } else if (n == 4) {
    order(0, 1), order(2, 3), order(0, 2), order(1, 3), order(1, 2);
  }
}

class SimplexStore {
 public:
  static constexpr int kMaxDimension = 3;

  enum Flag : uint8_t {
    kAlive = 1,
    kFlipped = 2,     // orientation is the tuple with its first two swapped
    kMeaningful = 4,  // encoder: some input simplex of this dimension maps here
    kUndecided = 8,   // orientation not yet decoded in the current split
  };

  // `killable`: simplices may be killed (the encoder's decimation); walks
  // then skip killed ones. The decoder's store only grows, and its walks
  // need not look at the flags.
  void reset(uint32_t vertexCapacity, bool killable);
  // Gives every simplex a label (index into the label table); only stores
  // of labelled complexes pay for them. Call after reset(), before add().
  void enableLabels() { labelled_ = true; }
  bool labelled() const { return labelled_; }
  uint32_t vertexCapacity() const { return uint32_t(heads_[1].size()); }
  // Makes room for vertex ids below `count` (lists start empty).
  void growVertices(uint32_t count);
  // Pool sizes (live and killed) may not exceed `maxSimplices`; add()
  // reports kNoSimplex. Memory for `expected` simplices is reserved at once.
  void setCapacity(int dimension, uint32_t maxSimplices, uint32_t expected);

  // Adds a simplex whose vertices are all distinct and that is not yet
  // present; links it into its vertices' lists. Returns its index, or
  // kNoSimplex when the pool is at capacity. `label` is kept by labelled
  // stores only.
  uint32_t add(int dimension, const uint32_t* vertices, uint8_t flags, uint32_t label = kNoLabel);
  // Killable stores only.
  void kill(int dimension, uint32_t simplex);
  // Puts `vertex` at `position` of a simplex's tuple (which must not
  // contain it elsewhere), keeping the orientation. Lists are left alone:
  // the split and merge routines detach and relink the vertices' lists
  // themselves.
  void setVertex(int dimension, uint32_t simplex, uint32_t position, uint32_t vertex) {
    pool_[dimension].vertices[size_t(simplex) * size_t(dimension + 1) + position] = vertex;
  }

  const uint32_t* vertices(int dimension, uint32_t simplex) const {
    return &pool_[dimension].vertices[size_t(simplex) * size_t(dimension + 1)];
  }
  // The vertex in an incidence slot (simplex · (dimension + 1) + position).
  uint32_t vertexInSlot(int dimension, uint32_t slot) const { return pool_[dimension].vertices[slot]; }
  uint8_t& flags(int dimension, uint32_t simplex) { return pool_[dimension].flags[simplex]; }
  uint8_t flags(int dimension, uint32_t simplex) const { return pool_[dimension].flags[simplex]; }
  uint32_t& label(int dimension, uint32_t simplex) { return pool_[dimension].labels[simplex]; }
  uint32_t label(int dimension, uint32_t simplex) const { return pool_[dimension].labels[simplex]; }
  uint32_t size(int dimension) const { return uint32_t(pool_[dimension].flags.size()); }
  uint32_t liveCount(int dimension) const { return live_[dimension]; }

  // Orientation as the parity of the oriented tuple relative to the
  // ascending order of its vertex ids (0 even, 1 odd).
  int parity(int dimension, uint32_t simplex) const {
    return tupleParity(vertices(dimension, simplex), dimension + 1) ^ ((flags(dimension, simplex) & kFlipped) ? 1 : 0);
  }

  // Calls visit(simplex, position) for every live simplex of `dimension`
  // holding `vertex`, unlinking killed ones on the way. The walks, and
  // detach(), of a dimension without simplices (a surface's tetrahedra)
  // read no list head: a cache miss each, per vertex split.
  template <class Visit>
  void forEachIncident(int dimension, uint32_t vertex, Visit&& visit) {
    Pool& pool = pool_[dimension];
    if (pool.flags.size() == 0) return;
    const uint32_t arity = uint32_t(dimension + 1);
    uint32_t* link = &heads_[dimension][vertex];
    while (*link != kNoSimplex) {
      const uint32_t slot = *link;
      const uint32_t simplex = slot / arity;
      // Only the encoder's store kills simplices; the decoder's walk need
      // not load their flags.
      if (killable_ && !(pool.flags[simplex] & kAlive)) {
        *link = pool.next[slot];
        continue;
      }
      visit(simplex, slot % arity);
      link = &pool.next[slot];
    }
  }
  // The same walk without unlinking: killed simplices are skipped. A
  // visitor that returns a bool ends the walk by returning true, and the
  // walk then returns true.
  template <class Visit>
  bool forEachIncident(int dimension, uint32_t vertex, Visit&& visit) const {
    const Pool& pool = pool_[dimension];
    if (pool.flags.size() == 0) return false;
    const uint32_t arity = uint32_t(dimension + 1);
    for (uint32_t slot = heads_[dimension][vertex]; slot != kNoSimplex; slot = pool.next[slot]) {
      const uint32_t simplex = slot / arity;
      if (killable_ && !(pool.flags[simplex] & kAlive)) continue;
      if constexpr (std::is_same_v<decltype(visit(simplex, 0u)), bool>) {
        if (visit(simplex, slot - simplex * arity)) return true;
      } else {
        visit(simplex, slot - simplex * arity);
      }
    }
    return false;
  }
  bool hasIncident(int dimension, uint32_t vertex) const;
  // Walks the lists of `count` vertices whose stars are gathered soon and
  // prefetches their simplices' tuples and flags. Each walk is a chain of
  // dependent loads; the walks of different vertices overlap here, where a
  // star's gathering waits on each step in turn. Reads only.
  void prefetchStars(const uint32_t* vertices, size_t count) const;

  // One dimension's incidence lists as plain arrays, for the hottest walks:
  // a loop over local pointers keeps them in registers, where a walk
  // through the vectors reloads them after each of its stores. Valid until
  // the next add() of that dimension.
  struct Lists {
    const uint32_t* heads;     // first slot per vertex
    const uint32_t* next;      // next slot per slot
    const uint32_t* vertices;  // arity per simplex
    const uint8_t* flags;
    bool skipDead;  // killable stores' walks skip killed simplices
    bool alive(uint32_t simplex) const { return !skipDead || (flags[simplex] & kAlive); }
  };
  Lists lists(int dimension) const {
    const Pool& pool = pool_[dimension];
    return {heads_[dimension].data(), pool.next.data(), pool.vertices.data(), pool.flags.data(), killable_};
  }

  // Empties `vertex`'s list of `dimension` without touching the simplices;
  // the caller relinks every slot it keeps with link().
  void detach(int dimension, uint32_t vertex) {
    if (size(dimension) > 0) heads_[dimension][vertex] = kNoSimplex;
  }
  void link(int dimension, uint32_t simplex, uint32_t position);

 private:
  struct Pool {
    GrowingArray<uint32_t> vertices;  // dimension + 1 per simplex
    GrowingArray<uint32_t> next;      // next slot in the vertex list, per slot
    GrowingArray<uint8_t> flags;
    GrowingArray<uint32_t> labels;    // labelled stores only
    uint32_t capacity = 0xffffffffu;
  };

  std::array<Pool, 4> pool_;                      // [0] unused
  std::array<LargeArray<uint32_t>, 4> heads_;    // [0] unused
  std::array<uint32_t, 4> live_{};
  bool killable_ = true;
  bool labelled_ = false;
};

// Inline, as add(): a split relinks every simplex of its star.
inline void SimplexStore::link(int dimension, uint32_t simplex, uint32_t position) {
  Pool& pool = pool_[dimension];
  const uint32_t slot = simplex * uint32_t(dimension + 1) + position;
  const uint32_t vertex = pool.vertices[slot];
  pool.next[slot] = heads_[dimension][vertex];
  heads_[dimension][vertex] = slot;
}

// Inline, always (clang, building the WebAssembly module, left it a call):
// the decoder adds a few simplices per vertex split.
[[gnu::always_inline]] inline uint32_t SimplexStore::add(int dimension, const uint32_t* vertices, uint8_t flags, uint32_t label) {
  Pool& pool = pool_[dimension];
  const uint32_t simplex = uint32_t(pool.flags.size());
  const size_t arity = size_t(dimension + 1);
  // Slots are simplex * arity + position in 32 bits (a product, not a
  // quotient: the arity is not known at compile time, and a division is
  // slow).
  if (simplex >= pool.capacity || uint64_t(simplex) * arity >= 0xfffffff0u) return kNoSimplex;
  pool.flags.push_back(uint8_t(flags | kAlive));
  if (labelled_) pool.labels.push_back(label);
  ++live_[dimension];
  // Each slot joins the head of its vertex's list, as link() puts it, from
  // the vertex id at hand rather than read back from the pool.
  uint32_t* heads = heads_[dimension].data();
  uint32_t* tuple = pool.vertices.extend(arity);
  uint32_t* next = pool.next.extend(arity);
  const uint32_t firstSlot = simplex * uint32_t(arity);
  for (uint32_t i = 0; i < arity; ++i) {
    const uint32_t vertex = vertices[i];
    tuple[i] = vertex;
    next[i] = heads[vertex];
    heads[vertex] = firstSlot + i;
  }
  return simplex;
}

}  // namespace kdmesh
