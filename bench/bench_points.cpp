// Point-cloud benchmark: kdmesh's kd-tree coder against Draco's point-cloud
// coder (kd-tree method, the one `draco_encoder -point_cloud` uses), both run
// in this process on the same vertices at the same quantization.
//
//   kdmesh_bench_points [--runs N] [--bits B]... MODEL...
//
// Prints one Markdown table row per model and quantization: size in bits per
// vertex, warm median encode/decode times, throughput and kdmesh/Draco ratios.
#include <cstdio>
#include <string>
#include <vector>

#include "bench_common.h"
#include "bench_draco.h"
#include "draco/point_cloud/point_cloud_builder.h"

namespace {

using bench::fail;
using bench::medianSeconds;

using bench::Measurement;

Measurement measureKdmesh(const kdmesh::Complex& cloud, int bits, int runs) {
  kdmesh::EncodeOptions options;
  options.bits = bits;
  kdmesh::EncodeResult encoded;
  Measurement m;
  m.encodeSeconds = medianSeconds(runs, [&] { encoded = kdmesh::encode(cloud, options); });
  if (!encoded.status.ok()) fail("kdmesh encode: " + encoded.status.message);
  m.bytes = encoded.bytes.size();
  kdmesh::Complex decoded;
  m.decodeSeconds = medianSeconds(runs, [&] {
    const kdmesh::Status status =
        kdmesh::decode(encoded.bytes.data(), encoded.bytes.size(), decoded);
    if (!status.ok()) fail("kdmesh decode: " + status.message);
  });
  if (decoded.vertexCount() != cloud.vertexCount()) fail("kdmesh decoded a different vertex count");
  return m;
}

std::unique_ptr<draco::PointCloud> dracoCloud(const std::vector<float>& positions) {
  const size_t count = positions.size() / 3;
  draco::PointCloudBuilder builder;
  builder.Start(static_cast<draco::PointIndex::ValueType>(count));
  const int attribute =
      builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  builder.SetAttributeValuesForAllPoints(attribute, positions.data(), 3 * sizeof(float));
  return builder.Finalize(/*deduplicate_points=*/false);
}

Measurement measureDraco(const std::vector<float>& positions, int bits, int level, int runs) {
  size_t decodedPoints = 0;
  const Measurement m = bench::measureDraco(*dracoCloud(positions), bits, level, runs, decodedPoints);
  if (decodedPoints != positions.size() / 3) fail("draco decoded a different point count");
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  const bench::Arguments args =
      bench::parseArguments(argc, argv, "usage: kdmesh_bench_points [--runs N] [--bits B]... MODEL...");
  const int runs = args.runs;
  std::printf("| model | vertices | bits | kdmesh bpv | Draco -cl 10 bpv | size ratio | "
              "kdmesh encode Mpts/s | kdmesh decode Mpts/s | Draco encode Mpts/s | "
              "Draco decode Mpts/s | encode time ratio | decode time ratio |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const std::string& path : args.models) {
    kdmesh::Complex complex = bench::readModel(path);
    kdmesh::Complex cloud;  // vertices only: this is the point-cloud benchmark
    cloud.positions = std::move(complex.positions);
    const double n = static_cast<double>(cloud.vertexCount());
    for (int bits : args.bits) {
      const Measurement ours = measureKdmesh(cloud, bits, runs);
      const Measurement draco = measureDraco(cloud.positions, bits, 10, runs);
      std::printf("| %s | %zu | %d | %.3f | %.3f | %.3f | %.2f | %.2f | %.2f | %.2f | %.2f | "
                  "%.2f |\n",
                  bench::baseName(path).c_str(), cloud.vertexCount(), bits, 8.0 * ours.bytes / n,
                  8.0 * draco.bytes / n, double(ours.bytes) / double(draco.bytes),
                  n / ours.encodeSeconds / 1e6, n / ours.decodeSeconds / 1e6,
                  n / draco.encodeSeconds / 1e6, n / draco.decodeSeconds / 1e6,
                  ours.encodeSeconds / draco.encodeSeconds,
                  ours.decodeSeconds / draco.decodeSeconds);
      std::fflush(stdout);
    }
  }
  return 0;
}
