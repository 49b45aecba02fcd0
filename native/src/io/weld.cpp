// ReadOptions::weld: vertices with bit-identical positions become one vertex.
#include <algorithm>
#include <array>
#include <cstring>
#include <numeric>

#include "io/io_internal.h"

namespace kdmesh::io::detail {
namespace {

using Bits3 = std::array<uint32_t, 3>;

bool hasRepeatedVertex(const uint32_t* simplex, size_t arity) {
  for (size_t i = 0; i < arity; ++i) {
    for (size_t j = i + 1; j < arity; ++j) {
      if (simplex[i] == simplex[j]) return true;
    }
  }
  return false;
}

// Renumbers `indices` and counts the simplices left with a repeated vertex.
size_t remap(std::vector<uint32_t>& indices, size_t arity,
             const std::vector<uint32_t>& newIndex) {
  for (uint32_t& index : indices) index = newIndex[index];
  size_t degenerate = 0;
  if (arity < 2) return 0;
  for (size_t i = 0; i + arity <= indices.size(); i += arity) {
    degenerate += hasRepeatedVertex(&indices[i], arity);
  }
  return degenerate;
}

}  // namespace

void weldVertices(Complex& complex, Notes& notes) {
  const size_t n = complex.vertexCount();
  if (n < 2) return;
  std::vector<Bits3> bits(n);
  for (size_t v = 0; v < n; ++v) {
    std::memcpy(bits[v].data(), &complex.positions[3 * v], sizeof(Bits3));
  }
  // Equal positions end up next to each other, the lowest index first.
  std::vector<uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&bits](uint32_t a, uint32_t b) {
    return bits[a] != bits[b] ? bits[a] < bits[b] : a < b;
  });
  std::vector<uint32_t> first(n);  // the lowest index with the same bits
  for (size_t i = 0; i < n; ++i) {
    const uint32_t v = order[i];
    first[v] = i > 0 && bits[order[i - 1]] == bits[v] ? first[order[i - 1]] : v;
  }
  // Kept vertices in their original order; first[v] <= v, so the positions
  // move down in place.
  std::vector<uint32_t> newIndex(n);
  uint32_t kept = 0;
  for (size_t v = 0; v < n; ++v) {
    if (first[v] != v) {
      newIndex[v] = newIndex[first[v]];
      continue;
    }
    newIndex[v] = kept;
    std::memmove(&complex.positions[3 * size_t{kept}],
                 &complex.positions[3 * v], 3 * sizeof(float));
    ++kept;
  }
  if (kept == n) return;
  complex.positions.resize(3 * size_t{kept});
  remap(complex.points, 1, newIndex);
  const size_t degenerate = remap(complex.edges, 2, newIndex) +
                            remap(complex.triangles, 3, newIndex) +
                            remap(complex.tetrahedra, 4, newIndex);
  notes.push_back("welded " + std::to_string(n - kept) +
                  " vertices with bit-identical positions into others (" +
                  std::to_string(n) + " -> " + std::to_string(kept) +
                  " vertices)");
  addCountNote(notes, "after welding, ", degenerate,
               " simplices have a repeated vertex (the encoder drops them)");
}

}  // namespace kdmesh::io::detail
