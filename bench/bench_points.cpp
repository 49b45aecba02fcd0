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
#include "draco/compression/decode.h"
#include "draco/compression/encode.h"
#include "draco/point_cloud/point_cloud_builder.h"

namespace {

using bench::fail;
using bench::medianSeconds;

struct Measurement {
  size_t bytes = 0;
  double encodeSeconds = 0;
  double decodeSeconds = 0;
};

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

// compressionLevel as draco_encoder's -cl: speed = 10 - level.
Measurement measureDraco(const std::vector<float>& positions, int bits, int compressionLevel,
                         int runs) {
  const std::unique_ptr<draco::PointCloud> cloud = dracoCloud(positions);
  draco::Encoder encoder;
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, bits);
  encoder.SetSpeedOptions(10 - compressionLevel, 10 - compressionLevel);
  draco::EncoderBuffer buffer;
  Measurement m;
  m.encodeSeconds = medianSeconds(runs, [&] {
    buffer.Clear();
    const draco::Status status = encoder.EncodePointCloudToBuffer(*cloud, &buffer);
    if (!status.ok()) fail("draco encode: " + status.error_msg_string());
  });
  m.bytes = buffer.size();
  size_t decodedPoints = 0;
  m.decodeSeconds = medianSeconds(runs, [&] {
    draco::DecoderBuffer input;
    input.Init(buffer.data(), buffer.size());
    draco::Decoder decoder;
    auto decoded = decoder.DecodePointCloudFromBuffer(&input);
    if (!decoded.ok()) fail("draco decode: " + decoded.status().error_msg_string());
    decodedPoints = decoded.value()->num_points();
  });
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
