// Simplicial complexes for the connectivity tests, generated in code.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <random>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "kdmesh/kdmesh.h"

namespace kdmesh::test {

// A (rows x columns) grid of quads on a surface given by `place`, split into
// triangles with consistent winding. `wrapU/V` close it into a cylinder or
// torus; `hole(i, j)` leaves quad (i, j) out.
template <class Place, class Hole>
Complex gridSurface(int rows, int columns, bool wrapU, bool wrapV, Place place, Hole hole) {
  Complex c;
  const int uCount = wrapU ? columns : columns + 1, vCount = wrapV ? rows : rows + 1;
  for (int j = 0; j < vCount; ++j)
    for (int i = 0; i < uCount; ++i) {
      const std::array<float, 3> p = place(float(i) / float(columns), float(j) / float(rows));
      c.positions.insert(c.positions.end(), p.begin(), p.end());
    }
  auto id = [&](int i, int j) { return uint32_t((j % vCount) * uCount + (i % uCount)); };
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < columns; ++i) {
      if (hole(i, j)) continue;
      const uint32_t a = id(i, j), b = id(i + 1, j), d = id(i, j + 1), e = id(i + 1, j + 1);
      c.triangles.insert(c.triangles.end(), {a, b, e, a, e, d});
    }
  return c;
}

inline Complex torusMesh(int rows, int columns) {
  return gridSurface(rows, columns, true, true, [](float u, float v) {
    const float a = 6.2831853f * u, b = 6.2831853f * v;
    return std::array<float, 3>{(3.f + std::cos(b)) * std::cos(a), (3.f + std::cos(b)) * std::sin(a),
                                std::sin(b)};
  }, [](int, int) { return false; });
}

// A UV sphere: poles are fans, so vertex degrees vary.
inline Complex sphereMesh(int rings, int segments) {
  Complex c;
  c.positions = {0.f, 0.f, 1.f};
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const float t = 3.14159265f * float(r) / float(rings), p = 6.2831853f * float(s) / float(segments);
      c.positions.insert(c.positions.end(), {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)});
    }
  c.positions.insert(c.positions.end(), {0.f, 0.f, -1.f});
  const uint32_t south = uint32_t(c.vertexCount() - 1);
  auto ring = [&](int r, int s) { return uint32_t(1 + (r - 1) * segments + (s % segments)); };
  for (int s = 0; s < segments; ++s) {
    c.triangles.insert(c.triangles.end(), {0, ring(1, s), ring(1, s + 1)});
    c.triangles.insert(c.triangles.end(), {south, ring(rings - 1, s + 1), ring(rings - 1, s)});
  }
  for (int r = 1; r + 1 < rings; ++r)
    for (int s = 0; s < segments; ++s)
      c.triangles.insert(c.triangles.end(), {ring(r, s), ring(r + 1, s), ring(r + 1, s + 1), ring(r, s),
                                             ring(r + 1, s + 1), ring(r, s + 1)});
  return c;
}

// An open, wavy sheet with square holes.
inline Complex gridWithHoles(int n) {
  return gridSurface(n, n, false, false, [](float u, float v) {
    return std::array<float, 3>{u, v, 0.1f * std::sin(7.f * u) * std::cos(5.f * v)};
  }, [](int i, int j) { return (i / 3 + j / 3) % 4 == 1 && i % 3 != 0; });
}

// Kuhn subdivision of an n^3 block of jittered cubes into 6 tetrahedra each:
// a conforming tetrahedral mesh.
inline Complex tetrahedralBlock(int n, uint32_t seed) {
  Complex c;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> jitter(-0.2f, 0.2f);
  const int m = n + 1;
  for (int k = 0; k < m; ++k)
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i)
        c.positions.insert(c.positions.end(), {float(i) + jitter(rng), float(j) + jitter(rng), float(k) + jitter(rng)});
  auto id = [m](int i, int j, int k) { return uint32_t((k * m + j) * m + i); };
  static const int kPermutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (const auto& perm : kPermutations) {
          int p[3] = {i, j, k};
          uint32_t t[4];
          t[0] = id(p[0], p[1], p[2]);
          for (int s = 0; s < 3; ++s) {
            ++p[perm[s]];
            t[s + 1] = id(p[0], p[1], p[2]);
          }
          // Odd permutations of the axes give negatively oriented paths.
          const bool odd = ((perm[0] > perm[1]) + (perm[0] > perm[2]) + (perm[1] > perm[2])) & 1;
          if (odd) std::swap(t[2], t[3]);
          c.tetrahedra.insert(c.tetrahedra.end(), t, t + 4);
        }
  return c;
}

// Random small complexes of every dimension, with shared and coincident
// vertices, non-manifold configurations and opposite orientations.
inline Complex randomComplex(uint32_t seed, int vertices, int simplices) {
  std::mt19937 rng(seed);
  Complex c;
  std::uniform_int_distribution<int> coordinate(0, 7);
  for (int i = 0; i < vertices; ++i)
    c.positions.insert(c.positions.end(), {float(coordinate(rng)), float(coordinate(rng)), float(coordinate(rng))});
  std::uniform_int_distribution<uint32_t> vertex(0, uint32_t(vertices - 1));
  for (int s = 0; s < simplices; ++s) {
    const int d = 1 + int(rng() % 3);
    std::vector<uint32_t>& list = d == 1 ? c.edges : d == 2 ? c.triangles : c.tetrahedra;
    for (int i = 0; i <= d; ++i) list.push_back(vertex(rng));
  }
  for (int i = 0; i < 3; ++i) c.points.push_back(vertex(rng));
  return c;
}

// Every simplex of a complex named by the float bits of its vertices' positions,
// with its orientation: the form in which two complexes are compared up to
// vertex order. Maximal simplices only, as a complex defines them.
struct OrientedSimplex {
  std::vector<std::array<uint32_t, 3>> vertices;  // ascending
  int parity;  // of the listed order relative to ascending; -1 when undefined
  bool operator<(const OrientedSimplex& o) const {
    return vertices != o.vertices ? vertices < o.vertices : parity < o.parity;
  }
  bool operator==(const OrientedSimplex& o) const { return vertices == o.vertices && parity == o.parity; }
};

inline std::array<uint32_t, 3> positionBits(const Complex& c, uint32_t v) {
  std::array<uint32_t, 3> bits;
  std::memcpy(bits.data(), &c.positions[3 * size_t(v)], 12);
  return bits;
}

// Two fans of `rim` triangles (or, with `solid`, of tetrahedra over a disc
// fanned from its centre) around two apexes a hair apart, sharing their
// rim: the apexes merge late, each with a star of about 2 · rim simplices,
// and the split that separates them copies every one.
inline Complex doubleFan(int rim, bool solid) {
  Complex c;
  c.positions = {0, 0, 1e-5f, 0, 0, -1e-5f, 0, 0, 0};
  for (int i = 0; i < rim; ++i) {
    const double angle = 2 * M_PI * i / rim;
    c.positions.insert(c.positions.end(), {float(std::cos(angle)), float(std::sin(angle)), 0.0f});
  }
  for (uint32_t i = 0; i < uint32_t(rim); ++i) {
    const uint32_t a = 3 + i, b = 3 + (i + 1) % uint32_t(rim);
    if (solid) c.tetrahedra.insert(c.tetrahedra.end(), {0, 2, a, b, 1, 2, b, a});
    else c.triangles.insert(c.triangles.end(), {0, a, b, 1, b, a});
  }
  return c;
}

// Drops degenerate, duplicate and non-maximal simplices like the encoder
// does, then names vertices by position. Edges have no orientation.
inline std::vector<OrientedSimplex> canonicalForm(const Complex& c) {
  std::set<std::vector<uint32_t>> present;  // vertex sets, any dimension
  std::vector<OrientedSimplex> out;
  const std::vector<uint32_t>* lists[4] = {&c.points, &c.edges, &c.triangles, &c.tetrahedra};
  std::vector<char> used(c.vertexCount(), 0);
  for (int d = 3; d >= 1; --d) {
    for (size_t i = 0; i < lists[d]->size(); i += size_t(d + 1)) {
      std::vector<uint32_t> v(lists[d]->begin() + std::ptrdiff_t(i), lists[d]->begin() + std::ptrdiff_t(i) + d + 1);
      std::vector<uint32_t> sorted = v;
      std::sort(sorted.begin(), sorted.end());
      if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) continue;
      if (!present.insert(sorted).second) continue;
      for (uint32_t x : v) used[x] = 1;
      // All faces become present, so listed faces are recognised as redundant.
      for (int mask = 1; mask < (1 << (d + 1)) - 1; ++mask) {
        std::vector<uint32_t> face;
        for (int b = 0; b <= d; ++b)
          if (mask >> b & 1) face.push_back(sorted[size_t(b)]);
        if (face.size() >= 2) present.insert(face);
      }
      OrientedSimplex s;
      std::vector<std::pair<std::array<uint32_t, 3>, int>> named;
      for (int k = 0; k <= d; ++k) named.push_back({positionBits(c, v[size_t(k)]), k});
      std::sort(named.begin(), named.end());
      int inversions = 0;
      for (size_t a = 0; a < named.size(); ++a)
        for (size_t b = a + 1; b < named.size(); ++b) inversions += named[a].second > named[b].second;
      bool coincident = false;
      for (size_t a = 0; a + 1 < named.size(); ++a) coincident |= named[a].first == named[a + 1].first;
      for (const auto& n : named) s.vertices.push_back(n.first);
      s.parity = d == 1 || coincident ? -1 : inversions & 1;
      out.push_back(s);
    }
  }
  for (uint32_t v = 0; v < c.vertexCount(); ++v)
    if (!used[v]) out.push_back({{positionBits(c, v)}, -1});
  std::sort(out.begin(), out.end());
  return out;
}

// The complex of a prefix must be the input complex with every vertex
// replaced by its ancestor at that prefix: same maximal simplices, and each
// oriented like an input simplex of its dimension that projects onto it.
inline void expectPrefixesAreProjections(const Complex& input, EncodeOptions o) {
  const EncodeResult encoded = encode(input, o);
  ASSERT_TRUE(encoded.status.ok()) << encoded.status.message;
  Decoder full;
  ASSERT_TRUE(full.push(encoded.bytes.data(), encoded.bytes.size()).ok());
  ASSERT_TRUE(full.complete());
  const Complex final = full.snapshot();
  const std::vector<uint32_t> parents = full.vertexParents();

  std::vector<uint64_t> cuts;
  for (const ChunkInfo& chunk : full.chunks()) cuts.push_back(chunk.offset);
  cuts.push_back(encoded.bytes.size());
  // One decoder fed chunk by chunk snapshots into one Complex, reused: it
  // must match a fresh decoder's snapshot of the same prefix.
  Decoder streaming;
  Complex reused;
  uint64_t streamed = 0;
  for (const uint64_t cut : cuts) {
    Decoder decoder;
    ASSERT_TRUE(decoder.push(encoded.bytes.data(), cut).ok());
    ASSERT_TRUE(streaming.push(encoded.bytes.data() + streamed, cut - streamed).ok());
    streamed = cut;
    if (!decoder.hasHeader()) continue;
    const Complex prefix = decoder.snapshot();
    streaming.snapshot(reused);
    EXPECT_EQ(reused.positions, prefix.positions) << "prefix of " << cut << " bytes";
    EXPECT_EQ(reused.points, prefix.points);
    EXPECT_EQ(reused.edges, prefix.edges);
    EXPECT_EQ(reused.triangles, prefix.triangles);
    EXPECT_EQ(reused.tetrahedra, prefix.tetrahedra);
    const uint32_t count = uint32_t(prefix.vertexCount());
    auto ancestor = [&](uint32_t v) {
      while (v >= count) v = parents[v];
      return v;
    };
    // Projected input: oriented simplices by ancestor ids.
    std::map<std::vector<uint32_t>, std::set<int>> projected;  // sorted ids -> parities seen
    const std::vector<uint32_t>* lists[4] = {&final.points, &final.edges, &final.triangles, &final.tetrahedra};
    for (int d = 0; d <= 3; ++d)
      for (size_t i = 0; i < lists[d]->size(); i += size_t(d + 1)) {
        std::vector<uint32_t> v;
        for (int k = 0; k <= d; ++k) v.push_back(ancestor((*lists[d])[i + size_t(k)]));
        std::vector<uint32_t> sorted = v;
        std::sort(sorted.begin(), sorted.end());
        const bool collapsed = std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end();
        sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
        int inversions = 0;
        for (size_t a = 0; a < v.size(); ++a)
          for (size_t b = a + 1; b < v.size(); ++b) inversions += v[a] > v[b];
        std::set<int>& parities = projected[sorted];
        if (!collapsed && d >= 2) parities.insert(inversions & 1);
      }
    // Maximal projected simplices.
    std::set<std::vector<uint32_t>> faces;
    for (const auto& [s, parities] : projected)
      for (int mask = 1; mask + 1 < (1 << s.size()); ++mask) {
        std::vector<uint32_t> f;
        for (size_t b = 0; b < s.size(); ++b)
          if (mask >> b & 1) f.push_back(s[b]);
        faces.insert(f);
      }
    std::set<std::vector<uint32_t>> expected, actual;
    for (const auto& [s, parities] : projected)
      if (!faces.count(s)) expected.insert(s);
    const std::vector<uint32_t>* got[4] = {&prefix.points, &prefix.edges, &prefix.triangles, &prefix.tetrahedra};
    for (int d = 0; d <= 3; ++d)
      for (size_t i = 0; i < got[d]->size(); i += size_t(d + 1)) {
        std::vector<uint32_t> v(got[d]->begin() + std::ptrdiff_t(i), got[d]->begin() + std::ptrdiff_t(i) + d + 1);
        std::vector<uint32_t> sorted = v;
        std::sort(sorted.begin(), sorted.end());
        ASSERT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end()) << "repeated vertex at " << cut;
        actual.insert(sorted);
        const std::set<int>& parities = projected[sorted];
        if (d >= 2 && !parities.empty()) {
          int inversions = 0;
          for (size_t a = 0; a < v.size(); ++a)
            for (size_t b = a + 1; b < v.size(); ++b) inversions += v[a] > v[b];
          EXPECT_TRUE(parities.count(inversions & 1)) << "orientation at byte " << cut << " of " << encoded.bytes.size() << " dim " << d << " simplex " << ::testing::PrintToString(v);
        }
      }
    ASSERT_EQ(actual, expected) << "prefix of " << cut << " bytes";
  }
}

}  // namespace kdmesh::test
