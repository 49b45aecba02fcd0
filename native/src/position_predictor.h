// Geometry from connectivity: where a vertex lies, predicted from its
// neighbours in the complex as it is when the prediction is made.
//
// A one-vertex cell's split decides one bit of its vertex's coordinate along
// the split axis; without connectivity that bit is close to a coin toss. The
// vertex's neighbours (cells of the current level, taken at their centres)
// say where it should be: near their centroid and, on a surface, on the
// plane through that centroid. The plane's normal sums the cross products of
// the vertex's triangles (each as the two other vertices in the triangle's
// winding), so it also says which side is the surface's outside. A vertex in
// no triangle (of a wireframe, say) sums the cross products of consecutive
// neighbour offsets instead, each turned to agree with the sum so far; that
// plane has no outside.
//
// Both predictions become features measured in the cell's half width along
// the split axis:
//   - where the plane crosses the split axis, relative to the split plane;
//   - how much the plane tilts across the cell (the other axes' share of the
//     normal): a plane nearly parallel to the split says a lot, one across it
//     nothing;
//   - where the centroid lies relative to the split plane;
//   - the neighbours' distance against the cell size (coarse cells are
//     larger than the gaps between neighbours and predict little);
//   - whether the outside lies towards the predicted half (surfaces curve
//     away from their outside more often than not, so a vertex sits on the
//     outer side of its neighbours' plane);
//   - how many triangles the vertex is in (a regular fan's centroid is a
//     better guess than an irregular one's);
//   - the parallelogram predictions: each triangle v a b of the vertex and
//     the triangle b a c across its far edge predict v at a + b − c (the
//     rule single-rate coders predict with, here from the current
//     complex); their median, and their median absolute deviation, which
//     says how far to trust it (also for the counts of cells whose parent
//     split sent every vertex one way, count_coder.h); the median and its
//     deviation rather than the mean and variance, since they hold against
//     the parallelograms that span a crease or a fold.
// And one more, from the order of coding: cells split level by level, so
// the neighbours coded before the vertex at this level are known to half
// a cell more. A neighbour in the cell's own slab along the split axis
// that went to one half says much of a surface near it: the vertex tends
// to the same half, the more so the flatter the surface lies across the
// axis (on the fandisk's faces, which are flat, nearly always). The
// refinement class counts those neighbours by half and the slab's
// neighbours not split yet, and says which halves of the two slabs beside
// the cell hold a neighbour (also for cell counts).
//
// The configuration is mirrored so that the prediction points to the upper
// half, which lets the two mirror images share statistics. A one-vertex split
// mixes four models chosen by these features (mixer.h), as a fifth input
// the odds of the upper half computed from the parallelograms' median
// offset over their deviation, unbucketed, and as a sixth a model chosen by
// the refinement class; the split of a cell of several vertices gets
// classes for CountCoder.
//
// A stream coded for fast decoding (EncodeOptions::fastDecode) keeps only
// what one pass over the vertex's edges gives: where the neighbours lie
// along the split axis (the refinement class) and where their centroid
// lies, mirrored by the centroid's side. A one-vertex split is coded with
// one model chosen by the two, a cell of several vertices with the
// centroid's neighbourhood class and the refinement class.
#pragma once

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <vector>

// Encoder and decoders must round every double operation alike (see
// docs/FORMAT.md): not in x87 extended precision, as 32-bit x86 does unless
// told otherwise.
#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD != 0
#error "kdmesh needs double arithmetic evaluated in double precision (on 32-bit x86: -msse2 -mfpmath=sse)"
#endif

#include "count_coder.h"
#include "kdmesh/kdmesh.h"
#include "mixer.h"
#include "model_priors.h"
#include "range_coder.h"
#include "simplex_store.h"
#include "split_schedule.h"

namespace kdmesh {

// How many of the ascending `bounds` are at most t: the class of a feature
// without branches (features fall on either side of a bound at random, which
// a branch predictor cannot learn). NaN falls in class 0.
template <size_t kCount>
int countAtMost(double t, const double (&bounds)[kCount]) {
  int below = 0;
  for (const double bound : bounds) below += t >= bound;
  return below;
}

// Where a neighbour lies along the split axis, from its offset in half
// widths of the cell: a bin of 0..9 (position_predictor.cpp).
int alongBin(double offset);

// The median of values[0..count), count > 0, and the median of their
// absolute deviations from it (the values may be reordered). Values, not
// positions, are what count: encoder and decoder agree whatever the sort.
void medianAndDeviation(double* values, uint32_t count, double& median, double& deviation);

class PositionPredictor {
 public:
  // Inputs of the one-vertex mixers: four models of the neighbourhood's
  // shape, the parallelogram odds and the refinement class's model.
  static constexpr int kSingleInputs = 6;

  // `store`: the complex the predictions read, as it changes;
  // `fastDecode`: the stream is coded for fast decoding (see above).
  PositionPredictor(const SplitSchedule& schedule, const SimplexStore& store, bool fastDecode);

  // The vertex's cell is now the one at `level` with these leading
  // coordinate bits.
  void place(uint32_t vertex, const uint32_t prefix[3], int level) {
    if (!placed(vertex)) centres_.resize(std::max<size_t>(size_t(vertex) + 1, centres_.size() / 3 * 2) * 3);
    const std::array<double, 3>& width = widths_[size_t(level)];
    for (int a = 0; a < 3; ++a) centre(vertex)[a] = double(prefix[a]) * width[a] + (width[a] - 1) * 0.5;
  }

  // The neighbourhood class of the split of a cell of several vertices at
  // `level` whose vertex in the complex is `vertex`: for a plane through the
  // cell that crosses the split plane, which share of it lies on the lesser
  // side (1..5); for one that does not, how close it comes (6..9); without a
  // plane, where the centroid lies (10..12); 0 without neighbours. With
  // the parallelogram predictions only after a one-sided parent split
  // (`parentOneSided`): the vertices of such a cell often travel together,
  // as coincident ones do, and the parallelograms of their vertex in the
  // complex then say where they all lie; the cells of a surface's nearby
  // vertices, which part soon, gain little from them for the work.
  CountContext countContext(uint32_t vertex, int level, bool parentOneSided);

  // Codes whether the vertex of a one-vertex cell at `level` lies in its
  // first half, and moves the vertex's cell to that half. A vertex without
  // neighbours falls back to `counts`. Returns the (decoded) bit.
  template <class Coder>
  bool codeSingle(Coder& coder, CountCoder& counts, uint32_t vertex, int level,
                  bool parentOneSided, bool inFirstHalf) {
    SingleContexts c;
    bool first;
    if (fastDecode_) {
      first = codeSingleAlongAxis(coder, counts, vertex, level, parentOneSided, inFirstHalf);
    } else if (!contextsOf(vertex, level, c)) {
      first = counts.codeSingle(coder, level, parentOneSided, inFirstHalf);
    } else {
      const bool bit = codeWithMixers(
          coder, std::array<Mixer<kSingleInputs>*, 3>{&mixer_, &parallelogramMixer_, &planeAndCentroidMixer_},
          {c.mixerSet, c.parallelogramMixerSet, c.planeAndCentroidMixerSet},
          {&models_[size_t(c.joint)], &planeModels_[size_t(c.plane)], &centroidModels_[size_t(c.centroid)],
           &parallelogramModels_[size_t(c.parallelogram)], &c.parallelogramOdds,
           &refinementModels_[size_t(c.refinement)]},
          inFirstHalf != c.mirrored);
      first = bit != c.mirrored;
    }
    // The half's centre lies a quarter of the cell's width below or above.
    const int axis = axis_[size_t(level)];
    const double quarter = widths_[size_t(level)][size_t(axis)] * 0.25;
    centre(vertex)[axis] += double(1 - 2 * int(first)) * quarter;
    return first;
  }

  // codeSingle() of a stream coded for fast decoding, without moving the
  // cell. Out of line (inlined, it made the loop of the default coding
  // slower), in position_predictor.cpp with the walk it inlines, for
  // RangeEncoder and RangeDecoder.
  template <class Coder>
  [[gnu::noinline]] bool codeSingleAlongAxis(Coder& coder, CountCoder& counts, uint32_t vertex, int level,
                                             bool parentOneSided, bool inFirstHalf);

  // Walks the edge lists of `count` vertices whose predictions come soon
  // and prefetches their neighbours' cell centres, so that the walks of
  // those predictions find both in cache. A walk is a chain of dependent
  // loads, which the processor overlaps only with work that does not wait
  // on it: here, the walks of the other vertices; in the decoding loop,
  // nothing. Their neighbours must have cells (place()), as for the
  // predictions.
  void prefetchNeighbourhoods(const uint32_t* vertices, size_t count) const;

  // A split left `isolated` in no simplex and its cell's other half, the
  // vertex `sibling`, with the simplices (or both in none: `sibling` is
  // then the isolated vertex that split, whose proxy passes on). A vertex
  // in no simplex of a surface mesh (the bunny has 1,113, in the holes of
  // its scan) lies on or near the surface all the same: its one-vertex
  // splits are predicted from the sibling it left (gatherFromProxy()).
  void adoptNeighbourhood(uint32_t isolated, uint32_t sibling, bool siblingIsolated);
  uint32_t proxyOf(uint32_t vertex) const { return vertex < proxies_.size() ? proxies_[vertex] : kNoSimplex; }

  // The split of the triangle's vertex at `position` may have changed its
  // neighbours across the two edges through that vertex: gather() will
  // search for them again.
  void forgetAcross(uint32_t triangle, uint32_t position);

  bool geometric(int level) const { return size_t(level) < axis_.size(); }
  // Whether the stream is coded for fast decoding.
  bool fastDecode() const { return fastDecode_; }
  double inverseHalfWidth(int level) const { return inverseHalfWidths_[size_t(level)]; }

  // The split axis of a geometric `level`, and the centre of a vertex's
  // current cell in grid units.
  int axis(int level) const { return axis_[size_t(level)]; }
  void centreOf(uint32_t vertex, double out[3]) const {
    for (int a = 0; a < 3; ++a) out[a] = centre(vertex)[a];
  }

  // Its model families, visit(family, first model), and its mixers,
  // visitMixer(family, mixer): what the constructor primes and training
  // reads (tools/train_priors.cpp).
  template <class Visit>
  void forEachFamily(Visit&& visit) {
    visit(ModelFamily::OneVertexSplits, models_.data());
    visit(ModelFamily::OneVertexByPlane, planeModels_.data());
    visit(ModelFamily::OneVertexByCentroid, centroidModels_.data());
    visit(ModelFamily::OneVertexByParallelogram, parallelogramModels_.data());
    visit(ModelFamily::OneVertexByRefinement, refinementModels_.data());
    visit(ModelFamily::OneVertexAlongAxis, alongAxisModels_.data());
  }
  template <class Visit>
  void forEachMixer(Visit&& visitMixer) const {
    visitMixer(MixerFamily::OneVertexSplits, mixer_);
    visitMixer(MixerFamily::OneVertexByParallelogram, parallelogramMixer_);
    visitMixer(MixerFamily::OneVertexByPlaneAndCentroid, planeAndCentroidMixer_);
  }

  // Adds the prediction counters to `statistics`.
  void addStatistics(ConnectivityStatistics& statistics) const {
    statistics.countPredictions += countPredictions_;
    statistics.positionPredictions += positionPredictions_;
    statistics.parallelogramPredictions += parallelogramPredictions_;
    statistics.refinedNeighbourPredictions += refinedNeighbourPredictions_;
    statistics.proxyPredictions += proxyPredictions_;
  }

 private:
  // The centre of a vertex's current cell in grid units (x, y, z at
  // centres_[3 · vertex]), kept as the cell shrinks rather than computed
  // from its coordinate bits at every look (in gather(), a second dependent
  // load and nine operations per neighbour). Exact: centres are multiples
  // of 1/2 below 2^32 (grids have at most 32 bits).
  const double* centre(uint32_t vertex) const { return &centres_[size_t(vertex) * 3]; }
  double* centre(uint32_t vertex) { return &centres_[size_t(vertex) * 3]; }
  bool placed(uint32_t vertex) const { return size_t(vertex) * 3 < centres_.size(); }

  // Neighbour counts by where they lie along the split axis (alongBin() in
  // position_predictor.cpp).
  using AlongAxisBins = std::array<uint32_t, 10>;
  // Sums over the neighbours' cell centres, relative to the vertex's cell
  // centre; the normal: see the top of this file. `oriented`: the normal
  // comes from the triangles' winding and points outside.
  struct Neighbourhood {
    double sum[3], normal[3];
    double squaredDistance;
    double squaredAlong;  // of the offsets along the split axis
    // The median of the parallelogram predictions' offsets along the split
    // axis (see gather()), and their median absolute deviation from it.
    double parallelogramMedian, parallelogramDeviation;
    uint32_t count, parallelograms;
    bool oriented;
    AlongAxisBins alongAxis;
  };
  // The predictions against the split at `level`, in half widths of the
  // cell along the split axis, mirrored so that the plane (or without one,
  // the centroid) lies on the upper side.
  struct Features {
    double planeOffset = 0;          // where the plane meets the split axis
    double tilt = 0;                 // the plane's rise across the cell
    double centroidOffset = 0;
    double meanSquaredDistance = 0;  // of the neighbours, in squared half widths
    int elongation = 1;              // elongationGroup() (position_predictor.cpp)
    double parallelogramOffset = 0;  // the parallelogram predictions' median offset
    double parallelogramSpread = 0;  // their squared median deviation, in squared half widths
    // The offset's bucket (position_predictor.cpp), the last for none.
    int parallelogram = CountContext::kParallelogramBuckets - 1;
    bool hasPlane = false, hasParallelogram = false, mirrored = false;
    bool outsideUp = false;  // an oriented normal points to the upper half
  };
  // Inlined always: its two callers use different parts of it.
  [[gnu::always_inline]] inline Features features(const Neighbourhood& around, int level) const;
  // Sums the neighbours of `vertex` against the split of `level`, with
  // the parallelogram predictions if kParallelograms; false without any.
  template <bool kParallelograms>
  bool gather(uint32_t vertex, int level, Neighbourhood& around);
  // The refinement class of gathered neighbours, mirrored as the features:
  // 0..CountContext::kRefinementClasses-1, or 4 times as many with
  // `farHalves` (whether the far halves of the slabs beside the cell hold
  // a neighbour already split). Counts the predictions with a neighbour
  // split in the cell's slab.
  // Inlined always: the fast path takes it at every one-vertex decision,
  // where a call would add much to its few dozen instructions.
  [[gnu::always_inline]] inline int refinementClass(const AlongAxisBins& bins, bool mirrored, bool farHalves);
  // Searches the triangle b a c across the edge a b (wound a b) and
  // returns the slot of its vertex c, or kNowhere; `slot` (triangle · 3 +
  // position) names the triangle v a b whose edge it is, under which the
  // answer is remembered in acrossSlots_.
  uint32_t searchAcross(uint32_t slot, uint32_t a, uint32_t b);
  // How many of a's triangles, in list order, searchAcross() examines: beyond,
  // the edge has no triangle across for the predictions. The reference
  // meshes, tetrahedral ones included, code the same bits with this bound
  // as without (64 changes the ball's); without any, the vertices around an
  // edge in 100,000 triangles each searched all of them, quadratic work for
  // a small stream.
  static constexpr uint32_t kMaxAcrossWalk = 128;
  static constexpr uint32_t kUnknown = 0xffffffffu, kNowhere = 0xfffffffeu;
  // The models of a one-vertex split: one for the joint class of all
  // features, one for the plane's alone, one for the centroid's alone, one
  // for the parallelogram predictions (with the plane's offset); mixed by
  // three mixers whose weights are chosen by the neighbours' distance and
  // elongation and by how far the parallelogram predictions agree, by the
  // parallelogram bucket, and by the centroid and plane buckets.
  struct SingleContexts {
    int joint, plane, centroid, parallelogram;
    int mixerSet, parallelogramMixerSet, planeAndCentroidMixerSet;
    int refinement;  // refinementClass() with far halves, and the tilt (< 1, or more or no plane)
    bool mirrored;
    // Holds, for this bit alone, the odds of the upper half that the
    // parallelogram predictions give (parallelogramOdds() in
    // position_predictor.cpp); its update after the bit is discarded.
    BitModel parallelogramOdds;
  };
  bool contextsOf(uint32_t vertex, int level, SingleContexts& contexts);
  // Fast decoding: the model of a one-vertex split from the vertex's edges,
  // and whether it is mirrored; false for a vertex in no edge.
  [[gnu::always_inline]] inline bool alongAxisContext(uint32_t vertex, int level, int& context, bool& mirrored);
  // The bins of the neighbours through edges along the split axis and their
  // centroid's offset in half widths (fast decoding).
  [[gnu::always_inline]] inline bool gatherAlongAxis(uint32_t vertex, int level, AlongAxisBins& bins,
                                                     double& centroid);
  CountContext alongAxisCountContext(uint32_t vertex, int level);
  // The refinement class without far halves, by centroid bucket.
  static constexpr int kAlongAxisCentroidBuckets = 4;
  static constexpr size_t kAlongAxisModels = size_t(CountContext::kRefinementClasses) * kAlongAxisCentroidBuckets;
  // One-vertex refinement models: the class with far halves, by tilt.
  static constexpr size_t kRefinementModels = size_t(CountContext::kRefinementClasses) * 4 * 2;
  // The neighbourhood of a vertex in no simplex: its proxy as its one
  // neighbour, with the plane of the proxy's own neighbourhood (no
  // parallelograms: they predict the proxy). The proxy is the first vertex
  // with neighbours along the chain of proxies (at most kProxyHops).
  bool gatherFromProxy(uint32_t vertex, int level, Neighbourhood& around);
  static constexpr int kProxyHops = 8;
  // The neighbourhood class of a cell's count from the plane or centroid.
  static CountContext countContextOf(const Features& f);

  std::vector<uint8_t> axis_;                  // split axis per level
  std::vector<std::array<double, 3>> widths_;  // cell width per level and axis
  // Per level, 1 / half the width along the split axis: widths are powers of
  // two, so multiplying by it rounds exactly as dividing by the half width
  // would, without a division's latency.
  std::vector<double> inverseHalfWidths_;
  LargeArray<double> centres_;
  LargeArray<uint32_t> proxies_;  // per vertex in no simplex, else kNoSimplex
  const SimplexStore& store_;
  // Per triangle slot (see searchAcross()), the slot of the far vertex c of the
  // triangle found across the edge opposite the slot's vertex (kNowhere: no
  // triangle; kUnknown: not searched since the triangle's star changed).
  // Searching walks a's triangles; a vertex split changes the answer only
  // for triangles of the split vertex's star (forgetAcross).
  LargeArray<uint32_t> acrossSlots_;
  // The parallelogram predictions of one gather(), and their deviations.
  std::vector<double> predictions_;
  std::vector<BitModel> models_, planeModels_, centroidModels_, parallelogramModels_, refinementModels_,
      alongAxisModels_;
  bool fastDecode_;
  Mixer<kSingleInputs> mixer_, parallelogramMixer_, planeAndCentroidMixer_;
  uint64_t countPredictions_ = 0;
  uint64_t positionPredictions_ = 0;
  uint64_t parallelogramPredictions_ = 0;
  uint64_t refinedNeighbourPredictions_ = 0;
  uint64_t proxyPredictions_ = 0;
};

}  // namespace kdmesh
