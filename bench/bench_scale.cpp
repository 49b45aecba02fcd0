// How cost grows with size: the dragon replicated COPIES times side by side
// (one complex, COPIES × 871,414 triangles), encoded and decoded in process.
// Prints one Markdown row: triangles, stream bytes, encode and decode seconds
// (one run each: these are large) and the process's peak resident memory.
//
//   kdmesh_bench_scale COPIES MODEL
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "bench_common.h"

int main(int argc, char** argv) {
  if (argc != 3) bench::fail("usage: kdmesh_bench_scale COPIES MODEL");
  const int copies = std::max(1, std::atoi(argv[1]));
  kdmesh::Complex one = bench::readModel(argv[2]);
  one.points.clear();
  float lo = INFINITY, hi = -INFINITY;
  for (size_t i = 0; i < one.positions.size(); i += 3) {
    lo = std::min(lo, one.positions[i]);
    hi = std::max(hi, one.positions[i]);
  }
  kdmesh::Complex scene;
  const uint32_t n = uint32_t(one.vertexCount());
  for (int c = 0; c < copies; ++c) {
    const float shift = float(c) * (hi - lo) * 1.1f;
    for (size_t i = 0; i < one.positions.size(); ++i)
      scene.positions.push_back(one.positions[i] + (i % 3 == 0 ? shift : 0.f));
    for (const uint32_t v : one.triangles) scene.triangles.push_back(v + uint32_t(c) * n);
  }
  one = {};
  kdmesh::EncodeOptions options;
  options.bits = 16;  // the copies share the grid: 16 bits keep each dragon at ~12-bit detail
  auto start = std::chrono::steady_clock::now();
  const kdmesh::EncodeResult encoded = kdmesh::encode(scene, options);
  const double encodeSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!encoded.status.ok()) bench::fail(encoded.status.message);
  const size_t triangles = scene.simplexCount(2);
  scene = {};
  kdmesh::Complex decoded;
  start = std::chrono::steady_clock::now();
  if (!kdmesh::decode(encoded.bytes.data(), encoded.bytes.size(), decoded).ok()) bench::fail("decode failed");
  const double decodeSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (decoded.simplexCount(2) != triangles) bench::fail("decoded a different triangle count");
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  std::printf("| %d | %zu | %zu | %.2f | %.2f | %.2f | %.2f | %.0f |\n", copies, triangles, encoded.bytes.size(),
              encodeSeconds, decodeSeconds, double(triangles) / encodeSeconds / 1e6,
              double(triangles) / decodeSeconds / 1e6, double(usage.ru_maxrss) * 1024.0 / double(triangles));
  return 0;
}
