// Vertex attribute benchmark: what texture-coordinate seams and normals
// cost in a kdmesh stream, and the normals against Draco's.
//
//   kdmesh_bench_attributes [--bits B]... MODEL...
//
// For each triangle mesh and position grid (default 12 bits) it prints, in
// bits per vertex of the model as read:
// - seams: the mesh with a cylindrical texture map around its vertical (y)
//   axis, whose seam (where u wraps from 1 to 0) splits the vertices of the
//   triangles across it in two; the mesh alone, the split mesh without the
//   map (what the extra vertices cost), and with it, exact and at 12 bits
//   per coordinate (--attr-bits 12);
// - normals: its area-weighted vertex normals, exact (float32) and at 8, 10
//   and 12 octahedral bits (--normal-bits), against Draco -cl 10 (positions
//   at the same bits) with normals at the same -qn, and its bytes with
//   minus without normals.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "bench_common.h"
#include "bench_draco.h"
#include "draco/mesh/triangle_soup_mesh_builder.h"

namespace {

using bench::fail;

kdmesh::VertexAttribute floatAttribute(const char* name, int components, const std::vector<float>& values) {
  kdmesh::VertexAttribute a{name, kdmesh::AttributeType::Float32, uint8_t(components), {}, {}};
  a.values.resize(values.size() * 4);
  std::memcpy(a.values.data(), values.data(), a.values.size());
  return a;
}

// Unit normals: the sum of the vertex's triangles' cross products (twice
// their areas), normalised; (0, 0, 1) for a vertex in no triangle.
std::vector<float> areaWeightedNormals(const kdmesh::Complex& c) {
  std::vector<double> sum(c.positions.size(), 0.0);
  for (size_t t = 0; t < c.triangles.size(); t += 3) {
    const float* p[3];
    for (int k = 0; k < 3; ++k) p[k] = &c.positions[3 * size_t(c.triangles[t + size_t(k)])];
    const double e[2][3] = {{p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]},
                            {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]}};
    const double n[3] = {e[0][1] * e[1][2] - e[0][2] * e[1][1], e[0][2] * e[1][0] - e[0][0] * e[1][2],
                         e[0][0] * e[1][1] - e[0][1] * e[1][0]};
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) sum[3 * size_t(c.triangles[t + size_t(k)]) + size_t(a)] += n[a];
  }
  std::vector<float> normals(sum.size());
  for (size_t v = 0; v < sum.size(); v += 3) {
    const double length = std::sqrt(sum[v] * sum[v] + sum[v + 1] * sum[v + 1] + sum[v + 2] * sum[v + 2]);
    for (size_t a = 0; a < 3; ++a) normals[v + a] = length > 0 ? float(sum[v + a] / length) : a == 2 ? 1.f : 0.f;
  }
  return normals;
}

// The mesh with a cylindrical map u = angle around the y axis through the
// bounding box centre / 2 pi + 1/2, v = height in the box; the vertices of
// a triangle that spans more than half a turn get, where u < 1/2, a copy
// with u + 1 (the seam). Returns the count of copies in `seamVertices`.
kdmesh::Complex withCylindricalMap(const kdmesh::Complex& c, size_t& seamVertices) {
  float low[3] = {INFINITY, INFINITY, INFINITY}, high[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < c.positions.size(); ++i) {
    low[i % 3] = std::min(low[i % 3], c.positions[i]);
    high[i % 3] = std::max(high[i % 3], c.positions[i]);
  }
  kdmesh::Complex out;
  out.positions = c.positions;
  out.triangles = c.triangles;
  std::vector<float> uv;
  for (size_t v = 0; v < c.vertexCount(); ++v) {
    const float* p = &c.positions[3 * v];
    const double angle = std::atan2(double(p[2]) - 0.5 * (low[2] + high[2]), double(p[0]) - 0.5 * (low[0] + high[0]));
    uv.push_back(float(angle / (2 * M_PI) + 0.5));
    uv.push_back(float((double(p[1]) - low[1]) / (double(high[1]) - low[1])));
  }
  std::vector<uint32_t> copyOf(c.vertexCount(), UINT32_MAX);
  for (size_t t = 0; t < out.triangles.size(); t += 3) {
    float least = 1, most = 0;
    for (int k = 0; k < 3; ++k) {
      least = std::min(least, uv[2 * size_t(out.triangles[t + size_t(k)])]);
      most = std::max(most, uv[2 * size_t(out.triangles[t + size_t(k)])]);
    }
    if (most - least <= 0.5f) continue;
    for (int k = 0; k < 3; ++k) {
      uint32_t& v = out.triangles[t + size_t(k)];
      if (uv[2 * size_t(v)] >= 0.5f) continue;
      if (copyOf[v] == UINT32_MAX) {
        copyOf[v] = uint32_t(out.vertexCount());
        out.positions.insert(out.positions.end(), &c.positions[3 * size_t(v)], &c.positions[3 * size_t(v)] + 3);
        uv.insert(uv.end(), {uv[2 * size_t(v)] + 1.f, uv[2 * size_t(v) + 1]});
      }
      v = copyOf[v];
    }
  }
  seamVertices = out.vertexCount() - c.vertexCount();
  out.attributes = {floatAttribute("uv", 2, uv)};
  return out;
}

kdmesh::EncodeResult encodeOrFail(const kdmesh::Complex& c, const kdmesh::EncodeOptions& options) {
  kdmesh::EncodeResult r = kdmesh::encode(c, options);
  if (!r.status.ok()) fail("kdmesh encode: " + r.status.message);
  return r;
}

// Draco -cl 10 of the mesh, positions at `bits`, with its normals at
// `normalBits` when given: the stream's bytes.
size_t dracoBytes(const kdmesh::Complex& c, const std::vector<float>* normals, int bits, int normalBits) {
  const size_t triangles = c.triangles.size() / 3;
  draco::TriangleSoupMeshBuilder builder;
  builder.Start(int(triangles));
  const int position = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  const int normal = normals ? builder.AddAttribute(draco::GeometryAttribute::NORMAL, 3, draco::DT_FLOAT32) : -1;
  for (size_t t = 0; t < triangles; ++t) {
    const float* corner[3];
    const float* corner3[3];
    for (int k = 0; k < 3; ++k) {
      const size_t v = size_t(c.triangles[3 * t + size_t(k)]);
      corner[k] = &c.positions[3 * v];
      if (normals) corner3[k] = &(*normals)[3 * v];
    }
    builder.SetAttributeValuesForFace(position, draco::FaceIndex(uint32_t(t)), corner[0], corner[1], corner[2]);
    if (normals)
      builder.SetAttributeValuesForFace(normal, draco::FaceIndex(uint32_t(t)), corner3[0], corner3[1], corner3[2]);
  }
  std::unique_ptr<draco::Mesh> mesh = builder.Finalize();
  draco::Encoder encoder;
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, bits);
  if (normals) encoder.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, normalBits);
  encoder.SetSpeedOptions(0, 0);
  draco::EncoderBuffer buffer;
  if (const draco::Status s = encoder.EncodeMeshToBuffer(*mesh, &buffer); !s.ok())
    fail("draco encode: " + s.error_msg_string());
  return buffer.size();
}

}  // namespace

int main(int argc, char** argv) {
  const bench::Arguments args =
      bench::parseArguments(argc, argv, "usage: kdmesh_bench_attributes [--bits B]... MODEL...");
  std::printf("| model | bits | seam vertices | mesh bpv | split mesh, no map | with the map (exact) | map's own bits | "
              "with the map (--attr-bits 12) | map's own bits |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  std::string normalRows;
  for (const std::string& path : args.models) {
    const kdmesh::Complex model = bench::readModel(path);
    if (model.triangles.empty()) fail(path + " has no triangles");
    const double n = double(model.vertexCount());
    size_t seamVertices = 0;
    const kdmesh::Complex mapped = withCylindricalMap(model, seamVertices);
    kdmesh::Complex split = mapped;
    split.attributes.clear();
    const std::vector<float> normals = areaWeightedNormals(model);
    for (const int bits : args.bits) {
      kdmesh::EncodeOptions options;
      options.bits = bits;
      const kdmesh::EncodeResult alone = encodeOrFail(model, options);
      const kdmesh::EncodeResult splitAlone = encodeOrFail(split, options);
      const kdmesh::EncodeResult withMap = encodeOrFail(mapped, options);
      kdmesh::EncodeOptions quantized = options;
      quantized.attributeBits = 12;
      const kdmesh::EncodeResult withMap12 = encodeOrFail(mapped, quantized);
      std::printf("| %s | %d | %zu | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f |\n", bench::baseName(path).c_str(),
                  bits, seamVertices, 8.0 * double(alone.bytes.size()) / n,
                  8.0 * double(splitAlone.bytes.size()) / n, 8.0 * double(withMap.bytes.size()) / n,
                  withMap.cost.attributeBits[0] / n, 8.0 * double(withMap12.bytes.size()) / n,
                  withMap12.cost.attributeBits[0] / n);
      std::fflush(stdout);

      kdmesh::Complex withNormals = model;
      withNormals.attributes = {floatAttribute("normal", 3, normals)};
      const kdmesh::EncodeResult exact = encodeOrFail(withNormals, options);
      const double dracoAlone = 8.0 * double(dracoBytes(model, nullptr, bits, 0)) / n;
      char line[256];
      std::snprintf(line, sizeof line, "| %s | %d | exact | %.3f | %.3f | | |\n", bench::baseName(path).c_str(), bits,
                    8.0 * double(exact.bytes.size()) / n, exact.cost.attributeBits[0] / n);
      normalRows += line;
      for (const int normalBits : {8, 10, 12}) {
        kdmesh::EncodeOptions octahedral = options;
        octahedral.normalBits = normalBits;
        const kdmesh::EncodeResult ours = encodeOrFail(withNormals, octahedral);
        const double draco = 8.0 * double(dracoBytes(model, &normals, bits, normalBits)) / n;
        std::snprintf(line, sizeof line, "| %s | %d | octahedral %d bits | %.3f | %.3f | %.3f | %.3f |\n",
                      bench::baseName(path).c_str(), bits, normalBits, 8.0 * double(ours.bytes.size()) / n,
                      ours.cost.attributeBits[0] / n, draco, draco - dracoAlone);
        normalRows += line;
      }
    }
  }
  std::printf("\n| model | bits | normals | kdmesh bpv | kdmesh normal bpv | Draco -cl 10 bpv | Draco normal bpv |\n");
  std::printf("|---|---:|---|---:|---:|---:|---:|\n%s", normalRows.c_str());
  return 0;
}
