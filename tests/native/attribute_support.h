// Helpers of the vertex attribute tests (test_attributes.cpp,
// test_attribute_io.cpp): attributes from typed values, vertices as keys of
// their position and values, and the lossless round trip through the codec.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "complexes.h"
#include "kdmesh/kdmesh.h"

namespace kdmesh::test {

template <class T>
inline VertexAttribute attribute(const std::string& name, AttributeType type, uint8_t components, const std::vector<T>& values) {
  VertexAttribute a{name, type, components, {}, {}};
  a.values.resize(values.size() * sizeof(T));
  std::memcpy(a.values.data(), values.data(), a.values.size());
  return a;
}

// One attribute of every type, made from the positions and a seed: smooth
// colours, unit normals with special float values mixed in, signed labels.
inline std::vector<VertexAttribute> everyKind(const Complex& c, uint32_t seed) {
  std::mt19937 rng(seed);
  const size_t n = c.vertexCount();
  std::vector<uint8_t> colour, small;
  std::vector<int8_t> signedByte;
  std::vector<uint16_t> intensity;
  std::vector<int16_t> offset;
  std::vector<uint32_t> id;
  std::vector<int32_t> label;
  std::vector<float> normal, uv;
  const float special[] = {-0.0f, std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                           std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::denorm_min(),
                           -std::numeric_limits<float>::max()};
  for (size_t v = 0; v < n; ++v) {
    const float* p = &c.positions[3 * v];
    for (int k = 0; k < 3; ++k) colour.push_back(uint8_t(int(128 + 100 * std::sin(p[k] * 2.f)) & 0xff));
    small.push_back(uint8_t(rng() % 3));
    signedByte.push_back(int8_t(rng() % 256));
    intensity.push_back(uint16_t(30000 + 20000 * std::cos(p[0])));
    offset.push_back(int16_t(int(rng() % 65536) - 32768));
    id.push_back(uint32_t(v) * 2654435761u);
    label.push_back(int32_t(rng() % 7) - 3);
    const float length = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) + 1e-6f;
    for (int k = 0; k < 3; ++k) normal.push_back(rng() % 50 == 0 ? special[rng() % 6] : p[k] / length);
    uv.push_back(p[0] * 0.1f);
    uv.push_back(p[1] * 0.1f);
  }
  return {attribute("color", AttributeType::UInt8, 3, colour),  attribute("flag", AttributeType::UInt8, 1, small),
          attribute("tilt", AttributeType::Int8, 1, signedByte), attribute("intensity", AttributeType::UInt16, 1, intensity),
          attribute("offset", AttributeType::Int16, 1, offset), attribute("id", AttributeType::UInt32, 1, id),
          attribute("label", AttributeType::Int32, 1, label),   attribute("normal", AttributeType::Float32, 3, normal),
          attribute("uv", AttributeType::Float32, 2, uv)};
}

// A vertex as its position bits followed by every attribute's bytes.
using VertexKey = std::vector<uint8_t>;
inline std::vector<VertexKey> vertexKeys(const Complex& c) {
  std::vector<VertexKey> keys(c.vertexCount());
  for (size_t v = 0; v < keys.size(); ++v) {
    const uint8_t* p = reinterpret_cast<const uint8_t*>(&c.positions[3 * v]);
    keys[v].assign(p, p + 12);
    for (const VertexAttribute& a : c.attributes) {
      const uint8_t* values = a.values.data() + v * a.valueBytes();
      keys[v].insert(keys[v].end(), values, values + a.valueBytes());
    }
  }
  return keys;
}

inline void expectSameDescriptors(const Complex& input, const Complex& decoded) {
  ASSERT_EQ(decoded.attributes.size(), input.attributes.size());
  for (size_t a = 0; a < input.attributes.size(); ++a) {
    EXPECT_EQ(decoded.attributes[a].name, input.attributes[a].name);
    EXPECT_EQ(decoded.attributes[a].type, input.attributes[a].type);
    EXPECT_EQ(decoded.attributes[a].components, input.attributes[a].components);
    ASSERT_EQ(decoded.attributes[a].values.size(), decoded.vertexCount() * input.attributes[a].valueBytes());
  }
}

// Lossless: the same vertices (position and values) up to order, the same
// complex, and every prefix's vertices with some input vertex's values.
inline void expectRoundTrip(const Complex& input, const EncodeOptions& options) {
  const EncodeResult encoded = encode(input, options);
  ASSERT_TRUE(encoded.status.ok()) << encoded.status.message;
  Decoder decoder;
  ASSERT_TRUE(decoder.push(encoded.bytes.data(), encoded.bytes.size()).ok());
  ASSERT_TRUE(decoder.finish().ok());
  EXPECT_EQ(decoder.header().attributeCount, input.attributes.size());
  const Complex decoded = decoder.snapshot();
  expectSameDescriptors(input, decoded);
  // Positions are exact in float32 mode only: elsewhere the values alone.
  const size_t skip = options.exact ? 0 : 12;
  auto keys = [skip](const Complex& c) {
    std::vector<VertexKey> out;
    for (const VertexKey& key : vertexKeys(c)) out.emplace_back(key.begin() + std::ptrdiff_t(skip), key.end());
    std::sort(out.begin(), out.end());
    return out;
  };
  EXPECT_TRUE(keys(decoded) == keys(input)) << "vertices and their values differ";
  if (input.hasSimplices() && options.exact) {
    EXPECT_EQ(canonicalForm(decoded), canonicalForm(input));
  }

  // Values of the input, whatever the position (a prefix's vertices stand
  // at their cells).
  std::set<VertexKey> inputValues;
  for (VertexKey key : vertexKeys(input)) inputValues.insert(VertexKey(key.begin() + 12, key.end()));
  for (const ChunkInfo& chunk : decoder.chunks()) {
    Decoder prefix;
    ASSERT_TRUE(prefix.push(encoded.bytes.data(), chunk.offset).ok());
    const Complex coarse = prefix.snapshot();
    if (!prefix.hasHeader() || coarse.attributes.empty()) continue;
    expectSameDescriptors(input, coarse);
    for (const VertexKey& key : vertexKeys(coarse))
      ASSERT_TRUE(inputValues.count(VertexKey(key.begin() + 12, key.end()))) << "prefix of " << chunk.offset;
  }
}

}  // namespace kdmesh::test
