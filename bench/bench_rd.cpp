// Rate–distortion of progressive decoding: for prefixes of a stream, how far
// each vertex of the complete model is from the vertex that stands for it at
// that prefix (its ancestor, through the decoder's stable vertex ids),
// relative to the bounding-box diagonal.
//
//   kdmesh_bench_rd [--bits B] [--points N] MODEL
//
// Prints CSV: bytes,vertices,mean_error,max_error (errors / diagonal).
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "bench_common.h"

int main(int argc, char** argv) {
  int bits = 12, samples = 40;
  std::string path;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--bits" && i + 1 < argc) bits = std::atoi(argv[++i]);
    else if (arg == "--points" && i + 1 < argc) samples = std::max(2, std::atoi(argv[++i]));
    else if (arg == "--help" || arg == "-h") {
      std::printf("usage: kdmesh_bench_rd [--bits B] [--points N] MODEL\n");
      return 0;
    } else path = arg;
  }
  if (path.empty()) bench::fail("no model given (try --help)");
  const kdmesh::Complex model = bench::readModel(path);
  kdmesh::EncodeOptions options;
  options.bits = bits;
  const kdmesh::EncodeResult encoded = kdmesh::encode(model, options);
  if (!encoded.status.ok()) bench::fail(encoded.status.message);
  const std::vector<uint8_t>& bytes = encoded.bytes;

  kdmesh::Decoder full;
  if (!full.push(bytes.data(), bytes.size()).ok() || !full.complete()) bench::fail("cannot decode");
  const kdmesh::Complex final = full.snapshot();
  const std::vector<uint32_t>& parents = full.vertexParents();
  const size_t n = final.vertexCount();
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < 3 * n; ++i) {
    lo[i % 3] = std::min(lo[i % 3], double(final.positions[i]));
    hi[i % 3] = std::max(hi[i % 3], double(final.positions[i]));
  }
  const double diagonal = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                    (hi[2] - lo[2]) * (hi[2] - lo[2]));

  std::printf("bytes,vertices,mean_error,max_error\n");
  const double first = double(kdmesh::kHeaderBytes + kdmesh::kChunkFrameBytes + 16), last = double(bytes.size());
  for (int s = 0; s < samples; ++s) {
    const size_t cut = size_t(std::llround(first * std::pow(last / first, double(s) / (samples - 1))));
    kdmesh::Decoder decoder;
    if (!decoder.push(bytes.data(), cut).ok()) bench::fail("prefix does not decode");
    const kdmesh::Complex prefix = decoder.snapshot();
    const uint32_t count = uint32_t(prefix.vertexCount());
    if (count == 0) continue;
    double sum = 0, worst = 0;
    for (uint32_t v = 0; v < n; ++v) {
      uint32_t a = v;
      while (a >= count) a = parents[a];
      double d2 = 0;
      for (int k = 0; k < 3; ++k) {
        const double d = double(final.positions[3 * size_t(v) + size_t(k)]) - double(prefix.positions[3 * size_t(a) + size_t(k)]);
        d2 += d * d;
      }
      const double d = std::sqrt(d2);
      sum += d;
      worst = std::max(worst, d);
    }
    std::printf("%zu,%u,%.6g,%.6g\n", cut, count, sum / double(n) / diagonal, worst / diagonal);
  }
  return 0;
}
