#include "position_predictor.h"

#include "model_priors.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace kdmesh {
namespace {

// The positions in a triangle's tuple of the vertices that follow the one
// at position p in the winding, by p and (+3) for a flipped tuple, which
// winds the other way; a table, since a branch on the flip would be
// mispredicted for half the triangles.
constexpr uint8_t kNext[6] = {1, 2, 0, 2, 0, 1}, kAfterNext[6] = {2, 0, 1, 1, 2, 0};

constexpr int kScaleClasses = 5;
constexpr int kTiltClasses = 5;  // the last: no plane
constexpr int kOutsideClasses = 2;
constexpr int kValenceClasses = 5;       // the last: no triangle
constexpr int kJointValenceClasses = 3;
constexpr int kPlaneBuckets = 6;
constexpr int kCentroidBuckets = 10;
constexpr int kParallelogramBuckets = CountContext::kParallelogramBuckets;  // the last: none
constexpr int kSpreadClasses = 9;
constexpr int kAgreementClasses = 3;
constexpr int kElongationGroups = CountContext::kElongationGroups;

// The root mean square neighbour distance in half widths of the cell, from
// its square.
int scaleClass(double r) {
  static constexpr double kBounds[kScaleClasses - 1] = {4, 16, 64, 256};
  return countAtMost(r, kBounds);
}

// How many triangles the vertex is in (≤ 4, 5, 6, ≥ 7, or none): how far
// its neighbourhood is from a regular fan, whose centroid lies where the
// vertex does. The joint model takes three groups of them.
int valenceClass(uint32_t triangles, bool inTriangles) {
  static constexpr double kBounds[kValenceClasses - 2] = {5, 6, 7};
  return inTriangles ? countAtMost(double(triangles), kBounds) : kValenceClasses - 1;
}
constexpr int kJointValence[kValenceClasses] = {0, 0, 1, 2, 2};

// The plane's rise across the cell along the other axes, against its rise
// along the split axis.
int tiltClass(double tilt) {
  static constexpr double kBounds[kTiltClasses - 2] = {0.3, 1, 3};
  return countAtMost(tilt, kBounds);
}

// How the neighbours spread along the split axis against their spread in
// all three: 3 · (squared offsets along the axis) / (squared offsets), < 0.5,
// < 1.6 or more. Neighbours strung out along the axis leave a vertex's
// position along it (or a cell's split) less certain than the other
// features say: the mixers weigh their models by it.
int elongationGroup(double squared, double along) {
  static constexpr double kBounds[kElongationGroups - 1] = {0.5, 1.6};
  return squared > 0 ? countAtMost(3 * along / squared, kBounds) : 1;
}

// Offsets from the split plane in half widths; the plane's is >= 0 after
// mirroring, the centroid's may have either sign.
int planeBucket(double t) {
  static constexpr double kBounds[kPlaneBuckets - 1] = {0.25, 0.5, 1, 2, 4};
  return countAtMost(t, kBounds);
}

// The mean parallelogram prediction's offset from the split plane in half
// widths, mirrored as the plane's.
int parallelogramBucket(double t) {
  static constexpr double kBounds[kParallelogramBuckets - 2] = {-2, -1, -0.5, -0.25, 0, 0.25, 0.5, 1, 2, 4};
  return countAtMost(t, kBounds);
}

// The squared median deviation of the parallelogram predictions along the
// split axis, in squared half widths: how far to trust their median.
int spreadClass(double spread) {
  static constexpr double kBounds[kSpreadClasses - 1] = {0.125, 0.25, 0.5, 1, 2, 4, 16, 64};
  return countAtMost(spread, kBounds);
}

}  // namespace

// Where a neighbour lies along the split axis, from its offset from the
// cell's centre in half widths of the cell: cells of this level lie 2
// apart, and one that has split at this level already 0.5 off that grid,
// in its lower or upper half. Bin 3 · (slab + 1) + (side + 1) for the
// slabs −1, 0 and 1 (the cell's own and the two beside it) and the sides
// −1 (lower half), 0 (not split yet) and 1; bin 9 for slabs farther off.
// Offsets are exact (multiples of 1/4 grid steps) and twice one is an
// integer q = 4 · slab + side of magnitude below 2^33; the three slabs
// are q = −5..6 (q = 4 · slab + 2, half a width off the grid, does not
// arise; it counts in the lower slab, not split), looked up in a table
// whose last entry, bin 9, takes every other q. Clamping the index instead
// of testing it keeps the lookup free of a branch: whether a neighbour is
// far is a coin toss for the branch predictor.
namespace {
struct AlongBins {
  int8_t bins[13] = {};
  constexpr AlongBins() {
    constexpr int kSide[4] = {0, 1, 0, -1};  // by q mod 4
    for (int q = -5; q <= 6; ++q) {
      const int slab = (q + 1 + 8) / 4 - 2;  // floor((q + 1) / 4)
      bins[q + 5] = int8_t(3 * (slab + 1) + kSide[(q + 8) % 4] + 1);
    }
    bins[12] = 9;
  }
};
constexpr AlongBins kAlongBins{};
}  // namespace

int alongBin(double offset) {
  const uint64_t index = uint64_t(int64_t(offset * 2) + 5);
  return kAlongBins.bins[std::min<uint64_t>(index, 12)];
}

namespace {

// The median of `count` sorted values: the middle one, or the mean of the
// two middle ones.
double middleOf(const double* sorted, uint32_t count) {
  const uint32_t half = count / 2;
  return count % 2 == 1 ? sorted[half] : 0.5 * (sorted[half - 1] + sorted[half]);
}

// Applies a network of comparisons to eight values, each a min and a max:
// no branch on the data, which falls either way at random. Expanded at
// compile time and inlined, so that the values stay in registers whatever
// the compiler's unrolling rules (clang, which builds the WebAssembly
// decoder, ignores GCC's unroll pragma and called a loop over memory).
template <size_t kComparisons, size_t... kIndex>
[[gnu::always_inline]] inline void applyNetwork(double (&v)[8], const uint8_t (&pairs)[kComparisons][2],
                                                std::index_sequence<kIndex...>) {
  auto compareAndSwap = [&v](size_t i, size_t j) {
    const double low = std::min(v[i], v[j]), high = std::max(v[i], v[j]);
    v[i] = low;
    v[j] = high;
  };
  (compareAndSwap(pairs[kIndex][0], pairs[kIndex][1]), ...);
}
template <size_t kComparisons>
[[gnu::always_inline]] inline void sortNetwork(double (&v)[8], const uint8_t (&pairs)[kComparisons][2]) {
  applyNetwork(v, pairs, std::make_index_sequence<kComparisons>());
}
// Any eight values (Knuth's 19 comparisons).
constexpr uint8_t kSortEight[19][2] = {{0, 2}, {1, 3}, {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6},
                                       {3, 7}, {0, 1}, {2, 3}, {4, 5}, {6, 7}, {2, 4}, {3, 5},
                                       {1, 4}, {3, 6}, {1, 2}, {3, 4}, {5, 6}};
// Any six values in the first six places (12 comparisons, the fewest).
constexpr uint8_t kSortSix[12][2] = {{0, 5}, {1, 3}, {2, 4}, {1, 2}, {3, 4}, {0, 3},
                                     {2, 5}, {0, 1}, {2, 3}, {4, 5}, {1, 2}, {3, 4}};
// Any four values in the first four places (5 comparisons).
constexpr uint8_t kSortFour[5][2] = {{0, 1}, {2, 3}, {0, 2}, {1, 3}, {1, 2}};

// The k-th least (from 1) of the values of two ascending runs: the least,
// over the ways to take k values from the runs' fronts, of the greatest
// taken. It selects one of the values, so it is exact; unrolled at compile
// time into minima and maxima.
template <int kRun, int kK>
[[gnu::always_inline]] inline double kthOfTwoRuns(const double (&a)[kRun], const double (&b)[kRun]) {
  double least = HUGE_VAL;
  for (int fromA = std::max(0, kK - kRun); fromA <= std::min(kK, kRun); ++fromA) {
    const double lastOfA = fromA > 0 ? a[fromA - 1] : -HUGE_VAL;
    const double lastOfB = kK - fromA > 0 ? b[kK - fromA - 1] : -HUGE_VAL;
    least = std::min(least, std::max(lastOfA, lastOfB));
  }
  return least;
}

// medianAndDeviation() of 2·kRun − 1 or 2·kRun values, sorted by `network`
// as 2·kRun (an odd count's last one infinite, and so its deviation).
// Sorted values fall to the median and rise after it: their deviations
// are two ascending runs, those up to the middle read backwards and those
// after it, whose middle values select the deviation.
template <int kRun, size_t kComparisons>
[[gnu::always_inline]] inline void medianAndDeviationOfFew(const double* values, uint32_t count,
                                                           const uint8_t (&network)[kComparisons][2],
                                                           double& median, double& deviation) {
  double sorted[8];
  for (uint32_t i = 0; i < 2 * kRun; ++i) sorted[i] = i < count ? values[i] : HUGE_VAL;
  sortNetwork(sorted, network);
  median = middleOf(sorted, count);
  double towardsMedian[kRun], afterMedian[kRun];
  for (int i = 0; i < kRun; ++i) {
    towardsMedian[i] = std::fabs(sorted[kRun - 1 - i] - median);
    afterMedian[i] = std::fabs(sorted[kRun + i] - median);
  }
  const double middle = kthOfTwoRuns<kRun, kRun>(towardsMedian, afterMedian);
  deviation = count == 2 * kRun ? 0.5 * (middle + kthOfTwoRuns<kRun, kRun + 1>(towardsMedian, afterMedian)) : middle;
}

}  // namespace

void medianAndDeviation(double* values, uint32_t count, double& median, double& deviation) {
  // Most vertices of a surface are in five to seven triangles.
  if (count >= 5 && count <= 6) return medianAndDeviationOfFew<3>(values, count, kSortSix, median, deviation);
  if (count >= 7 && count <= 8) return medianAndDeviationOfFew<4>(values, count, kSortEight, median, deviation);
  if (count >= 3 && count <= 4) return medianAndDeviationOfFew<2>(values, count, kSortFour, median, deviation);
  std::sort(values, values + count);
  median = middleOf(values, count);
  for (uint32_t i = 0; i < count; ++i) values[i] = std::fabs(values[i] - median);
  std::sort(values, values + count);
  deviation = middleOf(values, count);
}

namespace {

// The odds that the vertex lies in the upper half (after mirroring) by
// its parallelograms' median offset t and deviation s, in half widths, as
// a logistic of t / sqrt(s² + q): q stands for the error of the
// neighbours' own cells, which the deviation does not see when the
// predictions agree. The models bucket t and s; this input, unbucketed,
// lets the mixers weigh how far apart within a bucket they are (scale and
// q tuned on the bunny, triceratops and fandisk: docs/EXPERIMENTS.md).
uint16_t parallelogramOdds(const double offset, const double spread) {
  constexpr double kVariance = 0.15, kScale = 700;  // squared half widths; logistic units of 1/256
  const double logit = std::clamp(kScale * offset / std::sqrt(spread + kVariance), -2047.0, 2047.0);
  // Rounded half away from zero, as std::lround does, without its call:
  // the logit is clamped far inside int's range, so the truncation is
  // exact and so is the fraction it leaves.
  int rounded = int(logit);
  const double fraction = logit - rounded;
  rounded += (fraction >= 0.5) - (fraction <= -0.5);
  const uint32_t p0 = uint32_t(Logistic::squash(rounded)) << 3;
  return uint16_t(std::clamp<uint32_t>(p0, 64, kProbabilityOne - 64));
}

int centroidBucket(double t) {
  static constexpr double kBounds[kCentroidBuckets - 1] = {-2, -1, -0.5, -0.25, 0, 0.25, 0.5, 1, 2};
  return countAtMost(t, kBounds);
}

}  // namespace

PositionPredictor::PositionPredictor(const SplitSchedule& schedule, const SimplexStore& store, bool fastDecode)
    : axis_(schedule.axis),
      store_(store),
      models_(size_t(kJointValenceClasses) * kOutsideClasses * kScaleClasses * kTiltClasses * kPlaneBuckets *
              kCentroidBuckets),
      planeModels_(size_t(kOutsideClasses) * kScaleClasses * kTiltClasses * kPlaneBuckets),
      centroidModels_(size_t(kValenceClasses) * kScaleClasses * kCentroidBuckets),
      parallelogramModels_(size_t(kPlaneBuckets) * kSpreadClasses * kParallelogramBuckets),
      refinementModels_(kRefinementModels),
      alongAxisModels_(kAlongAxisModels),
      fastDecode_(fastDecode),
      mixer_(kElongationGroups * kScaleClasses * kAgreementClasses, mixerPriors(MixerFamily::OneVertexSplits)),
      parallelogramMixer_(kParallelogramBuckets, mixerPriors(MixerFamily::OneVertexByParallelogram)),
      planeAndCentroidMixer_(kCentroidBuckets * kPlaneBuckets, mixerPriors(MixerFamily::OneVertexByPlaneAndCentroid)) {
  static_assert(size_t(kJointValenceClasses) * kOutsideClasses * kScaleClasses * kTiltClasses * kPlaneBuckets *
                    kCentroidBuckets ==
                kFamilySize[int(ModelFamily::OneVertexSplits)]);
  static_assert(size_t(kOutsideClasses) * kScaleClasses * kTiltClasses * kPlaneBuckets ==
                kFamilySize[int(ModelFamily::OneVertexByPlane)]);
  static_assert(size_t(kValenceClasses) * kScaleClasses * kCentroidBuckets ==
                kFamilySize[int(ModelFamily::OneVertexByCentroid)]);
  static_assert(size_t(kPlaneBuckets) * kSpreadClasses * kParallelogramBuckets ==
                kFamilySize[int(ModelFamily::OneVertexByParallelogram)]);
  static_assert(size_t(kElongationGroups) * kScaleClasses * kAgreementClasses ==
                    kMixerSets[int(MixerFamily::OneVertexSplits)] &&
                kMixerInputs[int(MixerFamily::OneVertexSplits)] == kSingleInputs);
  static_assert(kParallelogramBuckets == kMixerSets[int(MixerFamily::OneVertexByParallelogram)] &&
                kMixerInputs[int(MixerFamily::OneVertexByParallelogram)] == kSingleInputs);
  static_assert(kCentroidBuckets * kPlaneBuckets == kMixerSets[int(MixerFamily::OneVertexByPlaneAndCentroid)] &&
                kMixerInputs[int(MixerFamily::OneVertexByPlaneAndCentroid)] == kSingleInputs);
  static_assert(kRefinementModels == kFamilySize[int(ModelFamily::OneVertexByRefinement)]);
  forEachFamily(primeModels);
  widths_.resize(size_t(schedule.levels) + 1);
  for (size_t level = 0; level < widths_.size(); ++level)
    for (int a = 0; a < 3; ++a)
      widths_[level][size_t(a)] = std::ldexp(1.0, schedule.bits[size_t(a)] - schedule.consumed[level][size_t(a)]);
  for (size_t level = 0; level < axis_.size(); ++level)
    inverseHalfWidths_.push_back(2.0 / widths_[level][axis_[level]]);
}

PositionPredictor::Features PositionPredictor::features(const Neighbourhood& around, int level) const {
  Features f;
  const int axis = axis_[size_t(level)];
  double halfWidth[3];
  for (int a = 0; a < 3; ++a) halfWidth[a] = widths_[size_t(level)][size_t(a)] * 0.5;
  const double inverseHalfWidth = inverseHalfWidths_[size_t(level)];
  const double inverse = 1.0 / double(around.count);
  double centroid[3];  // relative to the cell centre
  for (int a = 0; a < 3; ++a) centroid[a] = around.sum[a] * inverse;
  f.meanSquaredDistance = around.squaredDistance * inverse * (inverseHalfWidth * inverseHalfWidth);
  f.elongation = elongationGroup(around.squaredDistance, around.squaredAlong);
  f.centroidOffset = centroid[axis] * inverseHalfWidth;
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
  if (around.parallelograms > 0) {
    f.parallelogramOffset = around.parallelogramMedian * inverseHalfWidth;
    const double deviation = around.parallelogramDeviation * inverseHalfWidth;
    f.parallelogramSpread = deviation * deviation;
    f.hasParallelogram = true;
  }
  f.mirrored = (f.hasPlane ? f.planeOffset : f.centroidOffset) < 0;
  f.outsideUp = around.oriented && f.hasPlane && (normal[axis] > 0) != f.mirrored;
  if (f.mirrored) {
    f.planeOffset = -f.planeOffset;
    f.centroidOffset = -f.centroidOffset;
    f.parallelogramOffset = -f.parallelogramOffset;
  }
  if (f.hasParallelogram) f.parallelogram = parallelogramBucket(f.parallelogramOffset);
  return f;
}

uint32_t PositionPredictor::searchAcross(uint32_t slot, uint32_t a, uint32_t b) {
  // In the triangle b a c, wound that way, c follows a and b follows c.
  uint32_t found = kNowhere;
  uint32_t walked = 0;
  store_.forEachIncident(2, a, [&](uint32_t triangle, uint32_t position) {
    if (++walked > kMaxAcrossWalk) return true;
    const uint32_t row = position + (store_.flags(2, triangle) & SimplexStore::kFlipped ? 3 : 0);
    if (store_.vertices(2, triangle)[kAfterNext[row]] != b) return false;
    found = triangle * 3 + kNext[row];
    return true;
  });
  acrossSlots_[slot] = found;
  return found;
}

void PositionPredictor::forgetAcross(uint32_t triangle, uint32_t position) {
  const size_t first = size_t(triangle) * 3;
  if (first >= acrossSlots_.size()) return;
  for (uint32_t p = 0; p < 3; ++p)
    if (p != position) acrossSlots_[first + p] = kUnknown;
}

// The incidence lists are walked where they are: a copy of them in
// contiguous rows, rebuilt twice per level, took more instructions and
// memory (docs/EXPERIMENTS.md).
template <bool kParallelograms>
bool PositionPredictor::gather(uint32_t vertex, int level, Neighbourhood& around) {
  if (vertex >= store_.vertexCapacity() || !placed(vertex)) return false;
  const int axis = axis_[size_t(level)];
  const double inverseHalfWidth = inverseHalfWidths_[size_t(level)];
  std::array<uint32_t, 10> alongAxis{};
  // Scalars rather than arrays: these loops, the decoder's hottest, stalled
  // on store-to-load forwarding with array temporaries.
  const double* at = centre(vertex);
  const double atX = at[0], atY = at[1], atZ = at[2], atAxis = at[axis];
  double sumX = 0, sumY = 0, sumZ = 0, normalX = 0, normalY = 0, normalZ = 0, squared = 0, along = 0;
  uint32_t count = 0, parallelograms = 0;
  // Room for every triangle slot the walk may look up.
  if (acrossSlots_.size() < size_t(store_.size(2)) * 3) acrossSlots_.resize(size_t(store_.size(2)) * 3, kUnknown);
  // The walk reads the arrays through local pointers, which stay in
  // registers (through the vectors, each store in the loop made the
  // compiler load them again).
  const SimplexStore::Lists triangles = store_.lists(2);
  const double* centres = centres_.data();
  const uint32_t* acrossSlots = acrossSlots_.data();
  double* predictions = predictions_.data();
  uint32_t room = uint32_t(predictions_.size());
  // Each triangle adds the vertex that follows this one in its winding
  // (around a closed, consistently wound fan, every neighbour once) and the
  // cross product of the offsets of that vertex and the next.
  for (uint32_t slot = triangles.heads[vertex]; slot != kNoSimplex; slot = triangles.next[slot]) {
    const uint32_t triangle = slot / 3;
    if (!triangles.alive(triangle)) continue;
    const uint32_t* tuple = triangles.vertices + size_t(triangle) * 3;
    const uint32_t row = slot - triangle * 3 + (triangles.flags[triangle] & SimplexStore::kFlipped ? 3 : 0);
    const uint32_t next = tuple[kNext[row]], afterNext = tuple[kAfterNext[row]];
    const double* a = centres + size_t(next) * 3;
    const double* b = centres + size_t(afterNext) * 3;
    const double ax = a[0] - atX, ay = a[1] - atY, az = a[2] - atZ;
    const double bx = b[0] - atX, by = b[1] - atY, bz = b[2] - atZ;
    const double aAlong = a[axis] - atAxis;
    ++alongAxis[size_t(alongBin(aAlong * inverseHalfWidth))];
    sumX += ax;
    sumY += ay;
    sumZ += az;
    squared += ax * ax + ay * ay + az * az;
    along += aAlong * aAlong;
    normalX += ay * bz - az * by;
    normalY += az * bx - ax * bz;
    normalZ += ax * by - ay * bx;
    ++count;
    // The parallelogram rule: on a flat, evenly sampled surface v a c b is
    // a parallelogram, c being the far vertex of the triangle across a b;
    // listed only along the split axis, where the features look.
    if (!kParallelograms) continue;
    uint32_t farSlot = acrossSlots[slot];
    if (farSlot == kUnknown) farSlot = searchAcross(slot, next, afterNext);
    if (farSlot != kNowhere) {
      if (parallelograms == room) {
        predictions_.resize(std::max<size_t>(16, 2 * predictions_.size()));
        predictions = predictions_.data();
        room = uint32_t(predictions_.size());
      }
      const double* c = centres + size_t(triangles.vertices[farSlot]) * 3;
      predictions[parallelograms++] = aAlong + (b[axis] - atAxis) - (c[axis] - atAxis);
    }
  }
  if (count > 0) {
    double median = 0, deviation = 0;
    if (parallelograms > 0) medianAndDeviation(predictions, parallelograms, median, deviation);
    around = {{sumX, sumY, sumZ}, {normalX, normalY, normalZ}, squared, along, median, deviation, count,
              parallelograms, true, alongAxis};
    return true;
  }
  // No triangle: the other ends of the edges.
  double previousX = 0, previousY = 0, previousZ = 0;  // the first cross product is zero
  store_.forEachIncident(1, vertex, [&](uint32_t edge, uint32_t position) {
    const double* other = centre(store_.vertices(1, edge)[1 - position]);
    const double x = other[0] - atX, y = other[1] - atY, z = other[2] - atZ;
    sumX += x;
    sumY += y;
    sumZ += z;
    squared += x * x;
    squared += y * y;
    squared += z * z;
    along += (other[axis] - atAxis) * (other[axis] - atAxis);
    ++alongAxis[size_t(alongBin((other[axis] - atAxis) * inverseHalfWidth))];
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
    ++count;
  });
  if (count == 0) return false;
  around = {{sumX, sumY, sumZ}, {normalX, normalY, normalZ}, squared, along, 0, 0, count, 0, false, alongAxis};
  return true;
}

void PositionPredictor::adoptNeighbourhood(uint32_t isolated, uint32_t sibling, bool siblingIsolated) {
  const uint32_t proxy = siblingIsolated ? proxyOf(sibling) : sibling;
  if (proxy == kNoSimplex && isolated >= proxies_.size()) return;
  if (isolated >= proxies_.size()) proxies_.resize(std::max<size_t>(isolated + 1, proxies_.size() * 2), kNoSimplex);
  proxies_[isolated] = proxy;
}

bool PositionPredictor::gatherFromProxy(uint32_t vertex, int level, Neighbourhood& around) {
  uint32_t proxy = vertex;
  bool found = false;
  for (int hop = 0; hop < kProxyHops && !found; ++hop) {
    proxy = proxyOf(proxy);
    if (proxy == kNoSimplex) return false;
    found = gather<true>(proxy, level, around);
  }
  if (!found) return false;
  const int axis = axis_[size_t(level)];
  const double* from = centre(vertex);
  const double* to = centre(proxy);
  around.squaredDistance = 0;
  for (int a = 0; a < 3; ++a) {
    around.sum[a] = to[a] - from[a];
    around.squaredDistance += around.sum[a] * around.sum[a];
  }
  around.squaredAlong = around.sum[axis] * around.sum[axis];
  around.count = 1;
  around.parallelograms = 0;
  around.alongAxis = {};
  ++around.alongAxis[size_t(alongBin(around.sum[axis] * inverseHalfWidths_[size_t(level)]))];
  ++proxyPredictions_;
  return true;
}

// The neighbours of the cell's slab that went to its upper half, to its
// lower half and those not split yet (up to 3 each), then whether any
// neighbour lies in the half of each slab beside the cell that touches it,
// already split; whether any not split yet lies in each of those slabs;
// and with `farHalves`, whether any already split lies in the far half of
// each: 64 · 4 · 4 (· 4) classes. Mirroring reverses the axis, and so the
// bins: bin i is read as bin 8 − i.
int PositionPredictor::refinementClass(const AlongAxisBins& bins, bool mirrored, bool farHalves) {
  refinedNeighbourPredictions_ += bins[3] + bins[5] > 0;
  // The class is read both ways and one reading kept: which applies is a
  // coin toss for the branch predictor, and a choice per bin costs more.
  auto classFrom = [&bins, farHalves](size_t origin, int step) {
    auto bin = [&](size_t i) { return bins[size_t(int(origin) + step * int(i))]; };
    auto upTo3 = [&bin](size_t i) { return std::min(bin(i), 3u); };
    auto pair = [&bin](size_t above, size_t below) { return uint32_t(bin(above) > 0) * 2 + uint32_t(bin(below) > 0); };
    uint32_t c = (upTo3(5) * 4 + upTo3(3)) * 4 + upTo3(4);
    c = (c * 4 + pair(6, 2)) * 4 + pair(7, 1);
    if (farHalves) c = c * 4 + pair(8, 0);
    return c;
  };
  const uint32_t readings[2] = {classFrom(0, 1), classFrom(8, -1)};
  return int(readings[mirrored]);
}

bool PositionPredictor::contextsOf(uint32_t vertex, int level, SingleContexts& c) {
  Neighbourhood around;
  if (!gather<true>(vertex, level, around) && !gatherFromProxy(vertex, level, around)) return false;
  ++positionPredictions_;
  const Features f = features(around, level);
  c.mirrored = f.mirrored;
  const int tilt = f.hasPlane ? tiltClass(f.tilt) : kTiltClasses - 1;
  const int scale = scaleClass(f.meanSquaredDistance);
  const int valence = valenceClass(around.count, around.oriented);
  const int centroid = centroidBucket(f.centroidOffset);
  const int plane = planeBucket(f.planeOffset);  // 0 without a plane
  c.plane = ((f.outsideUp * kScaleClasses + scale) * kTiltClasses + tilt) * kPlaneBuckets + plane;
  c.joint = (kJointValence[valence] * kOutsideClasses * kScaleClasses * kTiltClasses * kPlaneBuckets + c.plane) *
                kCentroidBuckets +
            centroid;
  c.centroid = (valence * kScaleClasses + scale) * kCentroidBuckets + centroid;
  // Mixer weights also by how far the parallelogram predictions agree:
  // within about 1.4 half widths, farther, or no prediction.
  const int agreement = !f.hasParallelogram ? 2 : f.parallelogramSpread < 2 ? 0 : 1;
  c.mixerSet = (f.elongation * kScaleClasses + scale) * kAgreementClasses + agreement;
  c.parallelogramMixerSet = f.parallelogram;
  c.planeAndCentroidMixerSet = centroid * kPlaneBuckets + plane;
  c.parallelogram =
      (plane * kSpreadClasses + spreadClass(f.parallelogramSpread)) * kParallelogramBuckets + f.parallelogram;
  parallelogramPredictions_ += f.hasParallelogram;
  c.refinement = refinementClass(around.alongAxis, f.mirrored, true) * 2 + (tilt >= 2);
  c.parallelogramOdds.fast = c.parallelogramOdds.slow =
      f.hasParallelogram ? parallelogramOdds(f.parallelogramOffset, f.parallelogramSpread) : kProbabilityOne / 2;
  return true;
}

void PositionPredictor::prefetchNeighbourhoods(const uint32_t* vertices, size_t count) const {
  const SimplexStore::Lists edges = store_.lists(1);
  // The walks leave a result in a volatile store: a loop whose only
  // effects are prefetches may otherwise be deleted (C++ lets the compiler
  // assume that such a loop ends, and a prefetch changes nothing).
  // Natively they count their steps. WebAssembly has no prefetch: there
  // they add up the centres, whose loads bring their lines in all the same
  // (loads that nothing waits on overlap as prefetches do).
  [[maybe_unused]] uint32_t steps = 0;
  [[maybe_unused]] double sum = 0;
  for (size_t i = 0; i < count; ++i) {
    const uint32_t vertex = vertices[i];
    if (vertex >= store_.vertexCapacity()) continue;
    for (uint32_t slot = edges.heads[vertex]; slot != kNoSimplex; slot = edges.next[slot]) {
      const double* centre = centres_.data() + size_t(edges.vertices[slot ^ 1]) * 3;
#ifdef __wasm__
      sum += *centre;
#else
      __builtin_prefetch(centre);
      ++steps;
#endif
    }
  }
#ifdef __wasm__
  [[maybe_unused]] volatile double walked = sum;
#else
  [[maybe_unused]] volatile uint32_t walked = steps;
#endif
}

bool PositionPredictor::gatherAlongAxis(uint32_t vertex, int level, AlongAxisBins& bins, double& centroid) {
  bins = {};
  if (vertex >= store_.vertexCapacity() || !placed(vertex)) return false;
  const int axis = axis_[size_t(level)];
  const double inverseHalfWidth = inverseHalfWidths_[size_t(level)];
  // The centres' coordinates along the axis, three doubles apart.
  const double* along = centres_.data() + axis;
  const double atAxis = along[size_t(vertex) * 3];
  // A walk over local pointers (SimplexStore::lists()); an edge's slots are
  // 2 · edge + position, so the other end's slot is slot ^ 1.
  const SimplexStore::Lists edges = store_.lists(1);
  double sum = 0;  // of the neighbours' offsets along the axis, in half widths
  uint32_t count = 0;
  for (uint32_t slot = edges.heads[vertex]; slot != kNoSimplex; slot = edges.next[slot]) {
    if (!edges.alive(slot >> 1)) continue;
    const double offset = (along[size_t(edges.vertices[slot ^ 1]) * 3] - atAxis) * inverseHalfWidth;
    ++bins[size_t(alongBin(offset))];
    sum += offset;
    ++count;
  }
  if (count == 0) return false;
  centroid = sum / double(count);
  return true;
}

bool PositionPredictor::alongAxisContext(uint32_t vertex, int level, int& context, bool& mirrored) {
  static_assert(kAlongAxisModels == kFamilySize[int(ModelFamily::OneVertexAlongAxis)]);
  AlongAxisBins bins;
  double centroid = 0;
  if (!gatherAlongAxis(vertex, level, bins, centroid)) return false;
  ++positionPredictions_;
  mirrored = centroid < 0;
  const double offset = std::fabs(centroid);
  const int bucket = int(offset >= 0.25) + int(offset >= 0.75) + int(offset >= 1.5);
  context = refinementClass(bins, mirrored, false) * kAlongAxisCentroidBuckets + bucket;
  return true;
}

template <class Coder>
bool PositionPredictor::codeSingleAlongAxis(Coder& coder, CountCoder& counts, uint32_t vertex, int level,
                                            bool parentOneSided, bool inFirstHalf) {
  int context = 0;
  bool mirrored = false;
  if (!alongAxisContext(vertex, level, context, mirrored))
    return counts.codeSingle(coder, level, parentOneSided, inFirstHalf);
  return coder.bit(alongAxisModels_[size_t(context)], inFirstHalf != mirrored) != mirrored;
}
template bool PositionPredictor::codeSingleAlongAxis(RangeEncoder&, CountCoder&, uint32_t, int, bool, bool);
template bool PositionPredictor::codeSingleAlongAxis(RangeDecoder&, CountCoder&, uint32_t, int, bool, bool);

// The class by where the centroid lies, as for a vertex in no triangle.
CountContext PositionPredictor::alongAxisCountContext(uint32_t vertex, int level) {
  AlongAxisBins bins;
  double centroid = 0;
  if (!gatherAlongAxis(vertex, level, bins, centroid)) return {};
  ++countPredictions_;
  CountContext context;
  context.mirrored = centroid < 0;
  const double offset = std::fabs(centroid);
  context.neighbourhoodClass = 10 + int(offset >= 0.5) + int(offset >= 1.5);
  context.refinement = refinementClass(bins, context.mirrored, false);
  return context;
}

CountContext PositionPredictor::countContext(uint32_t vertex, int level, bool parentOneSided) {
  if (fastDecode_) return alongAxisCountContext(vertex, level);
  Neighbourhood around;
  if (!(parentOneSided ? gather<true>(vertex, level, around) : gather<false>(vertex, level, around))) return {};
  ++countPredictions_;
  const Features f = features(around, level);
  parallelogramPredictions_ += f.hasParallelogram;
  CountContext context = countContextOf(f);
  context.parallelogram = f.parallelogram;
  context.refinement = refinementClass(around.alongAxis, f.mirrored, false);
  return context;
}

CountContext PositionPredictor::countContextOf(const Features& f) {
  if (!f.hasPlane) {
    const double c = f.centroidOffset;
    return {c < 0.5 ? 10 : c < 1.5 ? 11 : 12, f.mirrored, f.elongation};
  }
  // The plane meets the cell's column along the split axis between
  // planeOffset - tilt and planeOffset + tilt (in half widths).
  const double low = f.planeOffset - f.tilt, high = f.planeOffset + f.tilt;
  if (low > 0) {
    // It stays in the upper half: how close it comes to the split plane.
    return {low < 0.5 ? 6 : low < 1 ? 7 : low < 2 ? 8 : 9, f.mirrored, f.elongation};
  }
  // It crosses the split plane: which share of its span inside the cell
  // lies in the lower half (at most about a half, since mirrored).
  const double inside = std::min(high, 1.0) - std::max(low, -1.0);
  const double below = std::min(high, 0.0) - std::max(low, -1.0);
  static constexpr double kShareBounds[4] = {0.08, 0.2, 0.32, 0.44};
  return {1 + countAtMost(inside > 0 && below > 0 ? below / inside : 0.0, kShareBounds), f.mirrored,
          f.elongation};
}

}  // namespace kdmesh
