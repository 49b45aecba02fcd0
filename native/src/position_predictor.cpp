#include "position_predictor.h"

#include "model_priors.h"

#include <cmath>

namespace kdmesh {
namespace {

constexpr int kScaleClasses = 5;
constexpr int kTiltClasses = 5;  // the last: no plane
constexpr int kOutsideClasses = 2;
constexpr int kPlaneBuckets = 6;
constexpr int kCentroidBuckets = 10;

// The root mean square neighbour distance in half widths of the cell, from
// its square.
int scaleClass(double r) {
  static constexpr double kBounds[kScaleClasses - 1] = {4, 16, 64, 256};
  return countAtMost(r, kBounds);
}

// The plane's rise across the cell along the other axes, against its rise
// along the split axis.
int tiltClass(double tilt) {
  static constexpr double kBounds[kTiltClasses - 2] = {0.3, 1, 3};
  return countAtMost(tilt, kBounds);
}

// Offsets from the split plane in half widths; the plane's is >= 0 after
// mirroring, the centroid's may have either sign.
int planeBucket(double t) {
  static constexpr double kBounds[kPlaneBuckets - 1] = {0.25, 0.5, 1, 2, 4};
  return countAtMost(t, kBounds);
}

int centroidBucket(double t) {
  static constexpr double kBounds[kCentroidBuckets - 1] = {-2, -1, -0.5, -0.25, 0, 0.25, 0.5, 1, 2};
  return countAtMost(t, kBounds);
}

}  // namespace

PositionPredictor::PositionPredictor(const SplitSchedule& schedule)
    : axis_(schedule.axis),
      models_(size_t(kOutsideClasses) * kScaleClasses * kTiltClasses * kPlaneBuckets * kCentroidBuckets),
      planeModels_(size_t(kOutsideClasses) * kScaleClasses * kTiltClasses * kPlaneBuckets),
      centroidModels_(size_t(kScaleClasses) * kCentroidBuckets),
      // The joint model is the sharpest; the others help while it learns.
      mixer_(kScaleClasses, {39322, 19661, 19661}) {
  static_assert(size_t(kOutsideClasses) * kScaleClasses * kTiltClasses * kPlaneBuckets * kCentroidBuckets ==
                kFamilySize[int(ModelFamily::OneVertexSplits)]);
  static_assert(size_t(kOutsideClasses) * kScaleClasses * kTiltClasses * kPlaneBuckets ==
                kFamilySize[int(ModelFamily::OneVertexByPlane)]);
  static_assert(size_t(kScaleClasses) * kCentroidBuckets == kFamilySize[int(ModelFamily::OneVertexByCentroid)]);
  primeModels(ModelFamily::OneVertexSplits, models_.data());
  primeModels(ModelFamily::OneVertexByPlane, planeModels_.data());
  primeModels(ModelFamily::OneVertexByCentroid, centroidModels_.data());
  widths_.resize(size_t(schedule.levels) + 1);
  for (size_t level = 0; level < widths_.size(); ++level)
    for (int a = 0; a < 3; ++a)
      widths_[level][size_t(a)] = std::ldexp(1.0, schedule.bits[size_t(a)] - schedule.consumed[level][size_t(a)]);
}

namespace {

// Turns per-vertex counts in first[v + 1] into row starts.
void startRows(std::vector<uint32_t>& first) {
  for (size_t v = 1; v < first.size(); ++v) first[v] += first[v - 1];
}

// After a fill that advanced each row start to the next row's, shifts the
// starts back.
void restoreRows(std::vector<uint32_t>& first) {
  for (size_t v = first.size() - 1; v > 0; --v) first[v] = first[v - 1];
  first[0] = 0;
}

}  // namespace

void PositionPredictor::snapshotNeighbours(const SimplexStore& store, uint64_t splits) {
  if (splits == snapshotSplits_) return;
  snapshotSplits_ = splits;
  const size_t rows = places_.size() + 1;
  firstWing_.assign(rows, 0);
  const uint32_t triangles = store.size(2);
  for (uint32_t triangle = 0; triangle < triangles; ++triangle) {
    const uint32_t* v = store.vertices(2, triangle);
    for (int i = 0; i < 3; ++i) ++firstWing_[v[i] + 1];
  }
  startRows(firstWing_);
  wings_.resize(size_t(firstWing_.back()) * 2);
  for (uint32_t triangle = 0; triangle < triangles; ++triangle) {
    const uint32_t* v = store.vertices(2, triangle);
    // The winding: the tuple, or with its first two swapped when flipped.
    const bool flipped = store.flags(2, triangle) & SimplexStore::kFlipped;
    const uint32_t w0 = v[flipped ? 1 : 0], w1 = v[flipped ? 0 : 1], w2 = v[2];
    const auto addWing = [&](uint32_t at, uint32_t a, uint32_t b) {
      uint32_t* wing = &wings_[size_t(firstWing_[at]++) * 2];
      wing[0] = a;
      wing[1] = b;
    };
    addWing(w0, w1, w2);
    addWing(w1, w2, w0);
    addWing(w2, w0, w1);
  }
  restoreRows(firstWing_);

  auto wingless = [&](uint32_t v) { return firstWing_[v] == firstWing_[v + 1]; };
  firstNeighbour_.assign(rows, 0);
  const uint32_t edges = store.size(1);
  for (uint32_t edge = 0; edge < edges; ++edge) {
    const uint32_t* v = store.vertices(1, edge);
    for (int i = 0; i < 2; ++i) firstNeighbour_[v[i] + 1] += wingless(v[i]);
  }
  startRows(firstNeighbour_);
  neighbours_.resize(firstNeighbour_.back());
  // Meshes: every vertex with an edge has a triangle.
  for (uint32_t edge = 0; edge < edges && !neighbours_.empty(); ++edge) {
    const uint32_t* v = store.vertices(1, edge);
    for (int i = 0; i < 2; ++i)
      if (wingless(v[i])) neighbours_[firstNeighbour_[v[i]]++] = v[1 - i];
  }
  restoreRows(firstNeighbour_);
}

PositionPredictor::Features PositionPredictor::features(const Neighbourhood& around, int level) const {
  Features f;
  const int axis = axis_[size_t(level)];
  double halfWidth[3];
  for (int a = 0; a < 3; ++a) halfWidth[a] = widths_[size_t(level)][size_t(a)] * 0.5;
  const double inverse = 1.0 / double(around.count);
  double centroid[3];  // relative to the cell centre
  for (int a = 0; a < 3; ++a) centroid[a] = around.sum[a] * inverse;
  f.meanSquaredDistance = around.squaredDistance * inverse / (halfWidth[axis] * halfWidth[axis]);
  f.centroidOffset = centroid[axis] / halfWidth[axis];
  const double* normal = around.normal;
  const double along = std::fabs(normal[axis]) * halfWidth[axis];
  if (along > 0) {
    // The plane n·(x − centroid) = 0 meets the split axis through the cell
    // centre (the origin here) at x_axis = n·centroid / n_axis.
    double across = 0, rise = 0;
    for (int a = 0; a < 3; ++a) {
      rise += normal[a] * centroid[a];
      if (a != axis) across += std::fabs(normal[a]) * halfWidth[a];
    }
    f.planeOffset = rise / (normal[axis] * halfWidth[axis]);
    f.tilt = across / along;
    f.hasPlane = true;
  }
  f.mirrored = (f.hasPlane ? f.planeOffset : f.centroidOffset) < 0;
  f.outsideUp = around.oriented && f.hasPlane && (normal[axis] > 0) != f.mirrored;
  if (f.mirrored) {
    f.planeOffset = -f.planeOffset;
    f.centroidOffset = -f.centroidOffset;
  }
  return f;
}

bool PositionPredictor::gather(uint32_t vertex, Neighbourhood& around) const {
  if (size_t(vertex) + 1 >= firstWing_.size()) return false;
  // Scalars rather than arrays: these loops, the decoder's hottest, stalled
  // on store-to-load forwarding with array temporaries.
  const double* at = places_[vertex].centre;
  const double atX = at[0], atY = at[1], atZ = at[2];
  double sumX = 0, sumY = 0, sumZ = 0, normalX = 0, normalY = 0, normalZ = 0, squared = 0;
  const uint32_t wingCount = firstWing_[vertex + 1] - firstWing_[vertex];
  if (wingCount > 0) {
    // Each wing adds both its vertices (a closed fan thus counts every
    // neighbour twice) and the cross product of their offsets.
    const uint32_t* wing = wings_.data() + size_t(firstWing_[vertex]) * 2;
    for (uint32_t i = 0; i < wingCount; ++i, wing += 2) {
      const double* a = places_[wing[0]].centre;
      const double* b = places_[wing[1]].centre;
      const double ax = a[0] - atX, ay = a[1] - atY, az = a[2] - atZ;
      const double bx = b[0] - atX, by = b[1] - atY, bz = b[2] - atZ;
      sumX += ax + bx;
      sumY += ay + by;
      sumZ += az + bz;
      squared += ax * ax + ay * ay + az * az + bx * bx + by * by + bz * bz;
      normalX += ay * bz - az * by;
      normalY += az * bx - ax * bz;
      normalZ += ax * by - ay * bx;
    }
    around = {{sumX, sumY, sumZ}, {normalX, normalY, normalZ}, squared, 2 * wingCount, true};
    return true;
  }
  const uint32_t* neighbour = neighbours_.data() + firstNeighbour_[vertex];
  const uint32_t count = firstNeighbour_[vertex + 1] - firstNeighbour_[vertex];
  if (count == 0) return false;
  double previousX = 0, previousY = 0, previousZ = 0;  // the first cross product is zero
  for (uint32_t i = 0; i < count; ++i) {
    const double* centre = places_[neighbour[i]].centre;
    const double x = centre[0] - atX, y = centre[1] - atY, z = centre[2] - atZ;
    sumX += x;
    sumY += y;
    sumZ += z;
    squared += x * x;
    squared += y * y;
    squared += z * z;
    const double crossX = previousY * z - previousZ * y;
    const double crossY = previousZ * x - previousX * z;
    const double crossZ = previousX * y - previousY * x;
    // copysign, not a branch: the signs are a coin toss for the branch predictor.
    const double sign = std::copysign(1.0, crossX * normalX + crossY * normalY + crossZ * normalZ);
    normalX += sign * crossX;
    normalY += sign * crossY;
    normalZ += sign * crossZ;
    previousX = x;
    previousY = y;
    previousZ = z;
  }
  around = {{sumX, sumY, sumZ}, {normalX, normalY, normalZ}, squared, count, false};
  return true;
}

bool PositionPredictor::contextsOf(uint32_t vertex, int level, SingleContexts& c) {
  Neighbourhood around;
  if (!gather(vertex, around)) return false;
  ++positionPredictions_;
  const Features f = features(around, level);
  c.mirrored = f.mirrored;
  const int tilt = f.hasPlane ? tiltClass(f.tilt) : kTiltClasses - 1;
  const int scale = scaleClass(f.meanSquaredDistance);
  c.plane = ((f.outsideUp * kScaleClasses + scale) * kTiltClasses + tilt) * kPlaneBuckets + planeBucket(f.planeOffset);
  c.joint = c.plane * kCentroidBuckets + centroidBucket(f.centroidOffset);
  c.centroid = scale * kCentroidBuckets + centroidBucket(f.centroidOffset);
  c.mixerSet = scale;
  return true;
}

CountContext PositionPredictor::countContext(uint32_t vertex, int level) {
  Neighbourhood around;
  if (!gather(vertex, around)) return {};
  ++countPredictions_;
  const Features f = features(around, level);
  if (!f.hasPlane) {
    const double c = f.centroidOffset;
    return {c < 0.5 ? 10 : c < 1.5 ? 11 : 12, f.mirrored};
  }
  // The plane meets the cell's column along the split axis between
  // planeOffset - tilt and planeOffset + tilt (in half widths).
  const double low = f.planeOffset - f.tilt, high = f.planeOffset + f.tilt;
  if (low > 0) {
    // It stays in the upper half: how close it comes to the split plane.
    return {low < 0.5 ? 6 : low < 1 ? 7 : low < 2 ? 8 : 9, f.mirrored};
  }
  // It crosses the split plane: which share of its span inside the cell
  // lies in the lower half (at most about a half, since mirrored).
  const double inside = std::min(high, 1.0) - std::max(low, -1.0);
  const double below = std::min(high, 0.0) - std::max(low, -1.0);
  static constexpr double kShareBounds[4] = {0.08, 0.2, 0.32, 0.44};
  return {1 + countAtMost(inside > 0 && below > 0 ? below / inside : 0.0, kShareBounds), f.mirrored};
}

}  // namespace kdmesh
