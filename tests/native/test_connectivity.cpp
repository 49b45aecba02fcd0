// Connectivity coding: exact round trips of simplicial complexes of every
// kind, and the prefix property (every prefix is the projection of the input).
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "complexes.h"
#include "shapes.h"
#include "kdmesh/kdmesh.h"
#include "test_support.h"

namespace kdmesh::test {
namespace {

Complex roundTrip(const Complex& input, const EncodeOptions& options, EncodeResult* encoded = nullptr) {
  EncodeResult result = encode(input, options);
  EXPECT_TRUE(result.status.ok()) << result.status.message;
  Complex output;
  const Status status = decode(result.bytes.data(), result.bytes.size(), output);
  EXPECT_TRUE(status.ok()) << status.message;
  if (encoded) *encoded = std::move(result);
  return output;
}

EncodeOptions exact() {
  EncodeOptions o;
  o.exact = true;
  return o;
}

void expectExactRoundTrip(const Complex& input) {
  const Complex output = roundTrip(input, exact());
  EXPECT_EQ(output.vertexCount(), input.vertexCount());
  EXPECT_EQ(canonicalForm(output), canonicalForm(input));
}

TEST(Connectivity, ClosedManifoldMeshes) {
  expectExactRoundTrip(torusMesh(12, 20));
  expectExactRoundTrip(sphereMesh(9, 14));
}

// Every prediction path runs, and the decoder takes the same paths as the
// encoder (its counters come from its own replay of the stream).
TEST(Connectivity, PredictorsRunAlikeOnBothSides) {
  struct Case {
    Complex complex;
    bool surface;
  };
  const Case cases[] = {{sphereMesh(12, 18), true}, {gridWithHoles(16), true}, {tetrahedralBlock(4, 5), false}};
  for (const Case& c : cases) {
    EncodeOptions options;
    options.bits = 12;
    EncodeResult encoded;
    roundTrip(c.complex, options, &encoded);
    Decoder decoder;
    ASSERT_TRUE(decoder.push(encoded.bytes.data(), encoded.bytes.size()).ok());
    const ConnectivityStatistics& mine = encoded.statistics;
    const ConnectivityStatistics theirs = decoder.statistics();
    EXPECT_GT(mine.edgeCodesByDirection, 0u);
    EXPECT_GT(mine.countPredictions, 0u);
    EXPECT_GT(mine.positionPredictions, 0u);
    EXPECT_EQ(theirs.edgeCodesByDirection, mine.edgeCodesByDirection);
    EXPECT_EQ(theirs.countPredictions, mine.countPredictions);
    EXPECT_EQ(theirs.positionPredictions, mine.positionPredictions);
    EXPECT_EQ(theirs.parallelogramPredictions, mine.parallelogramPredictions);
    EXPECT_EQ(theirs.edgeExpansions, mine.edgeExpansions);
    EXPECT_EQ(theirs.pairedTriangles, mine.pairedTriangles);
    EXPECT_EQ(theirs.closedFanEdgeCodes, mine.closedFanEdgeCodes);
    EXPECT_EQ(theirs.cutCandidatePairs, mine.cutCandidatePairs);
    EXPECT_EQ(theirs.refinedNeighbourPredictions, mine.refinedNeighbourPredictions);
    // Cells split level by level: about half a vertex's neighbours split
    // before it, some in its own slab.
    EXPECT_GT(mine.refinedNeighbourPredictions * 10, mine.positionPredictions + mine.countPredictions);
    // Surfaces split mostly by edge expansions; tetrahedral meshes have
    // triangles between cut edges.
    if (c.surface) {
      EXPECT_GT(mine.edgeExpansions * 2, mine.vertexSplits);
      // Most vertices of a surface have triangles across their link.
      EXPECT_GT(mine.parallelogramPredictions * 2, mine.positionPredictions + mine.countPredictions);
      // Inner vertices of a surface have closed fans, and their edge
      // expansions leave two cut candidates between a 1 and a 2.
      EXPECT_GT(mine.closedFanEdgeCodes, 0u);
      EXPECT_GT(mine.cutCandidatePairs, 0u);
    } else {
      EXPECT_GT(mine.pairedTriangles, 0u);
    }
  }
}

// A stream coded for fast decoding predicts one-vertex splits and cell
// counts from the neighbours along the split axis alone (no parallelogram,
// no proxy), on both sides alike, and still round-trips every kind of
// complex, in every prefix.
TEST(Connectivity, FastDecodeStreamsRoundTripWithAxialPredictionsAlone) {
  EncodeOptions fast = exact();
  fast.fastDecode = true;
  Complex mixed = tetrahedralBlock(1, 9);
  const std::vector<float> extra = uniformCloud(8, 11, 3.f);
  mixed.positions.insert(mixed.positions.end(), extra.begin(), extra.end());
  mixed.triangles.insert(mixed.triangles.end(), {0, 8, 9, 9, 10, 11});
  mixed.edges.insert(mixed.edges.end(), {11, 12, 7, 13});
  mixed.points.push_back(14);
  const Complex shapes[] = {torusMesh(12, 20), gridWithHoles(16), tetrahedralBlock(4, 3), mixed,
                            randomComplex(77, 40, 60)};
  for (const Complex& shape : shapes) {
    EncodeResult encoded;
    const Complex output = roundTrip(shape, fast, &encoded);
    EXPECT_EQ(output.vertexCount(), shape.vertexCount());
    EXPECT_EQ(canonicalForm(output), canonicalForm(shape));
    Decoder decoder;
    ASSERT_TRUE(decoder.push(encoded.bytes.data(), encoded.bytes.size()).ok());
    EXPECT_TRUE(decoder.header().fastDecode);
    const ConnectivityStatistics& mine = encoded.statistics;
    const ConnectivityStatistics theirs = decoder.statistics();
    EXPECT_GT(mine.vertexSplits, 0u);
    EXPECT_GT(mine.positionPredictions, 0u);
    EXPECT_GT(mine.countPredictions, 0u);
    EXPECT_EQ(mine.parallelogramPredictions + mine.proxyPredictions, 0u);
    EXPECT_EQ(theirs.parallelogramPredictions + theirs.proxyPredictions, 0u);
    EXPECT_EQ(theirs.positionPredictions, mine.positionPredictions);
    EXPECT_EQ(theirs.countPredictions, mine.countPredictions);
    EXPECT_EQ(theirs.refinedNeighbourPredictions, mine.refinedNeighbourPredictions);
    EXPECT_EQ(theirs.vertexSplits, mine.vertexSplits);
    EXPECT_EQ(theirs.edgeExpansions, mine.edgeExpansions);
    EXPECT_EQ(theirs.fanExpansions, mine.fanExpansions);
    EXPECT_LE(mine.fanExpansions, mine.edgeExpansions);
  }
  for (uint32_t seed = 1; seed <= 40; ++seed) {
    const Complex c = randomComplex(seed, 4 + int(seed % 23), 1 + int(seed % 41));
    SCOPED_TRACE(seed);
    EXPECT_EQ(canonicalForm(roundTrip(c, fast)), canonicalForm(c));
    if (HasFailure()) break;
  }
  // The full neighbourhood is what the default stream saves bits with.
  EncodeOptions grid;
  grid.bits = 12;
  EncodeOptions gridFast = grid;
  gridFast.fastDecode = true;
  const Complex torus = torusMesh(24, 40);
  const EncodeResult full = encode(torus, grid), axial = encode(torus, gridFast);
  EXPECT_LT(full.bytes.size(), axial.bytes.size());
  // The same splits either way; the fast coding codes most of the closed
  // fans' edge expansions by their two cuts, the default coding none.
  EXPECT_EQ(axial.statistics.codes, full.statistics.codes);
  EXPECT_EQ(axial.statistics.edgeExpansions, full.statistics.edgeExpansions);
  EXPECT_EQ(full.statistics.fanExpansions, 0u);
  EXPECT_GT(axial.statistics.fanExpansions * 4, axial.statistics.edgeExpansions * 3);
  fast.chunkBytes = 64;
  expectPrefixesAreProjections(torusMesh(14, 22), fast);
  expectPrefixesAreProjections(tetrahedralBlock(3, 5), fast);
}

TEST(Connectivity, OpenMeshWithHoles) { expectExactRoundTrip(gridWithHoles(18)); }

TEST(Connectivity, NonManifoldEdgesAndVertexTouchingSheets) {
  Complex c;
  // Four triangles on the edge (0, 1), a fin, and two sheets touching at vertex 0.
  c.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0.5f, 0.5f, 0.5f,
                 -1, -1, -1, -2, -1, -1, -1, -2, -1};
  c.triangles = {0, 1, 2, 1, 0, 3, 0, 1, 4, 1, 0, 5, 0, 6, 7, 0, 8, 6};
  expectExactRoundTrip(c);
}

TEST(Connectivity, TriangleSoupWithDuplicatedVertices) {
  // Every triangle has its own three vertices, many at shared positions.
  const Complex mesh = sphereMesh(7, 10);
  Complex soup;
  for (uint32_t v : mesh.triangles) {
    soup.positions.insert(soup.positions.end(), &mesh.positions[3 * v], &mesh.positions[3 * v] + 3);
    soup.triangles.push_back(uint32_t(soup.triangles.size()));
  }
  expectExactRoundTrip(soup);
}

TEST(Connectivity, PolylinesAndIsolatedPoints) {
  Complex c;
  c.positions = uniformCloud(60, 5);
  for (uint32_t i = 0; i + 1 < 30; ++i) c.edges.insert(c.edges.end(), {i, i + 1});
  c.edges.insert(c.edges.end(), {29, 0, 35, 36, 36, 37});  // a loop and a separate polyline
  expectExactRoundTrip(c);  // vertices 30..34 and 38..59 are isolated points
}

// Points in no simplex on a surface (as in the holes of a scan) are
// predicted from the vertex they split from; encoder and decoder agree.
TEST(Connectivity, PointsInNoSimplexOnASurface) {
  Complex c = sphereMesh(16, 24);
  const uint32_t meshVertices = uint32_t(c.vertexCount());
  const std::vector<float> cloud = uniformCloud(40, 17, 2.f);
  for (size_t i = 0; i + 2 < cloud.size(); i += 3) {
    const float x = cloud[i] - 1, y = cloud[i + 1] - 1, z = cloud[i + 2] - 1;
    const float length = std::sqrt(x * x + y * y + z * z);
    if (length > 0) c.positions.insert(c.positions.end(), {x / length, y / length, z / length});
  }
  ASSERT_GT(c.vertexCount(), meshVertices + 5);
  expectExactRoundTrip(c);
  EncodeOptions options;
  options.bits = 12;
  EncodeResult encoded;
  roundTrip(c, options, &encoded);
  Decoder decoder;
  ASSERT_TRUE(decoder.push(encoded.bytes.data(), encoded.bytes.size()).ok());
  EXPECT_GT(encoded.statistics.proxyPredictions, 0u);
  EXPECT_EQ(decoder.statistics().proxyPredictions, encoded.statistics.proxyPredictions);
}

TEST(Connectivity, TetrahedralMesh) { expectExactRoundTrip(tetrahedralBlock(4, 3)); }

TEST(Connectivity, MixedDimensions) {
  Complex c = tetrahedralBlock(1, 9);  // 8 vertices, 6 tetrahedra
  const uint32_t base = uint32_t(c.vertexCount());
  const std::vector<float> extra = uniformCloud(8, 11, 3.f);
  c.positions.insert(c.positions.end(), extra.begin(), extra.end());
  c.triangles.insert(c.triangles.end(), {0, base, base + 1, base + 1, base + 2, base + 3});
  c.edges.insert(c.edges.end(), {base + 3, base + 4, 7, base + 5});
  c.points.push_back(base + 6);
  expectExactRoundTrip(c);
}

TEST(Connectivity, CoincidentVerticesAreSeparatedByConnectivity) {
  // Quantized to 2 bits, this mesh has many vertices per grid point.
  const Complex mesh = torusMesh(10, 16);
  EncodeOptions o;
  o.bits = 2;
  const Complex output = roundTrip(mesh, o);
  EXPECT_EQ(output.vertexCount(), mesh.vertexCount());
  EXPECT_EQ(output.simplexCount(2), mesh.simplexCount(2));
}

TEST(Connectivity, RandomComplexesProperty) {
  for (uint32_t seed = 1; seed <= 150; ++seed) {
    const Complex c = randomComplex(seed, 4 + int(seed % 23), 1 + int(seed % 41));
    SCOPED_TRACE(seed);
    // Grid positions on 8 values per axis: coincident vertices abound.
    expectExactRoundTrip(c);
    if (HasFailure()) break;
  }
}

TEST(Connectivity, RepairsAreCounted) {
  Complex c;
  c.positions = uniformCloud(6, 2);
  c.triangles = {0, 1, 2, 2, 0, 1, 0, 0, 3, 3, 4, 5};  // a duplicate (rotated) and a degenerate
  c.edges = {0, 1, 4, 5, 1, 3};                        // two faces of triangles, one new edge
  c.points = {0, 3};
  EncodeResult encoded = encode(c, exact());
  ASSERT_TRUE(encoded.status.ok()) << encoded.status.message;
  EXPECT_EQ(encoded.repairs.duplicate[2], 1u);
  EXPECT_EQ(encoded.repairs.degenerate[2], 1u);
  EXPECT_EQ(encoded.repairs.redundant[1], 2u);
  EXPECT_EQ(encoded.repairs.redundant[0], 2u);
  Complex output;
  ASSERT_TRUE(decode(encoded.bytes.data(), encoded.bytes.size(), output).ok());
  EXPECT_EQ(output.simplexCount(2), 2u);
  EXPECT_EQ(output.simplexCount(1), 1u);
  EXPECT_EQ(canonicalForm(output), canonicalForm(c));
}

TEST(Connectivity, BadIndicesAreRejected) {
  Complex c;
  c.positions = uniformCloud(3, 1);
  c.triangles = {0, 1, 7};
  const EncodeResult r = encode(c);
  EXPECT_EQ(r.status.code, ErrorCode::InvalidInput);
  EXPECT_NE(r.status.message.find("triangle 0 refers to vertex 7"), std::string::npos) << r.status.message;
}

// Coarse vertices placed on their neighbours' planes stay in their cells
// (within the decoder's error bound of every input vertex they stand for),
// lie closer to the vertices they stand for than cell centres, on the
// whole, and leave the complete model exact.
TEST(CoarsePlacement, PredictedVerticesStayInTheirCellsAndComeCloserToTheModel) {
  for (const bool exactFloats : {false, true}) {
    SCOPED_TRACE(exactFloats ? "float32" : "12-bit grid");
    EncodeOptions o;
    o.bits = 12;
    o.exact = exactFloats;
    o.chunkBytes = 512;
    const EncodeResult encoded = encode(sphereMesh(60, 120), o);
    ASSERT_TRUE(encoded.status.ok()) << encoded.status.message;
    DecoderOptions centres;
    centres.coarsePlacement = CoarsePlacement::CellCentre;
    Decoder full;
    ASSERT_TRUE(full.push(encoded.bytes.data(), encoded.bytes.size()).ok());
    const Complex final = full.snapshot();
    const std::vector<uint32_t> parents = full.vertexParents();
    double predictedError = 0, centreError = 0;
    size_t prefixes = 0;
    uint64_t pushed = 0;
    // One decoder of each kind, fed chunk by chunk: every prefix, in
    // linear time.
    Decoder predicted, centred(centres);
    for (const ChunkInfo& chunk : full.chunks()) {
      ASSERT_TRUE(predicted.push(encoded.bytes.data() + pushed, size_t(chunk.offset - pushed)).ok());
      ASSERT_TRUE(centred.push(encoded.bytes.data() + pushed, size_t(chunk.offset - pushed)).ok());
      pushed = chunk.offset;
      if (!predicted.hasHeader()) continue;
      const Complex p = predicted.snapshot(), c = centred.snapshot();
      ASSERT_EQ(p.vertexCount(), c.vertexCount());
      EXPECT_EQ(p.triangles, c.triangles);
      const double bound = predicted.errorBound();
      EXPECT_LE(bound, 2 * centred.errorBound() * (1 + 1e-9));
      const uint32_t count = uint32_t(p.vertexCount());
      for (uint32_t v = 0; v < final.vertexCount(); ++v) {
        uint32_t a = v;
        while (a >= count) a = parents[a];
        double squaredToPredicted = 0, squaredToCentre = 0;
        for (size_t k = 0; k < 3; ++k) {
          const double exactCoordinate = final.positions[3 * v + k];
          squaredToPredicted += std::pow(exactCoordinate - p.positions[3 * a + k], 2);
          squaredToCentre += std::pow(exactCoordinate - c.positions[3 * a + k], 2);
        }
        ASSERT_LE(std::sqrt(squaredToPredicted), bound * (1 + 1e-6) + 1e-9) << "vertex " << v;
        predictedError += std::sqrt(squaredToPredicted);
        centreError += std::sqrt(squaredToCentre);
      }
      ++prefixes;
    }
    EXPECT_GT(prefixes, 10u);
    EXPECT_LT(predictedError, centreError);
    Decoder completeCentred(centres);
    ASSERT_TRUE(completeCentred.push(encoded.bytes.data(), encoded.bytes.size()).ok());
    EXPECT_EQ(completeCentred.snapshot().positions, final.positions);
  }
}

// Splits whose stars hold over a thousand simplices take the indexed paths of
// the orientation vote and of the snapshots' face tests.
TEST(Connectivity, StarsOfOverAThousandSimplicesRoundTripInEveryPrefix) {
  EncodeOptions o = exact();
  o.chunkBytes = 256;
  for (const bool solid : {false, true}) {
    const Complex input = doubleFan(600, solid);
    const EncodeResult encoded = encode(input, o);
    ASSERT_TRUE(encoded.status.ok()) << encoded.status.message;
    Complex output;
    ASSERT_TRUE(decode(encoded.bytes.data(), encoded.bytes.size(), output).ok());
    EXPECT_EQ(canonicalForm(output), canonicalForm(input)) << (solid ? "tetrahedra" : "triangles");
    expectPrefixesAreProjections(input, o);
  }
}

TEST(Connectivity, EveryChunkPrefixIsTheProjectionOfTheInput) {
  EncodeOptions o = exact();
  o.chunkBytes = 64;
  expectPrefixesAreProjections(torusMesh(14, 22), o);
  expectPrefixesAreProjections(tetrahedralBlock(3, 5), o);
  expectPrefixesAreProjections(randomComplex(77, 40, 60), o);
  o.exact = false;
  o.bits = 3;  // coincident vertices: the prefix after the geometric levels
  expectPrefixesAreProjections(randomComplex(78, 40, 60), o);
}

}  // namespace
}  // namespace kdmesh::test
