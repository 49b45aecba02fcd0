// Vertex attribute benchmark: what vertex attributes cost in a kdmesh
// stream, against Draco's on the same values.
//
//   kdmesh_bench_attributes [--bits B]... MODEL...
//
// For each triangle mesh and position grid (default 12 bits) it prints, in
// bits per vertex of the model as read:
// - seams: the mesh with a cylindrical texture map around its vertical (y)
//   axis, whose seam (where u wraps from 1 to 0) splits the vertices of the
//   triangles across it in two; the mesh alone, the split mesh without the
//   map (what the extra vertices cost), and with it, exact and at 12 bits
//   per coordinate (--attr-bits 12); what the map and its seam add at 12
//   bits against Draco -cl 10 with the map at -qt 12;
// - normals: its area-weighted vertex normals, exact (float32) and at 8, 10
//   and 12 octahedral bits (--normal-bits), against Draco -cl 10 (positions
//   at the same bits) with normals at the same -qn;
// - colours: 8-bit RGB made to vary as a scan's do (scanColours()), exact,
//   on the mesh and on its vertices as a point cloud, against Draco -cl 10's
//   lossless 8-bit colours on the same mesh and cloud.
// What an attribute costs is, for both codecs, the stream with it minus the
// stream without it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "bench_common.h"
#include "bench_draco.h"
#include "draco/mesh/triangle_soup_mesh_builder.h"
#include "draco/point_cloud/point_cloud_builder.h"

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

// 8-bit RGB colours that vary as a scanned surface's do: an albedo of
// smooth bands across the bounding box, shaded by the vertex normal under a
// light from above, plus a pseudo-random speckle of −3 to +4 per channel.
std::vector<uint8_t> scanColours(const kdmesh::Complex& c, const std::vector<float>& normals) {
  float low[3] = {INFINITY, INFINITY, INFINITY}, high[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < c.positions.size(); ++i) {
    low[i % 3] = std::min(low[i % 3], c.positions[i]);
    high[i % 3] = std::max(high[i % 3], c.positions[i]);
  }
  std::vector<uint8_t> colours;
  uint32_t state = 12345;
  for (size_t v = 0; v < c.vertexCount(); ++v) {
    double t[3];
    for (size_t a = 0; a < 3; ++a)
      t[a] = (double(c.positions[3 * v + a]) - low[a]) / std::max(1e-30, double(high[a]) - double(low[a]));
    const double albedo[3] = {0.55 + 0.35 * std::sin(9 * t[0] + 2 * t[1]), 0.45 + 0.3 * std::sin(7 * t[1] + 1),
                              0.35 + 0.25 * std::sin(5 * t[2] + 3 * t[0])};
    const double shade = 0.35 + 0.65 * std::max(0.0, 0.3 * normals[3 * v] + 0.9 * normals[3 * v + 1] +
                                                         0.3 * normals[3 * v + 2]);
    for (size_t a = 0; a < 3; ++a) {
      state = state * 1664525u + 1013904223u;
      const int speckle = int(state >> 29) - 3;  // -3..4
      colours.push_back(uint8_t(std::clamp(int(std::lround(255 * albedo[a] * shade)) + speckle, 0, 255)));
    }
  }
  return colours;
}

// A per-vertex attribute for Draco: its type, components, values (per
// vertex of the complex) and quantization bits (0: none).
struct DracoAttribute {
  draco::GeometryAttribute::Type type;
  draco::DataType dataType;
  int components;
  const void* values;
  int bits;
};

size_t dracoEncode(const draco::PointCloud& geometry, bool mesh, int bits, const std::vector<DracoAttribute>& extra) {
  draco::Encoder encoder;
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, bits);
  for (const DracoAttribute& a : extra)
    if (a.bits > 0) encoder.SetAttributeQuantization(a.type, a.bits);
  encoder.SetSpeedOptions(0, 0);
  draco::EncoderBuffer buffer;
  const draco::Status s = mesh ? encoder.EncodeMeshToBuffer(static_cast<const draco::Mesh&>(geometry), &buffer)
                               : encoder.EncodePointCloudToBuffer(geometry, &buffer);
  if (!s.ok()) fail("draco encode: " + s.error_msg_string());
  return buffer.size();
}

// Draco -cl 10 of the mesh (or, with `cloud`, of its vertices), positions
// at `bits`, with the `extra` attributes: the stream's bytes.
size_t dracoBytes(const kdmesh::Complex& c, int bits, const std::vector<DracoAttribute>& extra, bool cloud = false) {
  auto bytesOf = [](const DracoAttribute& a) { return size_t(a.components) * draco::DataTypeLength(a.dataType); };
  if (cloud) {
    draco::PointCloudBuilder builder;
    builder.Start(uint32_t(c.vertexCount()));
    const int position = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
    builder.SetAttributeValuesForAllPoints(position, c.positions.data(), 3 * sizeof(float));
    for (const DracoAttribute& a : extra) {
      const int id = builder.AddAttribute(a.type, int8_t(a.components), a.dataType);
      builder.SetAttributeValuesForAllPoints(id, a.values, int(bytesOf(a)));
    }
    return dracoEncode(*builder.Finalize(/*deduplicate_points=*/false), false, bits, extra);
  }
  const size_t triangles = c.triangles.size() / 3;
  draco::TriangleSoupMeshBuilder builder;
  builder.Start(int(triangles));
  const int position = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  std::vector<int> ids;
  for (const DracoAttribute& a : extra) ids.push_back(builder.AddAttribute(a.type, int8_t(a.components), a.dataType));
  for (size_t t = 0; t < triangles; ++t) {
    size_t v[3];
    for (int k = 0; k < 3; ++k) v[k] = size_t(c.triangles[3 * t + size_t(k)]);
    const draco::FaceIndex face{uint32_t(t)};
    builder.SetAttributeValuesForFace(position, face, &c.positions[3 * v[0]], &c.positions[3 * v[1]],
                                      &c.positions[3 * v[2]]);
    for (size_t i = 0; i < extra.size(); ++i) {
      const auto* values = static_cast<const uint8_t*>(extra[i].values);
      const size_t size = bytesOf(extra[i]);
      builder.SetAttributeValuesForFace(ids[i], face, values + v[0] * size, values + v[1] * size, values + v[2] * size);
    }
  }
  return dracoEncode(*builder.Finalize(), true, bits, extra);
}

}  // namespace

int main(int argc, char** argv) {
  const bench::Arguments args =
      bench::parseArguments(argc, argv, "usage: kdmesh_bench_attributes [--bits B]... MODEL...");
  std::printf("| model | bits | seam vertices | mesh bpv | split mesh, no map | with the map (exact) | "
              "with the map (--attr-bits 12) | map and seam, kdmesh 12 bits | Draco -qt 12 | size ratio |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  std::string normalRows, colourRows;
  char line[320];
  for (const std::string& path : args.models) {
    const kdmesh::Complex model = bench::readModel(path);
    if (model.triangles.empty()) fail(path + " has no triangles");
    const std::string name = bench::baseName(path);
    const double n = double(model.vertexCount());
    size_t seamVertices = 0;
    const kdmesh::Complex mapped = withCylindricalMap(model, seamVertices);
    kdmesh::Complex split = mapped;
    split.attributes.clear();
    const std::vector<float> normals = areaWeightedNormals(model);
    const std::vector<uint8_t> colours = scanColours(model, normals);
    for (const int bits : args.bits) {
      kdmesh::EncodeOptions options;
      options.bits = bits;
      const double dracoAlone = 8.0 * double(dracoBytes(model, bits, {})) / n;

      const kdmesh::EncodeResult alone = encodeOrFail(model, options);
      const double kdmeshAlone = 8.0 * double(alone.bytes.size()) / n;
      auto bpv = [n](const kdmesh::EncodeResult& r) { return 8.0 * double(r.bytes.size()) / n; };
      const kdmesh::EncodeResult splitAlone = encodeOrFail(split, options);
      const kdmesh::EncodeResult withMap = encodeOrFail(mapped, options);
      kdmesh::EncodeOptions quantized = options;
      quantized.attributeBits = 12;
      const kdmesh::EncodeResult withMap12 = encodeOrFail(mapped, quantized);
      const std::vector<uint8_t>& uv = mapped.attributes[0].values;
      const double dracoMap =
          8.0 *
              double(dracoBytes(mapped, bits,
                                {{draco::GeometryAttribute::TEX_COORD, draco::DT_FLOAT32, 2, uv.data(), 12}})) /
              n -
          dracoAlone;
      const double map12 = bpv(withMap12) - kdmeshAlone;
      std::printf("| %s | %d | %zu | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f |\n", name.c_str(), bits,
                  seamVertices, kdmeshAlone, bpv(splitAlone), bpv(withMap), bpv(withMap12), map12, dracoMap,
                  map12 / dracoMap);
      std::fflush(stdout);

      kdmesh::Complex withNormals = model;
      withNormals.attributes = {floatAttribute("normal", 3, normals)};
      const kdmesh::EncodeResult exact = encodeOrFail(withNormals, options);
      std::snprintf(line, sizeof line, "| %s | %d | exact | %.3f | %.3f | | | |\n", name.c_str(), bits, bpv(exact),
                    bpv(exact) - kdmeshAlone);
      normalRows += line;
      for (const int normalBits : {8, 10, 12}) {
        kdmesh::EncodeOptions octahedral = options;
        octahedral.normalBits = normalBits;
        const kdmesh::EncodeResult ours = encodeOrFail(withNormals, octahedral);
        const double draco =
            8.0 *
            double(dracoBytes(model, bits,
                              {{draco::GeometryAttribute::NORMAL, draco::DT_FLOAT32, 3, normals.data(), normalBits}})) /
            n;
        std::snprintf(line, sizeof line, "| %s | %d | octahedral %d bits | %.3f | %.3f | %.3f | %.3f | %.3f |\n",
                      name.c_str(), bits, normalBits, bpv(ours), bpv(ours) - kdmeshAlone, draco, draco - dracoAlone,
                      (bpv(ours) - kdmeshAlone) / (draco - dracoAlone));
        normalRows += line;
      }

      const DracoAttribute colour{draco::GeometryAttribute::COLOR, draco::DT_UINT8, 3, colours.data(), 0};
      for (const bool cloud : {false, true}) {
        kdmesh::Complex coloured = model;
        if (cloud) coloured.triangles.clear();
        coloured.attributes = {{"color", kdmesh::AttributeType::UInt8, 3, colours, {}}};
        kdmesh::Complex plain = coloured;
        plain.attributes.clear();
        const kdmesh::EncodeResult ours = encodeOrFail(coloured, options);
        const double oursPlain = bpv(encodeOrFail(plain, options));
        const double draco = 8.0 * double(dracoBytes(model, bits, {colour}, cloud)) / n;
        const double dracoPlain = cloud ? 8.0 * double(dracoBytes(model, bits, {}, true)) / n : dracoAlone;
        std::snprintf(line, sizeof line, "| %s | %s | %d | %.3f | %.3f | %.3f | %.3f | %.3f |\n", name.c_str(),
                      cloud ? "point cloud" : "mesh", bits, bpv(ours), bpv(ours) - oursPlain, draco, draco - dracoPlain,
                      (bpv(ours) - oursPlain) / (draco - dracoPlain));
        colourRows += line;
      }
    }
  }
  std::printf("\n| model | bits | normals | kdmesh bpv | kdmesh normal bpv | Draco -cl 10 bpv | Draco normal bpv | "
              "size ratio |\n");
  std::printf("|---|---:|---|---:|---:|---:|---:|---:|\n%s", normalRows.c_str());
  std::printf("\n| model | as | bits | kdmesh bpv | kdmesh colour bpv | Draco -cl 10 bpv | Draco colour bpv | colour size ratio |\n");
  std::printf("|---|---|---:|---:|---:|---:|---:|---:|\n%s", colourRows.c_str());
  return 0;
}
