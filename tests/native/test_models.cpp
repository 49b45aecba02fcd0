// Round trips of real models: the paper's triceratops and fandisk (unpacked
// from Debian's libcgal-demo into build/models by scripts/models.sh) and the
// Stanford bunny from ../shared/models when that directory is present.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "complexes.h"
#include "kdmesh/io.h"
#include "kdmesh/kdmesh.h"

namespace kdmesh::test {
namespace {

bool exists(const std::string& path) { return std::ifstream(path).good(); }

Complex readModel(const std::string& path) {
  Complex c;
  io::Notes notes;
  const Status status = io::readFile(path, c, notes);
  EXPECT_TRUE(status.ok()) << path << ": " << status.message;
  return c;
}

// The grid positions the codec gives back for `bits` (docs/FORMAT.md).
Complex snapped(Complex c, int bits) {
  std::array<float, 3> lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < c.positions.size(); ++i) {
    lo[i % 3] = std::min(lo[i % 3], c.positions[i]);
    hi[i % 3] = std::max(hi[i % 3], c.positions[i]);
  }
  double longest = 0;
  for (int a = 0; a < 3; ++a) longest = std::max(longest, double(hi[a]) - double(lo[a]));
  const double step = longest / double((1u << bits) - 1);
  for (size_t i = 0; i < c.positions.size(); ++i) {
    const double q = double(std::llround((double(c.positions[i]) - double(lo[i % 3])) / step));
    c.positions[i] = float(double(lo[i % 3]) + q * step);
  }
  return c;
}

void expectRoundTrips(const Complex& model, int bits, bool checkPrefixes = true) {
  ASSERT_GT(model.simplexCount(2) + model.simplexCount(3), 0u);
  for (const bool exact : {true, false}) {
    EncodeOptions o;
    o.exact = exact;
    o.bits = bits;
    const EncodeResult encoded = encode(model, o);
    ASSERT_TRUE(encoded.status.ok()) << encoded.status.message;
    Complex decoded;
    const Status status = decode(encoded.bytes.data(), encoded.bytes.size(), decoded);
    ASSERT_TRUE(status.ok()) << status.message;
    ASSERT_EQ(decoded.vertexCount(), model.vertexCount());
    EXPECT_EQ(canonicalForm(decoded), canonicalForm(exact ? model : snapped(model, bits)))
        << (exact ? "exact" : "grid");
    if (!exact && checkPrefixes) expectPrefixesAreProjections(model, o);
  }
}

TEST(Models, Triceratops) {
  const std::string path = std::string(KDMESH_MODELS_DIR) + "/triceratops.off";
  ASSERT_TRUE(exists(path)) << path << " is missing: run scripts/models.sh";
  const Complex model = readModel(path);
  EXPECT_EQ(model.vertexCount(), 2832u);
  expectRoundTrips(model, 12);
}

TEST(Models, Fandisk) {
  const std::string path = std::string(KDMESH_MODELS_DIR) + "/fandisk.off";
  ASSERT_TRUE(exists(path)) << path << " is missing: run scripts/models.sh";
  const Complex model = readModel(path);
  EXPECT_EQ(model.vertexCount(), 6475u);
  expectRoundTrips(model, 10);
}

TEST(Models, DelaunayTetrahedralizationOfRandomPoints) {
  // Made by TetGen in scripts/models.sh: 10,000 points in a ball.
  const std::string path = std::string(KDMESH_MODELS_DIR) + "/ball10k.1.ele";
  ASSERT_TRUE(exists(path)) << path << " is missing: run scripts/models.sh";
  const Complex model = readModel(path);
  EXPECT_EQ(model.vertexCount(), 10000u);
  EXPECT_GT(model.simplexCount(3), 60000u);
  expectRoundTrips(model, 16, /*checkPrefixes=*/false);  // tetrahedral prefixes: Connectivity tests
}

TEST(Models, Bunny) {
  const std::string path = std::string(KDMESH_SHARED_MODELS) + "/bunny.obj";
  if (!exists(path)) GTEST_SKIP() << path << " not present";
  const Complex model = readModel(path);
  EXPECT_EQ(model.vertexCount(), 35947u);
  expectRoundTrips(model, 12);
}

}  // namespace
}  // namespace kdmesh::test
