// glTF scenes: every primitive to a kdmesh stream and back (kdmesh/gltf.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include "gltf/gltf_internal.h"
#include "kdmesh/gltf.h"

namespace kdmesh::test {
namespace {

namespace fs = std::filesystem;
using gltf::detail::readAccessor;
using tinygltf::Accessor;
using tinygltf::Model;
using tinygltf::Primitive;

// A 1x1 PNG: an image the validator can read.
const std::vector<uint8_t> kPng = {
    0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44, 0x52, 0x00, 0x00,
    0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x08, 0x02, 0x00, 0x00, 0x00, 0x90, 0x77, 0x53, 0xde, 0x00, 0x00, 0x00,
    0x0c, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9c, 0x63, 0xf8, 0xdf, 0xc0, 0x00, 0x00, 0x04, 0x01, 0x01, 0x80, 0xc5,
    0x2a, 0x18, 0x5d, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};

// Builds a scene in memory, as an exporter would lay it out.
class SceneBuilder {
 public:
  SceneBuilder() {
    model_.asset.version = "2.0";
    model_.asset.generator = "kdmesh tests";
    model_.buffers.emplace_back();
  }

  template <typename T>
  int accessor(const std::vector<T>& values, int componentType, int type, bool normalized = false, int target = 0) {
    std::vector<unsigned char>& data = model_.buffers[0].data;
    data.resize((data.size() + 3) & ~size_t{3});
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = data.size();
    view.byteLength = values.size() * sizeof(T);
    view.target = target;
    const auto* bytes = reinterpret_cast<const unsigned char*>(values.data());
    data.insert(data.end(), bytes, bytes + view.byteLength);
    model_.bufferViews.push_back(view);
    Accessor a;
    a.bufferView = int(model_.bufferViews.size() - 1);
    a.componentType = componentType;
    a.type = type;
    a.normalized = normalized;
    a.count = values.size() / size_t(gltf::detail::typeComponents(type));
    if (componentType == TINYGLTF_COMPONENT_TYPE_FLOAT && type == TINYGLTF_TYPE_VEC3) {
      a.minValues.assign(3, 1e30);
      a.maxValues.assign(3, -1e30);
      for (size_t i = 0; i < values.size(); ++i) {
        a.minValues[i % 3] = std::min(a.minValues[i % 3], double(values[i]));
        a.maxValues[i % 3] = std::max(a.maxValues[i % 3], double(values[i]));
      }
    }
    model_.accessors.push_back(a);
    return int(model_.accessors.size() - 1);
  }
  int positions(const std::vector<float>& xyz) {
    return accessor(xyz, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, false, TINYGLTF_TARGET_ARRAY_BUFFER);
  }
  int image(const std::vector<uint8_t>& png) {
    std::vector<unsigned char>& data = model_.buffers[0].data;
    data.resize((data.size() + 3) & ~size_t{3});
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = data.size();
    view.byteLength = png.size();
    data.insert(data.end(), png.begin(), png.end());
    model_.bufferViews.push_back(view);
    tinygltf::Image image;
    image.bufferView = int(model_.bufferViews.size() - 1);
    image.mimeType = "image/png";
    image.name = "checker";
    model_.images.push_back(image);
    return int(model_.images.size() - 1);
  }
  Model& model() { return model_; }

 private:
  Model model_;
};

// A grid of (n+1)^2 vertices with two triangles per cell, on a wavy surface.
std::vector<float> gridPositions(int n) {
  std::vector<float> xyz;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      xyz.push_back(float(i) / float(n));
      xyz.push_back(float(j) / float(n));
      xyz.push_back(0.1f * float((i * 7 + j * 3) % 5) / 5.0f);
    }
  return xyz;
}
std::vector<uint16_t> gridTriangles(int n, int firstRow, int rows) {
  std::vector<uint16_t> t;
  for (int j = firstRow; j < firstRow + rows; ++j)
    for (int i = 0; i < n; ++i) {
      const auto v = uint16_t(j * (n + 1) + i);
      const auto up = uint16_t(v + n + 1);
      t.insert(t.end(), {v, uint16_t(v + 1), uint16_t(up + 1), v, uint16_t(up + 1), up});
    }
  return t;
}

// The scene of the round-trip tests: several meshes and materials, a
// texture with its image, a node hierarchy with extras, an animation, and
// indexed, non-indexed, strip, line and point primitives.
Model testScene() {
  SceneBuilder b;
  Model& m = b.model();
  const int n = 8;
  const std::vector<float> grid = gridPositions(n);
  const size_t gridVertices = grid.size() / 3;
  std::vector<float> normals, uvs;
  std::vector<uint8_t> colours;
  std::vector<uint16_t> labels;
  for (size_t v = 0; v < gridVertices; ++v) {
    normals.insert(normals.end(), {0.0f, -0.0f, 1.0f});
    uvs.insert(uvs.end(), {grid[3 * v], 1.0f - grid[3 * v + 1]});
    colours.insert(colours.end(), {uint8_t(v * 13), uint8_t(v * 7), uint8_t(255 - v), 255});
    labels.push_back(uint16_t(v % 3));
  }
  const int position = b.positions(grid);
  const int normal = b.accessor(normals, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3);
  const int uv = b.accessor(uvs, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2);
  const int colour = b.accessor(colours, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_TYPE_VEC4, true);
  const int label = b.accessor(labels, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_SCALAR);
  // Mesh 0: one vertex buffer, two materials, each drawing half the rows.
  tinygltf::Mesh surface;
  surface.name = "surface";
  for (int half = 0; half < 2; ++half) {
    Primitive p;
    p.attributes = {{"POSITION", position}, {"NORMAL", normal}, {"TEXCOORD_0", uv}, {"COLOR_0", colour}, {"_LABEL", label}};
    p.indices = b.accessor(gridTriangles(n, half * n / 2, n / 2), TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                           TINYGLTF_TYPE_SCALAR, false, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    p.material = half;
    p.mode = TINYGLTF_MODE_TRIANGLES;
    surface.primitives.push_back(p);
  }
  m.meshes.push_back(surface);

  // Mesh 1: a non-indexed triangle soup (two vertices coincide), a
  // non-indexed triangle strip and an indexed line list.
  tinygltf::Mesh soup;
  soup.name = "soup";
  {
    Primitive p;
    p.attributes = {{"POSITION", b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 2, 2, 2, 3, 2, 2, 2, 3, 2})}};
    p.material = 1;
    p.mode = TINYGLTF_MODE_TRIANGLES;
    soup.primitives.push_back(p);
    Primitive strip;
    strip.attributes = {{"POSITION", b.positions({0, 0, 5, 1, 0, 5, 0, 1, 5, 1, 1, 5, 0, 2, 5, 1, 2.5f, 5})}};
    strip.mode = TINYGLTF_MODE_TRIANGLE_STRIP;
    soup.primitives.push_back(strip);
    Primitive lines;
    lines.attributes = {{"POSITION", b.positions({0, 0, -1, 1, 0, -1, 1, 1, -1, 0, 1, -1.5f})}};
    lines.indices = b.accessor(std::vector<uint8_t>{0, 1, 1, 2, 2, 3, 3, 0, 0, 2}, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                               TINYGLTF_TYPE_SCALAR, false, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    lines.mode = TINYGLTF_MODE_LINE;
    soup.primitives.push_back(lines);
  }
  m.meshes.push_back(soup);

  // Mesh 2: a point cloud with float colours.
  tinygltf::Mesh cloud;
  cloud.name = "cloud";
  {
    std::vector<float> xyz, rgb;
    for (int i = 0; i < 50; ++i) {
      xyz.insert(xyz.end(), {float(i % 7) * 0.25f, float(i % 5) * 0.5f, float(i % 3)});
      rgb.insert(rgb.end(), {float(i) / 50.0f, 0.5f, 1.0f - float(i) / 50.0f});
    }
    Primitive p;
    p.attributes = {{"POSITION", b.positions(xyz)},
                    {"COLOR_0", b.accessor(rgb, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3)}};
    p.mode = TINYGLTF_MODE_POINTS;
    cloud.primitives.push_back(p);
  }
  m.meshes.push_back(cloud);

  // Materials, a texture with its image and sampler.
  const int image = b.image(kPng);
  tinygltf::Sampler sampler;
  sampler.magFilter = TINYGLTF_TEXTURE_FILTER_NEAREST;
  m.samplers.push_back(sampler);
  tinygltf::Texture texture;
  texture.source = image;
  texture.sampler = 0;
  m.textures.push_back(texture);
  tinygltf::Material textured;
  textured.name = "textured";
  textured.pbrMetallicRoughness.baseColorTexture.index = 0;
  textured.pbrMetallicRoughness.roughnessFactor = 0.25;
  m.materials.push_back(textured);
  tinygltf::Material red;
  red.name = "red";
  red.pbrMetallicRoughness.baseColorFactor = {1, 0, 0, 1};
  red.doubleSided = true;
  m.materials.push_back(red);

  // Nodes: a root with a transform and extras, holding the meshes.
  tinygltf::Node root;
  root.name = "root";
  root.translation = {1, 2, 3};
  root.children = {1, 2, 3};
  root.extras = tinygltf::Value(tinygltf::Value::Object{{"author", tinygltf::Value(std::string("kdmesh"))}});
  m.nodes.push_back(root);
  for (int mesh = 0; mesh < 3; ++mesh) {
    tinygltf::Node child;
    child.name = "child" + std::to_string(mesh);
    child.mesh = mesh;
    child.scale = {1, 1, double(mesh + 1)};
    m.nodes.push_back(child);
  }
  tinygltf::Scene scene;
  scene.nodes = {0};
  m.scenes.push_back(scene);
  m.defaultScene = 0;

  // An animation of the root's translation.
  tinygltf::Animation animation;
  animation.name = "slide";
  tinygltf::AnimationSampler keys;
  keys.input = b.accessor(std::vector<float>{0, 1}, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR);
  m.accessors[size_t(keys.input)].minValues = {0};
  m.accessors[size_t(keys.input)].maxValues = {1};
  keys.output = b.accessor(std::vector<float>{1, 2, 3, 4, 5, 6}, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3);
  keys.interpolation = "LINEAR";
  animation.samplers.push_back(keys);
  tinygltf::AnimationChannel channel;
  channel.sampler = 0;
  channel.target_node = 0;
  channel.target_path = "translation";
  animation.channels.push_back(channel);
  m.animations.push_back(animation);
  return m;
}

// One drawn vertex: its position and attribute bytes, semantics in order.
using VertexRecord = std::vector<uint8_t>;

// What a primitive draws, independent of vertex order and of how it lists
// its simplices: each simplex as its vertices' records, rotated to start at
// the smallest (keeping the orientation), all simplices sorted.
struct Drawn {
  int dimension = 0;
  std::map<std::string, std::pair<int, int>> layout;  // semantic -> (componentType, type)
  std::vector<std::vector<VertexRecord>> simplices;
  bool operator==(const Drawn& o) const {
    return dimension == o.dimension && layout == o.layout && simplices == o.simplices;
  }
};

Drawn drawnBy(const Model& model, const Primitive& primitive) {
  Drawn out;
  size_t count = 0;
  std::vector<std::vector<uint8_t>> values;
  std::vector<size_t> bytes;
  for (const auto& [semantic, index] : primitive.attributes) {
    const Accessor& a = model.accessors[size_t(index)];
    out.layout[semantic] = {a.componentType, a.type};
    values.emplace_back();
    EXPECT_TRUE(readAccessor(model, index, values.back()).ok()) << semantic;
    count = a.count;
    bytes.push_back(values.back().size() / std::max<size_t>(a.count, 1));
  }
  const auto record = [&](uint32_t v) {
    VertexRecord r;
    for (size_t i = 0; i < values.size(); ++i)
      r.insert(r.end(), values[i].begin() + long(v * bytes[i]), values[i].begin() + long((v + 1) * bytes[i]));
    return r;
  };
  std::vector<uint32_t> order;
  if (primitive.indices >= 0) {
    EXPECT_TRUE(gltf::detail::readIndices(model, primitive.indices, count, order).ok());
  } else {
    for (uint32_t v = 0; v < count; ++v) order.push_back(v);
  }
  std::vector<std::vector<uint32_t>> simplices;
  const size_t n = order.size();
  switch (primitive.mode) {
    case TINYGLTF_MODE_POINTS:
      for (uint32_t v : order) simplices.push_back({v});
      break;
    case TINYGLTF_MODE_LINE:
      for (size_t i = 0; i + 1 < n; i += 2) simplices.push_back({order[i], order[i + 1]});
      break;
    case TINYGLTF_MODE_TRIANGLES:
      for (size_t i = 0; i + 2 < n; i += 3) simplices.push_back({order[i], order[i + 1], order[i + 2]});
      break;
    case TINYGLTF_MODE_TRIANGLE_STRIP:
      for (size_t i = 0; i + 2 < n; ++i)
        simplices.push_back(i % 2 ? std::vector<uint32_t>{order[i + 1], order[i], order[i + 2]}
                                  : std::vector<uint32_t>{order[i], order[i + 1], order[i + 2]});
      break;
    default: ADD_FAILURE() << "mode " << primitive.mode;
  }
  out.dimension = simplices.empty() ? 0 : int(simplices[0].size()) - 1;
  for (const auto& simplex : simplices) {
    std::vector<VertexRecord> records;
    for (uint32_t v : simplex) records.push_back(record(v));
    if (records.size() == 2) std::sort(records.begin(), records.end());  // lines have no orientation
    else std::rotate(records.begin(), std::min_element(records.begin(), records.end()), records.end());
    out.simplices.push_back(records);
  }
  std::sort(out.simplices.begin(), out.simplices.end());
  return out;
}

std::vector<uint8_t> imageBytes(const Model& model, const tinygltf::Image& image) {
  const uint8_t* data = nullptr;
  size_t size = 0;
  EXPECT_TRUE(gltf::detail::viewBytes(model, image.bufferView, data, size).ok());
  return std::vector<uint8_t>(data, data + size);
}

// Everything but the geometry is the input's.
void expectSameContent(const Model& in, const Model& out) {
  EXPECT_EQ(in.materials, out.materials);
  EXPECT_EQ(in.textures, out.textures);
  EXPECT_EQ(in.samplers, out.samplers);
  EXPECT_EQ(in.nodes, out.nodes);
  EXPECT_EQ(in.scenes, out.scenes);
  EXPECT_EQ(in.defaultScene, out.defaultScene);
  ASSERT_EQ(in.images.size(), out.images.size());
  for (size_t i = 0; i < in.images.size(); ++i) {
    EXPECT_EQ(in.images[i].name, out.images[i].name);
    EXPECT_EQ(in.images[i].mimeType, out.images[i].mimeType);
    EXPECT_EQ(imageBytes(in, in.images[i]), imageBytes(out, out.images[i]));
  }
  ASSERT_EQ(in.animations.size(), out.animations.size());
  for (size_t i = 0; i < in.animations.size(); ++i) {
    EXPECT_EQ(in.animations[i].channels, out.animations[i].channels);
    ASSERT_EQ(in.animations[i].samplers.size(), out.animations[i].samplers.size());
    for (size_t s = 0; s < in.animations[i].samplers.size(); ++s) {
      const auto& a = in.animations[i].samplers[s];
      const auto& b = out.animations[i].samplers[s];
      std::vector<uint8_t> x, y;
      ASSERT_TRUE(readAccessor(in, a.input, x).ok());
      ASSERT_TRUE(readAccessor(out, b.input, y).ok());
      EXPECT_EQ(x, y);
      ASSERT_TRUE(readAccessor(in, a.output, x).ok());
      ASSERT_TRUE(readAccessor(out, b.output, y).ok());
      EXPECT_EQ(x, y);
    }
  }
  ASSERT_EQ(in.meshes.size(), out.meshes.size());
  for (size_t m = 0; m < in.meshes.size(); ++m) {
    EXPECT_EQ(in.meshes[m].name, out.meshes[m].name);
    ASSERT_EQ(in.meshes[m].primitives.size(), out.meshes[m].primitives.size());
    for (size_t p = 0; p < in.meshes[m].primitives.size(); ++p)
      EXPECT_EQ(in.meshes[m].primitives[p].material, out.meshes[m].primitives[p].material);
  }
}

class GltfTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "kdmesh_gltf_test_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr) << std::strerror(errno);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }
  std::string at(const std::string& name) const { return (dir_ / name).string(); }

  void save(const Model& model, const std::string& name) {
    ASSERT_TRUE(gltf::detail::saveScene(at(name), model).ok());
  }
  Model load(const std::string& name) {
    Model model;
    io::Notes notes;
    const Status s = gltf::detail::loadScene(at(name), model, notes);
    EXPECT_TRUE(s.ok()) << s.message;
    return model;
  }

  // Encodes `input` to `encoded` and decodes that to `decoded`.
  void roundTrip(const std::string& input, const std::string& encoded, const std::string& decoded,
                 const gltf::EncodeOptions& options = {}) {
    io::Notes notes;
    gltf::Summary summary;
    Status s = gltf::encodeFile(at(input), at(encoded), options, notes, &summary);
    ASSERT_TRUE(s.ok()) << s.message;
    EXPECT_EQ(summary.streams, summary.primitives);
    s = gltf::decodeFile(at(encoded), at(decoded), notes);
    ASSERT_TRUE(s.ok()) << s.message;
  }

  fs::path dir_;
};

TEST_F(GltfTest, EveryPrimitiveBecomesAStreamAndDecodesToWhatItDrew) {
  const Model scene = testScene();
  save(scene, "scene.glb");
  const Model in = load("scene.glb");
  roundTrip("scene.glb", "scene.kdm.glb", "plain.glb");

  const Model encoded = load("scene.kdm.glb");
  EXPECT_EQ(encoded.extensionsRequired, std::vector<std::string>{gltf::kExtensionName});
  for (const tinygltf::Mesh& mesh : encoded.meshes)
    for (const Primitive& p : mesh.primitives) {
      ASSERT_TRUE(p.extensions.count(gltf::kExtensionName));
      EXPECT_TRUE(gltf::detail::isListMode(p.mode));
      for (const auto& entry : p.attributes) EXPECT_LT(encoded.accessors[size_t(entry.second)].bufferView, 0);
    }
  // The streams take less than the geometry did.
  EXPECT_LT(fs::file_size(at("scene.kdm.glb")), fs::file_size(at("scene.glb")));

  const Model out = load("plain.glb");
  EXPECT_TRUE(out.extensionsUsed.empty());
  EXPECT_TRUE(out.extensionsRequired.empty());
  expectSameContent(in, out);
  for (size_t m = 0; m < in.meshes.size(); ++m)
    for (size_t p = 0; p < in.meshes[m].primitives.size(); ++p)
      EXPECT_TRUE(drawnBy(in, in.meshes[m].primitives[p]) == drawnBy(out, out.meshes[m].primitives[p]))
          << "mesh " << m << " primitive " << p;
}

TEST_F(GltfTest, TheComparisonSeesAChangedVertex) {
  // The check of the round trip above must be able to fail.
  Model scene = testScene();
  save(scene, "scene.glb");
  const Model in = load("scene.glb");
  Model changed = in;
  const int position = changed.meshes[0].primitives[0].attributes.at("POSITION");
  tinygltf::BufferView& view = changed.bufferViews[size_t(changed.accessors[size_t(position)].bufferView)];
  changed.buffers[0].data[view.byteOffset + 4] ^= 1;
  EXPECT_FALSE(drawnBy(in, in.meshes[0].primitives[0]) == drawnBy(changed, changed.meshes[0].primitives[0]));
}

TEST_F(GltfTest, JsonGltfWithSeparateStreamsRoundTrips) {
  save(testScene(), "scene.gltf");
  EXPECT_TRUE(fs::exists(at("scene.bin")));
  const Model in = load("scene.gltf");
  gltf::EncodeOptions options;
  options.separateStreams = true;
  roundTrip("scene.gltf", "out.kdm.gltf", "plain.gltf", options);
  EXPECT_TRUE(fs::exists(at("out.0-0.kdm")));
  EXPECT_TRUE(fs::exists(at("out.2-0.kdm")));
  const Model encoded = load("out.kdm.gltf");
  EXPECT_EQ(encoded.meshes[2].primitives[0].extensions.at(gltf::kExtensionName).Get("uri").Get<std::string>(),
            "out.2-0.kdm");
  const Model out = load("plain.gltf");
  expectSameContent(in, out);
  for (size_t m = 0; m < in.meshes.size(); ++m)
    for (size_t p = 0; p < in.meshes[m].primitives.size(); ++p)
      EXPECT_TRUE(drawnBy(in, in.meshes[m].primitives[p]) == drawnBy(out, out.meshes[m].primitives[p]));
}

TEST_F(GltfTest, AFallbackKeepsTheUncompressedAccessorsAndIsNotRequired) {
  save(testScene(), "scene.glb");
  const Model in = load("scene.glb");
  gltf::EncodeOptions options;
  options.fallback = true;
  io::Notes notes;
  gltf::Summary summary;
  ASSERT_TRUE(gltf::encodeFile(at("scene.glb"), at("fallback.glb"), options, notes, &summary).ok());
  // Indexed lists that draw every vertex: the points and the lines (the
  // surface's halves share their vertices, the soup and strip have no indices).
  EXPECT_EQ(summary.streams, 2u);
  const Model encoded = load("fallback.glb");
  EXPECT_TRUE(encoded.extensionsRequired.empty());
  EXPECT_EQ(encoded.extensionsUsed, std::vector<std::string>{gltf::kExtensionName});
  // A loader without the extension draws the input.
  for (size_t m = 0; m < in.meshes.size(); ++m)
    for (size_t p = 0; p < in.meshes[m].primitives.size(); ++p)
      EXPECT_TRUE(drawnBy(in, in.meshes[m].primitives[p]) == drawnBy(encoded, encoded.meshes[m].primitives[p]));
  ASSERT_TRUE(gltf::decodeFile(at("fallback.glb"), at("plain.glb"), notes).ok());
  const Model out = load("plain.glb");
  for (size_t m = 0; m < in.meshes.size(); ++m)
    for (size_t p = 0; p < in.meshes[m].primitives.size(); ++p)
      EXPECT_TRUE(drawnBy(in, in.meshes[m].primitives[p]) == drawnBy(out, out.meshes[m].primitives[p]));
}

TEST_F(GltfTest, PrimitivesThatCannotBeKeptExactlyStayUncompressed) {
  SceneBuilder b;
  Model& m = b.model();
  tinygltf::Mesh mesh;
  Primitive twice;  // the same triangle in both windings: a complex holds it once
  twice.attributes = {{"POSITION", b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0})}};
  twice.indices = b.accessor(std::vector<uint16_t>{0, 1, 2, 0, 2, 1}, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                             TINYGLTF_TYPE_SCALAR);
  twice.mode = TINYGLTF_MODE_TRIANGLES;
  mesh.primitives.push_back(twice);
  Primitive morphed = twice;  // morph targets
  morphed.indices = -1;
  morphed.targets = {{{"POSITION", b.positions({0, 0, 1, 0, 0, 1, 0, 0, 1})}}};
  mesh.primitives.push_back(morphed);
  Primitive plain;
  plain.attributes = {{"POSITION", b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0})}};
  plain.mode = TINYGLTF_MODE_TRIANGLES;
  mesh.primitives.push_back(plain);
  m.meshes.push_back(mesh);
  tinygltf::Node node;
  node.mesh = 0;
  m.nodes.push_back(node);
  save(m, "scene.glb");
  const Model in = load("scene.glb");
  io::Notes notes;
  gltf::Summary summary;
  ASSERT_TRUE(gltf::encodeFile(at("scene.glb"), at("out.glb"), {}, notes, &summary).ok());
  EXPECT_EQ(summary.streams, 1u);
  ASSERT_EQ(notes.size(), 2u);
  EXPECT_NE(notes[0].find("mesh 0 primitive 0: kept uncompressed"), std::string::npos) << notes[0];
  EXPECT_NE(notes[1].find("morph targets"), std::string::npos) << notes[1];
  const Model out = load("out.glb");
  for (size_t p = 0; p < 2; ++p) {
    EXPECT_FALSE(out.meshes[0].primitives[p].extensions.count(gltf::kExtensionName));
    EXPECT_TRUE(drawnBy(in, in.meshes[0].primitives[p]) == drawnBy(out, out.meshes[0].primitives[p]));
  }
  EXPECT_TRUE(out.meshes[0].primitives[2].extensions.count(gltf::kExtensionName));
}

TEST_F(GltfTest, GridPositionsStayWithinHalfAStep) {
  save(testScene(), "scene.glb");
  gltf::EncodeOptions options;
  options.stream.exact = false;
  options.stream.bits = 10;
  io::Notes notes;
  ASSERT_TRUE(gltf::encodeFile(at("scene.glb"), at("grid.glb"), options, notes).ok());
  ASSERT_TRUE(gltf::decodeFile(at("grid.glb"), at("plain.glb"), notes).ok());
  const Model in = load("scene.glb"), out = load("plain.glb");
  const Primitive& a = in.meshes[2].primitives[0];
  const Primitive& b = out.meshes[2].primitives[0];
  std::vector<uint8_t> x, y;
  ASSERT_TRUE(readAccessor(in, a.attributes.at("POSITION"), x).ok());
  ASSERT_TRUE(readAccessor(out, b.attributes.at("POSITION"), y).ok());
  ASSERT_EQ(x.size(), y.size());
  // The cloud's longest side is 2: steps of 2 / 1023.
  std::vector<float> p(x.size() / 4), q(y.size() / 4);
  std::memcpy(p.data(), x.data(), x.size());
  std::memcpy(q.data(), y.data(), y.size());
  std::vector<std::array<float, 3>> ps, qs;
  for (size_t i = 0; i < p.size(); i += 3) ps.push_back({p[i], p[i + 1], p[i + 2]});
  for (size_t i = 0; i < q.size(); i += 3) qs.push_back({q[i], q[i + 1], q[i + 2]});
  for (const auto& v : ps) {
    double best = 1e30;
    for (const auto& w : qs)
      best = std::min(best, double(std::max({std::abs(v[0] - w[0]), std::abs(v[1] - w[1]), std::abs(v[2] - w[2])})));
    EXPECT_LE(best, 0.5 * 2.0 / 1023 + 1e-6);
  }
}

// ---------------------------------------------------------------------------
// Hostile input: clear errors, never a crash
// ---------------------------------------------------------------------------

TEST_F(GltfTest, AccessorsBeyondTheirViewsAndIndicesOutOfRangeAreErrors) {
  {
    Model scene = testScene();
    scene.accessors[size_t(scene.meshes[1].primitives[0].attributes.at("POSITION"))].count = 1000000;
    save(scene, "long.glb");
    io::Notes notes;
    const Status s = gltf::encodeFile(at("long.glb"), at("out.glb"), {}, notes);
    EXPECT_EQ(s.code, ErrorCode::InvalidInput);
    EXPECT_NE(s.message.find("mesh 1 primitive 0"), std::string::npos) << s.message;
  }
  {
    Model scene = testScene();
    const Accessor& indices = scene.accessors[size_t(scene.meshes[1].primitives[2].indices)];
    scene.buffers[0].data[scene.bufferViews[size_t(indices.bufferView)].byteOffset + 3] = 200;
    save(scene, "index.glb");
    io::Notes notes;
    const Status s = gltf::encodeFile(at("index.glb"), at("out.glb"), {}, notes);
    EXPECT_EQ(s.code, ErrorCode::InvalidInput);
    EXPECT_NE(s.message.find("index 200"), std::string::npos) << s.message;
  }
}

TEST_F(GltfTest, DamagedStreamsAndFilesAreErrors) {
  save(testScene(), "scene.glb");
  io::Notes notes;
  ASSERT_TRUE(gltf::encodeFile(at("scene.glb"), at("enc.glb"), {}, notes).ok());
  Model encoded = load("enc.glb");
  // A byte of a stream flipped: the stream's checksums catch it.
  const int view = encoded.meshes[0].primitives[0].extensions.at(gltf::kExtensionName).Get("bufferView").GetNumberAsInt();
  encoded.buffers[0].data[encoded.bufferViews[size_t(view)].byteOffset + 100] ^= 0x40;
  save(encoded, "flipped.glb");
  Status s = gltf::decodeFile(at("flipped.glb"), at("out.glb"), notes);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message.find("mesh 0 primitive 0"), std::string::npos) << s.message;
  // A count that disagrees with the stream.
  encoded = load("enc.glb");
  encoded.accessors[size_t(encoded.meshes[2].primitives[0].attributes.at("POSITION"))].count += 1;
  save(encoded, "count.glb");
  s = gltf::decodeFile(at("count.glb"), at("out.glb"), notes);
  EXPECT_EQ(s.code, ErrorCode::InvalidInput);
  EXPECT_NE(s.message.find("vertices"), std::string::npos) << s.message;
  // URIs out of the scene's folder.
  encoded = load("enc.glb");
  tinygltf::Value::Object escape{{"uri", tinygltf::Value(std::string("../secret.kdm"))}};
  encoded.meshes[2].primitives[0].extensions[gltf::kExtensionName] = tinygltf::Value(escape);
  save(encoded, "escape.glb");
  s = gltf::decodeFile(at("escape.glb"), at("out.glb"), notes);
  EXPECT_EQ(s.code, ErrorCode::InvalidInput);
  EXPECT_NE(s.message.find("not a relative path"), std::string::npos) << s.message;
  // Every prefix of the file: an error or a scene, never a crash.
  std::ifstream file(at("enc.glb"), std::ios::binary);
  const std::vector<char> bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  for (size_t size : {size_t(0), size_t(11), size_t(20), bytes.size() / 3, bytes.size() / 2, bytes.size() - 1}) {
    std::ofstream(at("cut.glb"), std::ios::binary).write(bytes.data(), std::streamsize(size));
    s = gltf::decodeFile(at("cut.glb"), at("out.glb"), notes);
    EXPECT_FALSE(s.ok()) << size;
  }
}

TEST_F(GltfTest, DeeplyNestedAndMalformedJsonAreErrors) {
  // Brackets nested 100,000 deep would take a recursive parser's stack.
  std::string nested = "{\"asset\": {\"version\": \"2.0\"}, \"extras\": " + std::string(100000, '[') +
                       std::string(100000, ']') + "}";
  std::ofstream(at("nested.gltf")) << nested;
  io::Notes notes;
  Status s = gltf::encodeFile(at("nested.gltf"), at("out.glb"), {}, notes);
  EXPECT_EQ(s.code, ErrorCode::InvalidInput);
  EXPECT_NE(s.message.find("nests deeper"), std::string::npos) << s.message;
  // Meshes of the wrong JSON types: an error from tinygltf, no exception.
  for (const char* text : {"{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [3, {\"primitives\": 7}], \"accessors\": []}",
                           "{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [{\"primitives\": [{\"indices\": 0, \"attributes\": {}}]}], "
                           "\"accessors\": [5]}",
                           "{\"asset\": ", "not json"}) {
    std::ofstream(at("bad.gltf")) << text;
    s = gltf::encodeFile(at("bad.gltf"), at("out.glb"), {}, notes);
    EXPECT_FALSE(s.ok()) << text;
  }
}

TEST_F(GltfTest, CompressedInputIsRefused) {
  save(testScene(), "scene.glb");
  io::Notes notes;
  ASSERT_TRUE(gltf::encodeFile(at("scene.glb"), at("enc.glb"), {}, notes).ok());
  const Status s = gltf::encodeFile(at("enc.glb"), at("again.glb"), {}, notes);
  EXPECT_EQ(s.code, ErrorCode::Unsupported);
  EXPECT_NE(s.message.find("decode it first"), std::string::npos) << s.message;
}

}  // namespace
}  // namespace kdmesh::test

namespace kdmesh::test {
namespace {

TEST_F(GltfTest, AComplexBecomesASceneOfOneMeshWithItsAttributes) {
  Complex c;
  c.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 5, 5, 5, 6, 6, 6};
  c.triangles = {0, 1, 2, 1, 3, 2};
  c.edges = {3, 4};
  // Vertex 5 is an isolated point.
  const auto attribute = [&](const char* name, AttributeType type, uint8_t components) {
    VertexAttribute a;
    a.name = name;
    a.type = type;
    a.components = components;
    a.values.resize(c.vertexCount() * a.valueBytes());
    for (size_t i = 0; i < a.values.size(); ++i) a.values[i] = uint8_t(i * 37 + 11);
    if (type == AttributeType::Float32)
      for (size_t i = 0; i < a.values.size(); i += 4) {
        const float f = float(i) / 7.0f;
        std::memcpy(&a.values[i], &f, 4);
      }
    c.attributes.push_back(a);
  };
  attribute("color", AttributeType::UInt8, 3);
  attribute("normal", AttributeType::Float32, 3);
  attribute("uv", AttributeType::Float32, 2);
  attribute("label", AttributeType::Int16, 1);
  attribute("id", AttributeType::Int32, 1);
  io::Notes notes;
  ASSERT_TRUE(gltf::writeComplexScene(at("complex.glb"), c, notes).ok());
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("id"), std::string::npos);
  const Model scene = load("complex.glb");
  ASSERT_EQ(scene.meshes.size(), 1u);
  const auto& primitives = scene.meshes[0].primitives;
  ASSERT_EQ(primitives.size(), 3u);
  EXPECT_EQ(primitives[0].mode, TINYGLTF_MODE_TRIANGLES);
  EXPECT_EQ(primitives[1].mode, TINYGLTF_MODE_LINE);
  EXPECT_EQ(primitives[2].mode, TINYGLTF_MODE_POINTS);
  const std::map<std::string, int> semantics = primitives[0].attributes;
  for (const char* s : {"POSITION", "COLOR_0", "NORMAL", "TEXCOORD_0", "_LABEL"}) EXPECT_TRUE(semantics.count(s)) << s;
  EXPECT_FALSE(semantics.count("_ID"));
  EXPECT_TRUE(scene.accessors[size_t(semantics.at("COLOR_0"))].normalized);
  EXPECT_EQ(Drawn(drawnBy(scene, primitives[2])).simplices.size(), 1u);
  // Each primitive of the shared vertices round trips on its own vertices.
  roundTrip("complex.glb", "complex.kdm.glb", "plain.glb");
  const Model out = load("plain.glb");
  for (size_t p = 0; p < 3; ++p) EXPECT_TRUE(drawnBy(scene, primitives[p]) == drawnBy(out, out.meshes[0].primitives[p])) << p;
  c.tetrahedra = {0, 1, 2, 4};
  EXPECT_EQ(gltf::writeComplexScene(at("tetrahedra.glb"), c, notes).code, ErrorCode::InvalidArgument);
}

}  // namespace
}  // namespace kdmesh::test

#ifndef KDMESH_CLI_PATH
#error "KDMESH_CLI_PATH must name the kdmesh executable"
#endif

namespace kdmesh::test {
namespace {

// Runs the CLI in the test's folder; returns its exit status and stderr.
std::pair<int, std::string> runCli(const fs::path& dir, const std::string& args) {
  const std::string err = (dir / "stderr.txt").string();
  const std::string command = "cd '" + dir.string() + "' && exec '" KDMESH_CLI_PATH "' " + args + " </dev/null >/dev/null 2>'" + err + "'";
  const int status = std::system(command.c_str());
  std::ifstream in(err);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, std::string(std::istreambuf_iterator<char>(in), {})};
}

TEST_F(GltfTest, TheCommandLineEncodesAndDecodesScenes) {
  save(testScene(), "scene.glb");
  auto [code, err] = runCli(dir_, "encode scene.glb -o scene.kdm.glb");
  EXPECT_EQ(code, 0) << err;
  EXPECT_NE(err.find("scene.kdm.glb: 6 streams of 6 primitives"), std::string::npos) << err;
  std::tie(code, err) = runCli(dir_, "decode scene.kdm.glb -o plain.gltf -q");
  EXPECT_EQ(code, 0) << err;
  EXPECT_TRUE(err.empty()) << err;
  const Model in = load("scene.glb"), out = load("plain.gltf");
  for (size_t m = 0; m < in.meshes.size(); ++m)
    for (size_t p = 0; p < in.meshes[m].primitives.size(); ++p)
      EXPECT_TRUE(drawnBy(in, in.meshes[m].primitives[p]) == drawnBy(out, out.meshes[m].primitives[p]));
  // Mixed kinds of files and options for the other kind: one-line errors.
  for (const char* args : {"encode scene.glb -o scene.kdm", "decode scene.kdm.glb -o scene.ply",
                           "decode scene.kdm.glb -o x.glb --bytes 100", "encode scene.glb -o x.glb --weld"}) {
    std::tie(code, err) = runCli(dir_, args);
    EXPECT_EQ(code, 1) << args;
    EXPECT_EQ(err.rfind("kdmesh: error: ", 0), 0u) << args << ": " << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  }
}

}  // namespace
}  // namespace kdmesh::test
