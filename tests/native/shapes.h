// Point sets for the tests, generated from a seed so every run sees the same
// data. Each returns xyz floats, 3 per point.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace kdmesh::test {

inline std::vector<float> uniformCloud(size_t n, uint32_t seed, float scale = 1.0f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-scale, scale);
  std::vector<float> p(n * 3);
  for (float& v : p) v = u(rng);
  return p;
}

// Gaussian blobs of very different sizes: density varies by orders of magnitude.
inline std::vector<float> clusteredCloud(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-10.f, 10.f);
  std::vector<float> centres(8 * 3), sigmas(8);
  for (float& v : centres) v = u(rng);
  for (size_t i = 0; i < sigmas.size(); ++i) sigmas[i] = std::pow(10.f, -2.f + float(i) * 0.4f);
  std::vector<float> p(n * 3);
  std::normal_distribution<float> g(0.f, 1.f);
  for (size_t i = 0; i < n; ++i) {
    const size_t c = rng() % 8;
    for (size_t a = 0; a < 3; ++a) p[3 * i + a] = centres[3 * c + a] + sigmas[c] * g(rng);
  }
  return p;
}

inline std::vector<float> sphereSurface(size_t n, uint32_t seed, float radius = 2.f) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> g(0.f, 1.f);
  std::vector<float> p(n * 3);
  for (size_t i = 0; i < n; ++i) {
    float x = g(rng), y = g(rng), z = g(rng);
    const float r = std::sqrt(x * x + y * y + z * z) + 1e-20f;
    p[3 * i] = radius * x / r + 5.f;
    p[3 * i + 1] = radius * y / r - 3.f;
    p[3 * i + 2] = radius * z / r;
  }
  return p;
}

inline std::vector<float> torusSurface(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> angle(0.f, 6.2831853f);
  std::vector<float> p(n * 3);
  for (size_t i = 0; i < n; ++i) {
    const float u = angle(rng), v = angle(rng);
    p[3 * i] = (3.f + std::cos(v)) * std::cos(u);
    p[3 * i + 1] = (3.f + std::cos(v)) * std::sin(u);
    p[3 * i + 2] = 0.5f * std::sin(v);  // flat: z has fewer grid bits
  }
  return p;
}

// Few distinct positions, each repeated many times.
inline std::vector<float> coincidentCloud(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  const std::vector<float> distinct = uniformCloud(17, seed + 1);
  std::vector<float> p(n * 3);
  for (size_t i = 0; i < n; ++i) {
    const size_t k = rng() % 17;
    for (size_t a = 0; a < 3; ++a) p[3 * i + a] = distinct[3 * k + a];
  }
  return p;
}

}  // namespace kdmesh::test
