// Rate–distortion of progressive decoding: for each prefix of a stream that
// ends with a chunk (where the decoded model changes), how far
// each vertex of the complete model is from the vertex that stands for it at
// that prefix (its ancestor, through the decoder's stable vertex ids), and
// the symmetric Hausdorff distance between the prefix's and the complete
// model's surfaces, sampled as Metro does: the largest distance from the
// vertices and 50,000 area-weighted points of each surface to the other
// surface (its triangles and vertices), which can miss the farthest point
// by less than the sample spacing; all relative to the bounding-box
// diagonal.
//
//   kdmesh_bench_rd [--bits B] [--placement predicted|centre] [--chunk-bytes N] MODEL
//
// --placement: where prefixes put vertices whose cells are not yet single
// grid points (kdmesh::CoarsePlacement; predicted, the default, or centre).
// --chunk-bytes: the encoder's largest chunk payload (EncodeOptions::chunkBytes):
// smaller chunks give a finer curve.
//
// Prints CSV: bytes,vertices,mean_error,max_error,hausdorff (hausdorff is
// empty for models without triangles).
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <unordered_map>
#include <vector>

#include <algorithm>
#include <array>

#include "bench_common.h"

namespace {

using Point = std::array<double, 3>;

// The vertices plus `count` points on the triangles, area-weighted.
std::vector<Point> surfaceSamples(const kdmesh::Complex& c, size_t count, uint32_t seed) {
  std::vector<Point> out;
  for (size_t v = 0; v < c.vertexCount(); ++v)
    out.push_back({c.positions[3 * v], c.positions[3 * v + 1], c.positions[3 * v + 2]});
  const size_t triangles = c.triangles.size() / 3;
  std::vector<double> cumulative(triangles);
  double total = 0;
  auto corner = [&](size_t t, int k) {
    const size_t v = c.triangles[3 * t + size_t(k)];
    return Point{c.positions[3 * v], c.positions[3 * v + 1], c.positions[3 * v + 2]};
  };
  for (size_t t = 0; t < triangles; ++t) {
    const Point a = corner(t, 0), b = corner(t, 1), d = corner(t, 2);
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
    const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    total += 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    cumulative[t] = total;
  }
  if (triangles == 0 || total <= 0) return out;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0, 1);
  for (size_t i = 0; i < count; ++i) {
    const size_t t = size_t(std::lower_bound(cumulative.begin(), cumulative.end(), uniform(rng) * total) - cumulative.begin());
    double r1 = uniform(rng), r2 = uniform(rng);
    if (r1 + r2 > 1) r1 = 1 - r1, r2 = 1 - r2;
    const Point a = corner(std::min(t, triangles - 1), 0), b = corner(std::min(t, triangles - 1), 1),
                d = corner(std::min(t, triangles - 1), 2);
    out.push_back({a[0] + r1 * (b[0] - a[0]) + r2 * (d[0] - a[0]), a[1] + r1 * (b[1] - a[1]) + r2 * (d[1] - a[1]),
                   a[2] + r1 * (b[2] - a[2]) + r2 * (d[2] - a[2])});
  }
  return out;
}

// The closest point to p on triangle abc (Ericson, Real-Time Collision
// Detection, 5.1.5), and its distance.
double triangleDistance(const Point& p, const Point& a, const Point& b, const Point& c) {
  auto sub = [](const Point& x, const Point& y) { return Point{x[0] - y[0], x[1] - y[1], x[2] - y[2]}; };
  auto dot = [](const Point& x, const Point& y) { return x[0] * y[0] + x[1] * y[1] + x[2] * y[2]; };
  auto at = [&](const Point& origin, const Point& u, double s, const Point& w, double t) {
    const Point q{origin[0] + s * u[0] + t * w[0], origin[1] + s * u[1] + t * w[1], origin[2] + s * u[2] + t * w[2]};
    const Point d = sub(p, q);
    return std::sqrt(dot(d, d));
  };
  const Point ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return at(a, ab, 0, ac, 0);
  const Point bp = sub(p, b);
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return at(a, ab, 1, ac, 0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return at(a, ab, d1 / (d1 - d3), ac, 0);
  const Point cp = sub(p, c);
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return at(a, ab, 0, ac, 1);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return at(a, ab, 0, ac, d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return at(b, sub(c, b), w, ab, 0);
  }
  const double denominator = 1 / (va + vb + vc);
  return at(a, ab, vb * denominator, ac, vc * denominator);
}

// Distances to a model's surface: its triangles and its vertices (a vertex
// in no triangle is a point of the model), through a hash grid of cells
// about a triangle's size, searched in growing rings.
class NearestSurface {
 public:
  NearestSurface(const kdmesh::Complex& c, double diagonal) : c_(c) {
    const size_t triangles = c.triangles.size() / 3;
    if (triangles + c.vertexCount() < kFew) return;  // searched without the grid
    // Cells of twice the mean edge, or of the vertices' spacing without
    // triangles.
    double edges = 0;
    for (size_t t = 0; t < triangles; ++t) edges += length(corner(t, 0), corner(t, 1));
    const double size = triangles ? 2 * edges / double(triangles) : diagonal / std::cbrt(double(c.vertexCount()));
    cell_ = std::clamp(size, diagonal / 512, diagonal / 4);
    for (size_t t = 0; t < triangles; ++t) {
      std::array<int64_t, 3> lo = cellOf(corner(t, 0)), hi = lo;
      for (int k = 1; k < 3; ++k) {
        const std::array<int64_t, 3> q = cellOf(corner(t, k));
        for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], q[a]), hi[a] = std::max(hi[a], q[a]);
      }
      for (int64_t x = lo[0]; x <= hi[0]; ++x)
        for (int64_t y = lo[1]; y <= hi[1]; ++y)
          for (int64_t z = lo[2]; z <= hi[2]; ++z) grid_[key({x, y, z})].triangles.push_back(uint32_t(t));
    }
    for (size_t v = 0; v < c.vertexCount(); ++v) grid_[key(cellOf(vertex(v)))].vertices.push_back(uint32_t(v));
  }

  double distance(const Point& p) const {
    double best = INFINITY;
    if (c_.triangles.size() / 3 + c_.vertexCount() < kFew) {
      for (size_t t = 0; t < c_.triangles.size() / 3; ++t)
        best = std::min(best, triangleDistance(p, corner(t, 0), corner(t, 1), corner(t, 2)));
      for (size_t v = 0; v < c_.vertexCount(); ++v) best = std::min(best, length(p, vertex(v)));
      return best;
    }
    const std::array<int64_t, 3> c = cellOf(p);
    for (int64_t ring = 0; ring < 4096; ++ring) {
      for (int64_t dx = -ring; dx <= ring; ++dx)
        for (int64_t dy = -ring; dy <= ring; ++dy)
          for (int64_t dz = -ring; dz <= ring; ++dz) {
            if (std::max({std::llabs(dx), std::llabs(dy), std::llabs(dz)}) != ring) continue;
            const auto found = grid_.find(key({c[0] + dx, c[1] + dy, c[2] + dz}));
            if (found == grid_.end()) continue;
            for (const uint32_t t : found->second.triangles)
              best = std::min(best, triangleDistance(p, corner(t, 0), corner(t, 1), corner(t, 2)));
            for (const uint32_t v : found->second.vertices) best = std::min(best, length(p, vertex(v)));
          }
      // What lies beyond this ring is at least ring * cell away.
      if (best <= double(ring) * cell_) break;
    }
    return best;
  }

 private:
  static constexpr size_t kFew = 64;  // triangles and vertices searched one by one
  struct Cell {
    std::vector<uint32_t> triangles, vertices;
  };
  Point vertex(size_t v) const {
    return {c_.positions[3 * v], c_.positions[3 * v + 1], c_.positions[3 * v + 2]};
  }
  Point corner(size_t t, int k) const { return vertex(c_.triangles[3 * t + size_t(k)]); }
  static double length(const Point& a, const Point& b) {
    return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
  }
  std::array<int64_t, 3> cellOf(const Point& p) const {
    return {int64_t(std::floor(p[0] / cell_)), int64_t(std::floor(p[1] / cell_)), int64_t(std::floor(p[2] / cell_))};
  }
  static uint64_t key(const std::array<int64_t, 3>& c) {
    return uint64_t(c[0] * 73856093) ^ uint64_t(c[1] * 19349663) ^ uint64_t(c[2] * 83492791);
  }
  const kdmesh::Complex& c_;
  double cell_;
  std::unordered_map<uint64_t, Cell> grid_;
};

// The largest distance from the samples to the surface.
double directedHausdorff(const std::vector<Point>& from, const NearestSurface& to) {
  double worst = 0;
  for (const Point& p : from) worst = std::max(worst, to.distance(p));
  return worst;
}

}  // namespace

int main(int argc, char** argv) {
  int bits = 12;
  size_t chunkBytes = kdmesh::EncodeOptions{}.chunkBytes;
  kdmesh::DecoderOptions decoding;
  std::string path;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--bits" && i + 1 < argc) bits = std::atoi(argv[++i]);
    else if (arg == "--chunk-bytes" && i + 1 < argc) chunkBytes = size_t(std::max(64, std::atoi(argv[++i])));
    else if (arg == "--placement" && i + 1 < argc) {
      const std::string placement = argv[++i];
      if (placement != "predicted" && placement != "centre") bench::fail("--placement takes predicted or centre");
      decoding.coarsePlacement =
          placement == "centre" ? kdmesh::CoarsePlacement::CellCentre : kdmesh::CoarsePlacement::Predicted;
    }
    else if (arg == "--help" || arg == "-h") {
      std::printf("usage: kdmesh_bench_rd [--bits B] [--placement predicted|centre] [--chunk-bytes N] MODEL\n");
      return 0;
    } else path = arg;
  }
  if (path.empty()) bench::fail("no model given (try --help)");
  const kdmesh::Complex model = bench::readModel(path);
  kdmesh::EncodeOptions options;
  options.bits = bits;
  options.chunkBytes = chunkBytes;
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

  const bool surfaces = !final.triangles.empty();
  const size_t kSamples = 50000;
  const std::vector<Point> finalSamples = surfaces ? surfaceSamples(final, kSamples, 1) : std::vector<Point>{};
  const NearestSurface nearFinal(final, diagonal);

  std::printf("bytes,vertices,mean_error,max_error,hausdorff\n");
  kdmesh::Decoder decoder(decoding);
  size_t cut = 0;
  for (const kdmesh::ChunkInfo& chunk : full.chunks()) {
    const size_t end = size_t(chunk.offset) + chunk.payloadBytes + chunk.frameBytes;
    if (!decoder.push(bytes.data() + cut, end - cut).ok()) bench::fail("prefix does not decode");
    cut = end;
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
    std::string hausdorff;
    if (surfaces) {
      const std::vector<Point> prefixSamples = surfaceSamples(prefix, kSamples, 2);
      const NearestSurface nearPrefix(prefix, diagonal);
      const double h = std::max(directedHausdorff(prefixSamples, nearFinal), directedHausdorff(finalSamples, nearPrefix));
      char text[32];
      std::snprintf(text, sizeof text, "%.6g", h / diagonal);
      hausdorff = text;
    }
    std::printf("%zu,%u,%.6g,%.6g,%s\n", cut, count, sum / double(n) / diagonal, worst / diagonal, hausdorff.c_str());
  }
  return 0;
}
