// Mesh benchmark: kdmesh (geometry + connectivity, progressive) against
// Draco's single-rate mesh coder (edgebreaker) at -cl 10 and -cl 7, both in
// this process on the same triangles at the same quantization.
//
//   kdmesh_bench_mesh [--runs N] [--bits B]... MODEL...
//
// Prints a Markdown table: bits per vertex (connectivity / geometry / total)
// for kdmesh, total for Draco, warm median encode/decode times, throughput
// in M triangles/s, kdmesh/Draco time ratios, the same for streams encoded
// for fast decoding (EncodeOptions::fastDecode), and kdmesh's operator
// counts.
#include <cstdio>
#include <string>
#include <vector>

#include "bench_common.h"
#include "bench_draco.h"
#include "crc32.h"
#include "draco/mesh/triangle_soup_mesh_builder.h"

namespace {

using bench::fail;
using bench::medianSeconds;

using bench::Measurement;

// The mesh as Draco's own OBJ/PLY loaders build it: a soup of corners whose
// equal positions are merged.
std::unique_ptr<draco::Mesh> dracoMesh(const kdmesh::Complex& complex) {
  const size_t triangles = complex.triangles.size() / 3;
  draco::TriangleSoupMeshBuilder builder;
  builder.Start(int(triangles));
  const int position = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  for (size_t t = 0; t < triangles; ++t) {
    const float* corner[3];
    for (int c = 0; c < 3; ++c) corner[c] = &complex.positions[3 * size_t(complex.triangles[3 * t + size_t(c)])];
    builder.SetAttributeValuesForFace(position, draco::FaceIndex(uint32_t(t)), corner[0], corner[1], corner[2]);
  }
  return builder.Finalize();
}

Measurement measureDraco(const draco::Mesh& mesh, int bits, int level, int runs, size_t triangles) {
  size_t faces = 0;
  const Measurement m = bench::measureDraco(mesh, bits, level, runs, faces);
  if (faces == 0) fail("draco decoded no triangles");
  if (faces != triangles)
    std::fprintf(stderr, "note: draco -cl %d kept %zu of %zu triangles (it drops degenerate ones)\n", level,
                 faces, triangles);
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  const bench::Arguments args =
      bench::parseArguments(argc, argv, "usage: kdmesh_bench_mesh [--runs N] [--bits B]... MODEL...");
  std::printf("| model | vertices | triangles | bits | kdmesh conn / geom / total bpv | Draco -cl 10 bpv | "
              "Draco -cl 7 bpv | size ratio vs -cl 10 | kdmesh encode Mtri/s | kdmesh decode Mtri/s | "
              "Draco -cl 10 encode Mtri/s | Draco -cl 10 decode Mtri/s | encode time ratio | "
              "decode time ratio |\n");
  std::printf("|---|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  std::string operators, fast;
  for (const std::string& path : args.models) {
    const kdmesh::Complex model = bench::readModel(path);
    const double n = double(model.vertexCount()), triangles = double(model.simplexCount(2));
    const std::unique_ptr<draco::Mesh> mesh = dracoMesh(model);
    for (const int bits : args.bits) {
      kdmesh::EncodeOptions options;
      options.bits = bits;
      // Encodes and decodes the model with `options`, warm medians.
      auto measureOurs = [&](const kdmesh::EncodeOptions& o, kdmesh::EncodeResult& encoded) {
        Measurement m;
        m.encodeSeconds = medianSeconds(args.runs, [&] { encoded = kdmesh::encode(model, o); });
        if (!encoded.status.ok()) fail("kdmesh encode: " + encoded.status.message);
        m.bytes = encoded.bytes.size();
        kdmesh::Complex decoded;
        m.decodeSeconds = medianSeconds(args.runs, [&] {
          const kdmesh::Status s = kdmesh::decode(encoded.bytes.data(), encoded.bytes.size(), decoded);
          if (!s.ok()) fail("kdmesh decode: " + s.message);
        });
        if (decoded.simplexCount(2) != model.simplexCount(2)) fail("kdmesh decoded a different triangle count");
        return m;
      };
      kdmesh::EncodeResult encoded, encodedFast;
      const Measurement ours = measureOurs(options, encoded);
      kdmesh::EncodeOptions fastOptions = options;
      fastOptions.fastDecode = true;
      const Measurement oursFast = measureOurs(fastOptions, encodedFast);
      // The decoder checks a CRC-32 over every chunk payload: its share of decoding.
      uint32_t sink = 0;
      const double crcSeconds = medianSeconds(args.runs, [&] { sink ^= kdmesh::crc32(encoded.bytes.data(), encoded.bytes.size()); });
      std::fprintf(stderr, "%s %d bits: CRC-32 of the whole stream %.3f ms = %.2f %% of decoding (%u)\n",
                   bench::baseName(path).c_str(), bits, 1e3 * crcSeconds, 100.0 * crcSeconds / ours.decodeSeconds, sink & 1);
      const Measurement draco10 = measureDraco(*mesh, bits, 10, args.runs, size_t(triangles));
      const Measurement draco7 = measureDraco(*mesh, bits, 7, args.runs, size_t(triangles));
      std::printf("| %s | %.0f | %.0f | %d | %.2f / %.2f / %.2f | %.2f | %.2f | %.3f | %.2f | %.2f | %.2f | "
                  "%.2f | %.2f | %.2f |\n",
                  bench::baseName(path).c_str(), n, triangles, bits, encoded.cost.connectivityBits / n,
                  encoded.cost.geometryBits / n, 8.0 * double(ours.bytes) / n, 8.0 * double(draco10.bytes) / n,
                  8.0 * double(draco7.bytes) / n, double(ours.bytes) / double(draco10.bytes),
                  triangles / ours.encodeSeconds / 1e6, triangles / ours.decodeSeconds / 1e6,
                  triangles / draco10.encodeSeconds / 1e6, triangles / draco10.decodeSeconds / 1e6,
                  ours.encodeSeconds / draco10.encodeSeconds, ours.decodeSeconds / draco10.decodeSeconds);
      std::fflush(stdout);
      char row[512];
      std::snprintf(row, sizeof row, "| %s | %d | %.2f / %.2f / %.2f | %.3f | %.3f | %.2f | %.2f | %.2f | %.2f | %.2f |\n",
                    bench::baseName(path).c_str(), bits, encodedFast.cost.connectivityBits / n,
                    encodedFast.cost.geometryBits / n, 8.0 * double(oursFast.bytes) / n,
                    double(oursFast.bytes) / double(ours.bytes), double(oursFast.bytes) / double(draco10.bytes),
                    triangles / oursFast.encodeSeconds / 1e6, triangles / oursFast.decodeSeconds / 1e6,
                    oursFast.encodeSeconds / draco10.encodeSeconds, oursFast.decodeSeconds / draco10.decodeSeconds,
                    ours.decodeSeconds / oursFast.decodeSeconds);
      fast += row;
      const kdmesh::ConnectivityStatistics& st = encoded.statistics;
      char line[512];
      std::snprintf(line, sizeof line,
                    "| %s | %d | %llu | %llu | %.1f %% | %llu / %llu / %llu / %llu | %llu / %llu / %llu / %llu | %.1f %% |\n",
                    bench::baseName(path).c_str(), bits, (unsigned long long)(n - 1),
                    (unsigned long long)st.edgeExpansions, 100.0 * double(st.edgeExpansions) / (n - 1),
                    (unsigned long long)st.codes[1][0], (unsigned long long)st.codes[1][1],
                    (unsigned long long)st.codes[1][2], (unsigned long long)st.codes[1][3],
                    (unsigned long long)st.codes[2][0], (unsigned long long)st.codes[2][1],
                    (unsigned long long)st.codes[2][2], (unsigned long long)st.codes[2][3],
                    st.orientationBits ? 100.0 * double(st.orientationMispredicted) / double(st.orientationBits) : 0.0);
      operators += line;
    }
  }
  std::printf("\nEncoded with --fast-decode (predictions along the split axis alone), against the default stream and "
              "Draco -cl 10 above:\n\n| model | bits | conn / geom / total bpv | size vs default | size vs Draco -cl 10 | "
              "encode Mtri/s | decode Mtri/s | encode time ratio vs Draco | decode time ratio vs Draco | decode "
              "speed-up vs default |\n");
  std::printf("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|\n%s", fast.c_str());
  std::printf("\n| model | bits | merges (n - 1) | of which edge expansions | share | edge codes 1/2/3/4 | "
              "triangle codes 1/2/3/4 | orientation mispredicted |\n");
  std::printf("|---|---:|---:|---:|---:|---|---|---:|\n%s", operators.c_str());
  return 0;
}
