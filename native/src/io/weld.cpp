// ReadOptions::weld: vertices with bit-identical positions become one vertex.
#include <cstring>
#include <random>
#include <string>
#include <unordered_map>

#include "io/io_internal.h"

namespace kdmesh::io::detail {
namespace {

// Spreads one random seed over the hash's four multipliers.
uint64_t splitMix64(uint64_t& state) {
  uint64_t z = (state += 0x9e3779b97f4a7c15u);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
  return z ^ (z >> 31);
}

bool hasRepeatedVertex(const uint32_t* simplex, size_t arity) {
  for (size_t i = 0; i < arity; ++i) {
    for (size_t j = i + 1; j < arity; ++j) {
      if (simplex[i] == simplex[j]) return true;
    }
  }
  return false;
}

// Renumbers `indices` and drops the simplices left with a repeated vertex;
// returns how many it dropped.
size_t remap(std::vector<uint32_t>& indices, size_t arity,
             const std::vector<uint32_t>& newIndex) {
  for (uint32_t& index : indices) index = newIndex[index];
  return arity < 2 ? 0 : dropRepeated(indices, arity);
}

}  // namespace

// ---------------------------------------------------------------------------
// Welder
// ---------------------------------------------------------------------------

Welder::Welder(std::vector<float>& positions) : positions_(positions) {
  std::random_device device;
  uint64_t seed = uint64_t{device()} << 32 | device();
  for (uint64_t& multiplier : multipliers_) multiplier = splitMix64(seed);
  grow();
}

size_t Welder::slotOf(const uint32_t* bits) const {
  const uint64_t sum = multipliers_[0] + multipliers_[1] * bits[0] +
                       multipliers_[2] * bits[1] + multipliers_[3] * bits[2];
  return static_cast<size_t>(sum >> shift_);
}

// Doubles the table (at most half full, so that probes stay short) and
// enters every vertex again.
void Welder::grow() {
  constexpr int kFirstBits = 10;
  const int bits = slots_.empty() ? kFirstBits : 64 - shift_ + 1;
  shift_ = 64 - bits;
  slots_.assign(size_t{1} << bits, kEmpty);
  const size_t mask = slots_.size() - 1;
  const size_t count = positions_.size() / 3;
  for (size_t v = 0; v < count; ++v) {
    uint32_t bits[3];
    std::memcpy(bits, &positions_[3 * v], sizeof bits);
    size_t slot = slotOf(bits);
    while (slots_[slot] != kEmpty) slot = (slot + 1) & mask;
    slots_[slot] = static_cast<uint32_t>(v);
  }
}

uint32_t Welder::vertexAt(const float* xyz) {
  const size_t count = positions_.size() / 3;
  if (2 * (count + 1) > slots_.size()) grow();
  uint32_t bits[3];
  std::memcpy(bits, xyz, sizeof bits);
  const size_t mask = slots_.size() - 1;
  for (size_t slot = slotOf(bits);; slot = (slot + 1) & mask) {
    const uint32_t v = slots_[slot];
    if (v == kEmpty) {
      slots_[slot] = static_cast<uint32_t>(count);
      positions_.insert(positions_.end(), xyz, xyz + 3);
      return static_cast<uint32_t>(count);
    }
    if (std::memcmp(&positions_[3 * size_t{v}], bits, sizeof bits) == 0) {
      return v;
    }
  }
}

// ---------------------------------------------------------------------------
// Simplices and notes
// ---------------------------------------------------------------------------

namespace {

// Replaces `positions` by the welded vertices; returns the new index of
// every old vertex.
std::vector<uint32_t> weldPositions(std::vector<float>& positions) {
  std::vector<float> welded;
  Welder welder(welded);
  std::vector<uint32_t> newIndex(positions.size() / 3);
  for (size_t v = 0; v < newIndex.size(); ++v) {
    newIndex[v] = welder.vertexAt(&positions[3 * v]);
  }
  positions.swap(welded);
  return newIndex;
}

}  // namespace

size_t dropRepeated(std::vector<uint32_t>& indices, size_t arity,
                    size_t first) {
  size_t kept = first;
  for (size_t i = first; i + arity <= indices.size(); i += arity) {
    if (hasRepeatedVertex(&indices[i], arity)) continue;
    std::memmove(&indices[kept], &indices[i], arity * sizeof(uint32_t));
    kept += arity;
  }
  const size_t dropped = (indices.size() - kept) / arity;
  indices.resize(kept);
  return dropped;
}

void addWeldNotes(Notes& notes, size_t before, size_t after, size_t dropped) {
  if (after < before) {
    notes.push_back("welded " + counted(before - after, "vertex", "vertices") +
                    " with bit-identical positions into others (" +
                    std::to_string(before) + " -> " + counted(after, "vertex", "vertices") + ")");
  }
  addCountNote(notes, "dropped ", dropped, "simplex", "simplices",
               " that welding left with a repeated vertex");
}

namespace {

// With vertex attributes or float64 positions: vertices become one only if
// their positions (doubles, when there are) and every attribute's values
// are bit-identical (a seam's vertices stay apart). Replaces the positions
// and values by the welded vertices'.
std::vector<uint32_t> weldVerticesAndValues(Complex& complex) {
  const size_t n = complex.vertexCount();
  // The hash is seeded at random, so that no input can make it collide on purpose.
  std::random_device device;
  uint64_t seed = uint64_t{device()} << 32 | device();
  const uint64_t multiplier = splitMix64(seed) | 1;
  struct Hash {
    uint64_t multiplier;
    size_t operator()(const std::string& key) const {
      uint64_t h = multiplier;
      for (const char c : key) h = (h ^ uint8_t(c)) * multiplier;
      return size_t(h ^ (h >> 29));
    }
  };
  std::unordered_map<std::string, uint32_t, Hash> seen(16, Hash{multiplier});
  std::vector<uint32_t> newIndex(n);
  std::vector<uint32_t> kept;
  std::string key;
  for (size_t v = 0; v < n; ++v) {
    key.assign(reinterpret_cast<const char*>(&complex.positions[3 * v]), 12);
    if (!complex.positions64.empty()) key.append(reinterpret_cast<const char*>(&complex.positions64[3 * v]), 24);
    for (const VertexAttribute& a : complex.attributes)
      key.append(reinterpret_cast<const char*>(&a.values[v * a.valueBytes()]), a.valueBytes());
    const auto [at, inserted] = seen.emplace(key, uint32_t(kept.size()));
    if (inserted) kept.push_back(uint32_t(v));
    newIndex[v] = at->second;
  }
  std::vector<float> positions;
  positions.reserve(kept.size() * 3);
  for (const uint32_t v : kept) positions.insert(positions.end(), &complex.positions[3 * v], &complex.positions[3 * v] + 3);
  complex.positions.swap(positions);
  if (!complex.positions64.empty()) {
    std::vector<double> doubles;
    doubles.reserve(kept.size() * 3);
    for (const uint32_t v : kept)
      doubles.insert(doubles.end(), &complex.positions64[3 * v], &complex.positions64[3 * v] + 3);
    complex.positions64.swap(doubles);
  }
  for (VertexAttribute& a : complex.attributes) {
    std::vector<uint8_t> values;
    values.reserve(kept.size() * a.valueBytes());
    for (const uint32_t v : kept)
      values.insert(values.end(), &a.values[v * a.valueBytes()], &a.values[v * a.valueBytes()] + a.valueBytes());
    a.values.swap(values);
  }
  return newIndex;
}

}  // namespace

void weldVertices(Complex& complex, Notes& notes) {
  const size_t n = complex.vertexCount();
  if (n < 2) return;
  const std::vector<uint32_t> newIndex =
      complex.attributes.empty() && complex.positions64.empty() ? weldPositions(complex.positions)
                                                                : weldVerticesAndValues(complex);
  if (complex.vertexCount() == n) return;
  remap(complex.points, 1, newIndex);
  const size_t dropped = remap(complex.edges, 2, newIndex) +
                         remap(complex.triangles, 3, newIndex) +
                         remap(complex.tetrahedra, 4, newIndex);
  addWeldNotes(notes, n, complex.vertexCount(), dropped);
}

}  // namespace kdmesh::io::detail
