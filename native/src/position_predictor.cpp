#include "position_predictor.h"

#include <cmath>

namespace kdmesh {
namespace {

constexpr int kScaleClasses = 5;
constexpr int kTiltClasses = 5;  // the last: no plane
constexpr int kPlaneBuckets = 6;
constexpr int kCentroidBuckets = 10;

// The root mean square neighbour distance in half widths of the cell, from
// the squares.
int scaleClass(double meanSquaredDistance, double halfWidth) {
  const double r = meanSquaredDistance / (halfWidth * halfWidth);
  return r < 4 ? 0 : r < 16 ? 1 : r < 64 ? 2 : r < 256 ? 3 : 4;
}

// The plane's rise across the cell along the other axes, against its rise
// along the split axis.
int tiltClass(double tilt) { return tilt < 0.3 ? 0 : tilt < 1 ? 1 : tilt < 3 ? 2 : 3; }

// Offsets from the split plane in half widths; the plane's is >= 0 after
// mirroring, the centroid's may have either sign.
int planeBucket(double t) {
  return t < 0.25 ? 0 : t < 0.5 ? 1 : t < 1 ? 2 : t < 2 ? 3 : t < 4 ? 4 : 5;
}

int centroidBucket(double t) {
  static constexpr double kBounds[kCentroidBuckets - 1] = {-2, -1, -0.5, -0.25, 0, 0.25, 0.5, 1, 2};
  int bucket = 0;
  while (bucket < kCentroidBuckets - 1 && t >= kBounds[bucket]) ++bucket;
  return bucket;
}

}  // namespace

PositionPredictor::PositionPredictor(const SplitSchedule& schedule)
    : axis_(schedule.axis),
      models_(size_t(kScaleClasses) * kTiltClasses * kPlaneBuckets * kCentroidBuckets) {
  width_.resize(size_t(schedule.levels) + 1);
  for (size_t level = 0; level < width_.size(); ++level)
    for (int a = 0; a < 3; ++a)
      width_[level][size_t(a)] =
          std::ldexp(1.0, schedule.bits[size_t(a)] - schedule.consumed[level][size_t(a)]);
}

void PositionPredictor::centre(const Place& place, double out[3]) const {
  const std::array<double, 3>& width = width_[place.level];
  for (int a = 0; a < 3; ++a) out[a] = double(place.prefix[a]) * width[size_t(a)] + (width[size_t(a)] - 1) * 0.5;
}

void PositionPredictor::beginSingles(const SimplexStore& store) {
  const uint32_t vertexCount = uint32_t(places_.size());
  firstNeighbour_.assign(size_t(vertexCount) + 1, 0);
  const uint32_t edges = store.size(1);
  for (uint32_t edge = 0; edge < edges; ++edge) {
    const uint32_t* v = store.vertices(1, edge);
    ++firstNeighbour_[v[0] + 1];
    ++firstNeighbour_[v[1] + 1];
  }
  for (uint32_t v = 0; v < vertexCount; ++v) firstNeighbour_[v + 1] += firstNeighbour_[v];
  neighbours_.resize(firstNeighbour_[vertexCount]);
  for (uint32_t edge = 0; edge < edges; ++edge) {
    const uint32_t* v = store.vertices(1, edge);
    neighbours_[firstNeighbour_[v[0]]++] = v[1];
    neighbours_[firstNeighbour_[v[1]]++] = v[0];
  }
  // The fill advanced each start to the next row's; shift them back.
  for (uint32_t v = vertexCount; v > 0; --v) firstNeighbour_[v] = firstNeighbour_[v - 1];
  firstNeighbour_[0] = 0;
}

int PositionPredictor::contextOf(uint32_t vertex, int level, bool& mirrored) {
  const uint32_t* neighbour = neighbours_.data() + firstNeighbour_[vertex];
  const uint32_t count = firstNeighbour_[vertex + 1] - firstNeighbour_[vertex];
  if (count == 0) return -1;
  ++predicted_;
  double at[3], halfWidth[3];
  centre(places_[vertex], at);
  for (int a = 0; a < 3; ++a) halfWidth[a] = width_[size_t(level)][size_t(a)] * 0.5;
  // The plane's orientation does not matter, so neighbours need no order:
  // the normal sums the cross products of the offsets of consecutive
  // neighbours, each turned to agree with the sum so far.
  double sum[3] = {0, 0, 0}, normal[3] = {0, 0, 0}, previous[3] = {0, 0, 0}, squaredDistance = 0;
  for (uint32_t i = 0; i < count; ++i) {
    double p[3];
    centre(places_[neighbour[i]], p);
    for (int a = 0; a < 3; ++a) {
      p[a] -= at[a];
      sum[a] += p[a];
      squaredDistance += p[a] * p[a];
    }
    if (i > 0) {
      const double cross[3] = {previous[1] * p[2] - previous[2] * p[1], previous[2] * p[0] - previous[0] * p[2],
                               previous[0] * p[1] - previous[1] * p[0]};
      const double sign = cross[0] * normal[0] + cross[1] * normal[1] + cross[2] * normal[2] < 0 ? -1 : 1;
      for (int a = 0; a < 3; ++a) normal[a] += sign * cross[a];
    }
    for (int a = 0; a < 3; ++a) previous[a] = p[a];
  }
  const double inverse = 1.0 / double(count);
  double centroid[3];
  for (int a = 0; a < 3; ++a) centroid[a] = at[a] + sum[a] * inverse;
  const double spread = squaredDistance * inverse;

  const int axis = axis_[size_t(level)];
  double centroidOffset = (centroid[axis] - at[axis]) / halfWidth[axis];

  int tilt = kTiltClasses - 1;
  double planeOffset = 0;
  const double along = std::fabs(normal[axis]) * halfWidth[axis];
  if (along > 0) {
    double across = 0, f = 0;
    for (int a = 0; a < 3; ++a) {
      f += normal[a] * (at[a] - centroid[a]);
      if (a != axis) across += std::fabs(normal[a]) * halfWidth[a];
    }
    planeOffset = -f / (normal[axis] * halfWidth[axis]);
    tilt = tiltClass(across / along);
  }
  mirrored = (tilt < kTiltClasses - 1 ? planeOffset : centroidOffset) < 0;
  if (mirrored) {
    planeOffset = -planeOffset;
    centroidOffset = -centroidOffset;
  }
  const int scale = scaleClass(spread, halfWidth[axis]);
  return ((scale * kTiltClasses + tilt) * kPlaneBuckets + planeBucket(planeOffset)) * kCentroidBuckets +
         centroidBucket(centroidOffset);
}

}  // namespace kdmesh
