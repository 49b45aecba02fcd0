// The generalized vertex split (Popović & Hoppe), as coded by Gandoin &
// Devillers: when a kd-tree cell with vertex V splits into two non-empty
// halves, V becomes V1 (the first half; it keeps V's id) and V2 (a new id),
// and every simplex S of V's star gets a code
//   1: S goes to V1          2: S goes to V2          3: to both
//   4: to both, plus S ∪ {V1, V2} one dimension higher.
// The vertex V itself always goes to both: code 4 means the edge V1V2.
//
// The star is listed in a canonical order both sides can reproduce: by
// dimension, then by the sorted ids of the other vertices. Codes are taken
// in that order, except that at geometric levels the edges are taken from
// the one pointing most steeply across the split plane to the one lying
// most in it: an edge far from the plane goes to its side's vertex almost
// surely, and the codes it gets then tell its fan neighbours near the plane,
// the likely cut edges, where the fan crosses. Closure limits
// each code by those of the simplex's faces through V (a face coded 1 forces
// 1, a face coded 2 forces 2, a face coded 3 excludes 4, and the code of S
// must allow its children's faces), so implied codes cost nothing; the rest
// are coded with adaptive models per dimension and set of possible codes.
// At geometric levels the split is known to separate V1 and V2 along the
// split axis, so edges and triangles are coded by where their other
// vertices lie against the split plane, and edges also by the codes already
// given around the vertex's fan (runClass() in vertex_split.cpp;
// docs/FORMAT.md), the vertex's own code by the star's shape. In a
// tetrahedral star the cut edges form the link of the new edge v v2, a
// cycle: each has two triangles coded 4, which makes the triangles between
// cut edges cheap when the most constrained of them are taken first.
//
// In a stream coded for fast decoding, a star that is one closed fan of
// triangles first gets one bit: whether the split is an edge expansion of
// the fan (two edges coded 4, the fan's arcs between them coded 1 and 2).
// If so, its codes follow from where the two cuts lie, coded by a walk
// around the fan (codeFanExpansion()) instead of one code per simplex.
//
// Triangles and tetrahedra are oriented. A child that inherits its parent's
// tuple keeps the parent's orientation; the second copy of a code-3 simplex
// and the new simplex of a code 4 get one coded bit each, predicted from
// the orientations of already decided neighbours that share a facet.
//
// With labels, every simplex a split creates then gets its label, in the
// same order as the orientations (labels.h).
//
// One template serves both sides: on the encoder `Oracle` supplies the
// decimation's answers and the range coder writes them; on the decoder the
// range coder reads them and the oracle's values are ignored.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <type_traits>
#include <vector>

#include "kdmesh/kdmesh.h"
#include "labels.h"
#include "mixer.h"
#include "model_priors.h"
#include "position_predictor.h"
#include "range_coder.h"
#include "simplex_store.h"

namespace kdmesh {

// One byte per star entry, as the encoder's decimation records them.
namespace split_record {
constexpr uint8_t kCodeMask = 3;        // code - 1
constexpr int kCopyTargetShift = 2;     // orientation of the code-3/4 copy
constexpr int kNewTargetShift = 4;      // orientation of the code-4 simplex
constexpr uint8_t kFree = 0;            // target: any orientation will do
constexpr uint8_t kParity0 = 2, kParity1 = 3;
inline uint8_t target(int parity) { return uint8_t(kParity0 + parity); }
}  // namespace split_record

// The decoder's oracle: it has no records, and split() leaves each star
// entry's record 0 without asking for one.
struct NoRecords {
  uint8_t operator()() const { return 0; }
};

// How a cell's vertices divide between the halves of its split, `first` of
// `population` in the lower half: a class of the star's edge codes (a half
// of one or two vertices takes few of the edges, a large half many).
// Class 0 for the splits of coincident vertices past the geometric levels.
int splitBalance(uint32_t population, uint32_t first, bool geometric);

// The bucket of an edge's |cos| against the split axis (< 0.2, 0.45, 0.7, ≥ 0.7).
int directionBucket(double cosine);

// An entry of a vertex star in canonical order: by dimension, then by the
// ascending ids of the simplex's other vertices. Entry 0 is the vertex.
struct StarEntry {
  uint32_t simplex;
  uint32_t others[3];  // the other vertices, ascending
  uint8_t dimension;
  uint8_t position;    // of the vertex in the simplex's tuple
  uint8_t code;
  uint8_t record;
  uint8_t geometry;  // edges: class of the other vertex's direction (see classifyEdges())
  uint8_t fanCodes;  // edges: codes already given to fan neighbours, bits 0 (1), 1 (2), 2 (3 or 4)
  // Cut edges (coded 3 or 4): how many triangles through them were coded 4,
  // and how many between them and another cut edge are still to be coded.
  uint8_t addedTriangles;
  uint16_t pairedTriangles;
  uint8_t fanIndex;  // edges of a closed fan: position around it
  // Edges: star indices of two edges sharing a triangle with this one;
  // triangles: of their two edges through the vertex. kNoSimplex if none.
  uint32_t links[2];
  uint32_t copy, added;  // children made by codes 3 and 4
};

// Fills `star` with the star of `v`; begin[d] is the first entry of
// dimension d, begin[4] the end.
void gatherStar(SimplexStore& store, uint32_t v, std::vector<StarEntry>& star,
                std::array<size_t, 5>& begin);
// The canonical order of two entries of dimension `count`: whether the
// other vertices `a` come before `b`.
bool lessOthers(const uint32_t* a, const uint32_t* b, int count);
// Sorts star[first, last), entries of dimension d, into canonical order.
void sortStarEntries(std::vector<StarEntry>& star, size_t first, size_t last, int d);
// The entry of dimension d of such a star whose other vertices are
// `others` (d of them, ascending), or nullptr; d = 0 gives the vertex.
const StarEntry* findInStar(const std::vector<StarEntry>& star, const std::array<size_t, 5>& begin, int dimension,
                            const uint32_t* others);

class VertexSplitter {
 public:
  // Rows of models an edge code mixes (split()).
  static constexpr int kEdgeInputs = 4;

  // `geometry` knows where the cells are; the split of a cell at a
  // geometric level puts v in its first half and v2 in the second, which
  // predicts where v's edges go. A split tells `geometry` which triangles
  // it changed (PositionPredictor::forgetAcross).
  VertexSplitter(SimplexStore& store, PositionPredictor& geometry)
      : store_(store), geometry_(geometry), fanExpansions_(geometry.fastDecode()) {
    static_assert(sizeof(edgeModels_) / sizeof(BitModel) == kFamilySize[int(ModelFamily::EdgeCodes)]);
    static_assert(sizeof(edgeDirectionModels_) / sizeof(BitModel) ==
                  kFamilySize[int(ModelFamily::EdgeCodesByDirection)]);
    static_assert(sizeof(edgeBalanceModels_) / sizeof(BitModel) == kFamilySize[int(ModelFamily::EdgeCodesByBalance)]);
    static_assert(sizeof(triangleModels_[0]) / sizeof(BitModel) == kFamilySize[int(ModelFamily::TriangleCodes)]);
    static_assert(sizeof(edgeRunModels_) / sizeof(BitModel) == kFamilySize[int(ModelFamily::EdgeCodesByRun)]);
    static_assert(sizeof(vertexModels_) / sizeof(BitModel) == kFamilySize[int(ModelFamily::VertexCodes)]);
    static_assert(kMixerSets[int(MixerFamily::EdgeCodes)] == 8 && kMixerInputs[int(MixerFamily::EdgeCodes)] == kEdgeInputs);
    forEachFamily(primeModels);
    // Every pairing class of triangle codes starts from the same priors.
    for (auto& models : triangleModels_) std::copy_n(&triangleModels_[0][0][0][0], kFamilySize[int(ModelFamily::TriangleCodes)], &models[0][0][0]);
  }

  // Its model families with learned priors (of the triangle codes, the
  // first pairing class's) and its mixer, as PositionPredictor::
  // forEachFamily() lists its own.
  template <class Visit>
  void forEachFamily(Visit&& visit) {
    visit(ModelFamily::EdgeCodes, &edgeModels_[0][0][0][0][0]);
    visit(ModelFamily::EdgeCodesByDirection, &edgeDirectionModels_[0][0][0]);
    visit(ModelFamily::EdgeCodesByBalance, &edgeBalanceModels_[0][0][0][0]);
    visit(ModelFamily::TriangleCodes, &triangleModels_[0][0][0][0]);
    visit(ModelFamily::EdgeCodesByRun, &edgeRunModels_[0][0][0]);
    visit(ModelFamily::VertexCodes, &vertexModels_[0][0]);
  }
  template <class Visit>
  void forEachMixer(Visit&& visitMixer) const {
    visitMixer(MixerFamily::EdgeCodes, edgeMixer_);
  }

  // Codes labels of `tableSize` distinct values from now on; the store
  // must be labelled.
  void enableLabels(uint32_t tableSize) { labels_.emplace(tableSize); }

  // Splits `v`, whose cell is at `level`, into `v` and `v2`; `balance`:
  // splitBalance() of the cell's split. `oracle()` gives the record byte of
  // each star entry in canonical order (the decoder passes NoRecords),
  // `labelOracle()` the label of each new simplex (SplitRecords::labels)
  // when labels are enabled.
  // Returns false when the codes contradict each other, a label is not in
  // the table or the store is full: corrupt data on the decoder.
  template <class Coder, class Oracle, class LabelOracle>
  bool split(Coder& coder, uint32_t v, uint32_t v2, int level, int balance, Oracle&& oracle,
             LabelOracle&& labelOracle);

  const ConnectivityStatistics& statistics() const { return statistics_; }
  // Information content of the labels coded so far (measuring coders).
  double labelBits() const { return labelBits_; }

 private:
  using Entry = StarEntry;

  // Possible codes as a bit set: bit c-1 for code c.
  static constexpr uint8_t kAllowedBy[5] = {0, 0b0001, 0b0010, 0b0111, 0b1111};
  // Mirrored coding: codes 1 and 2 (bits 0 and 1 of code sets) trade places.
  static uint8_t mirrorSet(uint8_t set, bool mirrored) {
    return mirrored ? uint8_t((set & ~3u) | (set & 1u) << 1 | (set >> 1 & 1u)) : set;
  }
  static uint8_t mirrorCode(uint8_t code, bool mirrored) {
    return mirrored && code <= 2 ? uint8_t(3 - code) : code;
  }

  uint8_t possibleCodes(const Entry& entry) const;
  const Entry* findFace(int dimension, const uint32_t* others) const;
  // The cosines and lengths of the star's edges (classifyEdges()).
  void measureEdges(uint32_t v, int level);
  // Their direction classes, for the codes of codeEntries().
  void classifyEdges();
  void orderCodes(bool geometric);
  void linkFans();
  void indexFan();
  // gatherStar() and linkFans() for a star that is one closed fan of
  // triangles and nothing else, of at most kLeanFanEdges edges (the star of
  // almost every split of a surface): the same entries, links and fan
  // order, from one walk of each list, the edges sorted as keys and the
  // triangles ordered by their edges, instead of sorting whole entries.
  // False for any other star, which the general path then gathers.
  bool gatherClosedFan(uint32_t v);
  static constexpr int kLeanFanEdges = 32;
  size_t countPairedTriangles();
  static constexpr int kUnpaired = 0x7fffffff;
  int pairingSlack(const Entry& triangle) const;
  void takeMostConstrainedTriangle(size_t step);
  // How many triangles past the current one takeMostConstrainedTriangle()
  // compares, so that a split's work stays linear in its star. The
  // tetrahedral reference meshes code the same bits with this bound as
  // without (64 changes the ball's).
  static constexpr size_t kPairingLookAhead = 256;
  int triangleClass(const Entry& triangle) const;
  // Codes a symbol among the `possible` codes by sequential binarisation
  // (step s: is it the s-th candidate?), `codeBit(step, bit)` coding each
  // binary decision.
  template <class CodeBit>
  static uint8_t binarise(uint8_t possible, uint8_t code, CodeBit&& codeBit);
  template <class Coder>
  uint8_t codeSymbol(Coder& coder, BitModel (&models)[3], uint8_t possible, uint8_t code) {
    return binarise(possible, code, [&](int step, bool bit) { return coder.bit(models[step], bit); });
  }
  // Edges: kEdgeInputs rows of models mixed with the weight vector `mixerSet`.
  template <class Coder>
  uint8_t codeEdgeSymbol(Coder& coder, const std::array<BitModel*, kEdgeInputs>& rows, int mixerSet,
                         uint8_t possible, uint8_t code) {
    return binarise(possible, code, [&](int step, bool bit) {
      return edgeMixer_.code(coder, mixerSet, {&rows[0][step], &rows[1][step], &rows[2][step], &rows[3][step]}, bit);
    });
  }
  int runClass(const Entry& edge, int cutEdges, bool mirrored);
  // How far the edge at fan position `position` lies from the cut at
  // `cut`, the shorter way round, against half the fan: 4 for half or
  // more, 3 and 2 for one and two less, else 1.
  int cutBand(int position, int cut) const;
  // The fan positions after and before `position` around the closed fan
  // (a compare, not a division).
  int fanNext(int position) const {
    const int next = position + 1;
    return next & -int(next != fanSize_);
  }
  int fanPrevious(int position) const { return (position == 0 ? fanSize_ : position) - 1; }
  // Codes every entry of the star one by one, in the order of orderCodes();
  // false when the codes contradict each other.
  template <class Coder>
  bool codeEntries(Coder& coder, bool geometric, int balance, int& cutEdges, bool& codedThree);
  // Whether the star is one closed fan of triangles and nothing more.
  bool closedFanStar() const {
    return fanSize_ > 0 && begin_[4] == begin_[3] && begin_[3] - begin_[2] == size_t(fanSize_);
  }
  // Encoder: whether the records of such a star make an edge expansion
  // that codeFanExpansion() can code.
  bool recordsFormFanExpansion() const;
  // The fan position of the triangle between the edges at fan positions k
  // and k + 1 (mod fanSize_).
  int fanSlot(const Entry& triangle) const;
  // Codes the two cuts of a closed fan's edge expansion by a walk around
  // the fan from its steepest edge, and gives every entry its code.
  template <class Coder>
  void codeFanExpansion(Coder& coder);
  int vertexClass(int balance) const;
  // Decides the orientation of `simplex`, made by the split from the star
  // entry `from`: its copy (code 3 or 4) or the simplex one dimension up
  // that its code 4 added.
  template <class Coder>
  void decideOrientation(Coder& coder, int dimension, uint32_t simplex, const Entry& from, bool isCopy,
                         uint8_t target);
  int predictFlip(int dimension, uint32_t simplex, const Entry& from, bool isCopy, int& voteClass);
  // The triangles after the split that can share an edge with the new
  // triangle made from `from` (predictFlip()).
  const std::vector<uint32_t>& triangleNeighbours(const Entry& from, bool isCopy);
  template <int kArity>
  int neighbourVote(uint32_t simplex, int myParity, uint32_t other) const;
  template <int kArity>
  int voteOnFlip(uint32_t simplex, const std::vector<uint32_t>& candidates, int& voteClass);

  SimplexStore& store_;
  PositionPredictor& geometry_;
  std::vector<Entry> star_;
  std::vector<double> cosines_, lengths_;  // per edge of the star
  // Stars with more edges than this are sorted by std::stable_sort.
  static constexpr size_t kLongStar = 64;
  std::vector<uint32_t> codingOrder_;  // star_ indices in the order codes are taken
  // Fan neighbours beyond two per edge, summed over the star's edges (links
  // hold two). When there are any, the fan neighbours of every edge
  // (star_ indices): those of the edge begin_[1] + e are
  // fanList_[fanStart_[e] .. fanStart_[e + 1]).
  int crowdedLinks_ = 0;
  bool crowdedFans() const { return crowdedLinks_ > 0; }
  std::vector<uint32_t> fanStart_, fanList_, fanFill_;
  // Per vertex id, the star_ index of the edge to it (linkFans()).
  std::vector<uint32_t> edgeTo_;
  std::array<size_t, 5> begin_{};  // star_ entries of dimension d: [begin_[d], begin_[d+1])
  // Simplices of dimension d at v or v2 after the split, gathered on the
  // first orientation decision of that dimension (most splits of a surface
  // need none of dimension 3).
  std::array<std::vector<uint32_t>, 4> around_;
  std::vector<uint32_t> neighbours_;  // triangleNeighbours()
  std::array<bool, 4> aroundReady_{};
  const std::vector<uint32_t>& around(int dimension);
  // Per dimension, for stars of more than kIndexedStar simplices around: the
  // facets of around()'s simplices, sorted by key (the facet's vertices,
  // ascending), the first entry of each facet's run counting the decided
  // simplices that induce each orientation on it.
  struct FacetKey {
    uint64_t low;
    uint32_t high;
    bool operator<(const FacetKey& o) const { return low != o.low ? low < o.low : high < o.high; }
  };
  struct FacetEntry {
    FacetKey key;
    std::array<uint32_t, 2> decided;
  };
  FacetKey facetKey(int dimension, uint32_t simplex, int skip) const;
  FacetEntry& facetOf(int dimension, uint32_t simplex, int skip);
  int inducedSign(int dimension, uint32_t simplex, int skip) const;
  // Adds a simplex whose orientation is decided to its facets' counts.
  void countDecided(int dimension, uint32_t simplex);
  // Below this many simplices around, a vote polls them all: building the
  // index costs more than it saves.
  static constexpr size_t kIndexedStar = 256;
  // Whether a simplex made by the split (so holding v2) is a face of one of
  // dimension + 1: looked up in the index, or found in v2's list, rather
  // than in the list of another of its vertices, which may be in very many
  // simplices outside the split.
  bool isFaceOfHigher(int dimension, uint32_t simplex);
  uint32_t newVertex_ = kNoSimplex;  // v2 of the split under way
  std::array<std::vector<FacetEntry>, 4> facets_;
  // Code models: [dimension][possible set][step of the sequential binarisation].
  BitModel codeModels_[4][16][3];
  // Whether v and v2 are joined (the vertex's code, 3 or 4) by the shape of
  // the star (see vertexClass()).
  static constexpr int kVertexClasses = 12;
  BitModel vertexModels_[kVertexClasses][3];
  // Triangles at geometric levels: [pairing class (see split())][class of
  // their two other vertices' directions][possible set][step] (what
  // separates a tetrahedral mesh's star in two).
  static constexpr int kTriangleClasses = 18;
  BitModel triangleModels_[3][kTriangleClasses][16][3];
  static constexpr int kEdgeClasses = 49;
  // Edges: [cut state][fan codes][class][all four codes possible] (an
  // edge's only face is the vertex, coded 3 or 4, so it has two sets). The
  // cut state is the count of edges coded 4 so far (0..2) or, at geometric
  // levels, 3 + that count (0 or 1) when no more edges are left to code
  // than an edge expansion still needs cut ones: coded last, being closest
  // to the split plane, those usually are.
  static constexpr int kCutStates = 5;
  BitModel edgeModels_[kCutStates][8][kEdgeClasses][2][3];
  // Edges by direction class alone, mixed with the above (weight vectors
  // by cut state, the last two sharing one, and by whether the star is one
  // closed fan).
  BitModel edgeDirectionModels_[kEdgeClasses][2][3];
  // Edges of surface stars by splitBalance() and direction class, mixed in
  // third (with learned priors); a tetrahedral star, which the balance does
  // not help, mixes a model reset to 1/2 at every edge instead, whose
  // stretch of 0 leaves its mix and weights as a two-input mix would.
  static constexpr int kBalanceClasses = 9;
  BitModel edgeBalanceModels_[kBalanceClasses][kEdgeClasses][2][3];
  BitModel neutral_[3];
  Mixer<kEdgeInputs> edgeMixer_{8, mixerPriors(MixerFamily::EdgeCodes)};
  // Edges by where they lie in the star's fan (runClass()), mixed in fourth.
  static constexpr int kRunClasses = 66, kCutBands = 5;
  BitModel edgeRunModels_[kCutBands * kRunClasses][2][3];
  // When the star's edges form one closed fan (linkFans), their order
  // around it.
  int fanSize_ = 0;  // edges around the closed fan, 0 if the star is not one
  std::vector<uint32_t> fanOrder_;
  int firstCut_ = -1;     // fan position of the first edge coded 4
  double halfWidth_ = 0;  // of the split cell along the split axis (0: not geometric)
  double meanLength_ = 0;  // of the star's edges (measureEdges())
  // Fan expansions (streams coded for fast decoding): whether the closed
  // fan's split is one, by fan size (3..9 and more) and splitBalance().
  const bool fanExpansions_;
  BitModel fanExpansionModels_[7][kBalanceClasses];
  // The walk's first edge: whether it is a cut, by its direction bucket;
  // else whether its side is not the one its direction says; when it is
  // cut, whether the arc after it is not on the side of the next edge.
  BitModel startCutModels_[4], startSideModels_[4], arcSideModel_;
  // Whether an edge of the walk is a cut, by: cuts so far (0, 1); whether
  // its direction and the next edge's agree with the current arc's side;
  // whether it is the closer of the two to the split plane; the direction
  // buckets of both; whether it is longer than the star's mean; how far it
  // lies from the first cut (cutBand()); edges left (1, 2, 3+).
  static constexpr int kFanCutClasses = 2 * 2 * 2 * 2 * 4 * 4 * 2 * kCutBands * 4;
  BitModel fanCutModels_[kFanCutClasses];
  std::vector<uint8_t> slotSides_;  // per fan position, the code of its triangle
  // Per fan position, the star index of its triangle.
  std::vector<uint32_t> slotTriangles_;
  bool fanExpansionCoded_ = false;  // the split under way was coded by codeFanExpansion()
  std::array<uint32_t, 2> fanCutEntries_{};  // its two cut edges' star indices, ascending
  // Orientation models: [dimension - 2][copy or new][vote class][face of higher].
  BitModel orientationModels_[2][2][3][2];
  std::optional<LabelCoder> labels_;
  double labelBits_ = 0;
  ConnectivityStatistics statistics_;
};

template <class CodeBit>
uint8_t VertexSplitter::binarise(uint8_t possible, uint8_t code, CodeBit&& codeBit) {
  int step = 0;
  for (uint8_t c = 1; c <= 4; ++c) {
    if (!(possible & (1u << (c - 1)))) continue;
    if ((possible >> c) == 0) return c;  // the last candidate left
    if (codeBit(step, c == code)) return c;
    ++step;
  }
  return 0;  // unreachable: `possible` is never empty here
}

template <class Coder>
void VertexSplitter::decideOrientation(Coder& coder, int dimension, uint32_t simplex, const Entry& from,
                                       bool isCopy, uint8_t target) {
  int voteClass = 0;
  const int predicted = predictFlip(dimension, simplex, from, isCopy, voteClass);
  const int faceOfHigher = isFaceOfHigher(dimension, simplex);
  int flip = predicted;
  if (target != split_record::kFree)
    flip = store_.parity(dimension, simplex) != target - split_record::kParity0;
  BitModel& model = orientationModels_[dimension - 2][isCopy][voteClass][faceOfHigher];
  const bool mispredicted = coder.bit(model, flip != predicted);
  flip = predicted ^ int(mispredicted);
  uint8_t& flags = store_.flags(dimension, simplex);
  flags ^= uint8_t(flip * SimplexStore::kFlipped);
  flags &= uint8_t(~SimplexStore::kUndecided);
  if (!facets_[size_t(dimension)].empty()) countDecided(dimension, simplex);
  ++statistics_.orientationBits;
  statistics_.orientationMispredicted += mispredicted;
}

template <class Coder>
bool VertexSplitter::codeEntries(Coder& coder, bool geometric, int balance, int& cutEdges, bool& codedThree) {
  classifyEdges();
  orderCodes(geometric);
  const bool volume = begin_[4] > begin_[3];  // the star holds a tetrahedron
  size_t pairedTriangles = 0;
  const size_t orderedTriangles = geometric ? begin_[3] - begin_[2] : 0;
  for (size_t step = 0; step < codingOrder_.size(); ++step) {
    if (step - begin_[2] < orderedTriangles) {  // unsigned: a triangle at a geometric level
      if (step == begin_[2]) pairedTriangles = countPairedTriangles();
      if (pairedTriangles > 0) takeMostConstrainedTriangle(step);
    }
    const uint32_t index = codingOrder_[step];
    Entry& entry = star_[index];
    const uint8_t possible = possibleCodes(entry);
    if (possible == 0) return false;
    const uint8_t code = uint8_t((entry.record & split_record::kCodeMask) + 1);
    if (entry.dimension == 1) {
      const bool all = possible == 0b1111;
      const int cut = std::min(cutEdges, 2);
      // Edges come right after the vertex in the coding order.
      const size_t edgesLeft = begin_[2] - step;  // this one included
      const bool lastCuts = geometric && cut < 2 && edgesLeft <= size_t(2 - cut);
      const int cutState = lastCuts ? 3 + cut : cut;
      // In a tetrahedral star an edge to v2's half is coded mirrored: the
      // two sides share statistics (surfaces lose by it, their split is not
      // symmetric enough).
      const bool mirrored = volume && geometric && cosines_[index - begin_[1]] > 0;
      if (volume) std::fill(neutral_, neutral_ + 3, BitModel{});
      // Weight vectors by cut state (the last two share one) and whether
      // the star is one closed fan.
      const int mixerSet = std::min(cutState, 3) + 4 * (fanSize_ > 0);
      entry.code = mirrorCode(
          codeEdgeSymbol(coder,
                         {edgeModels_[cutState][mirrorSet(entry.fanCodes, mirrored)][entry.geometry][all],
                          edgeDirectionModels_[entry.geometry][all],
                          volume ? neutral_ : edgeBalanceModels_[balance][entry.geometry][all],
                          edgeRunModels_[runClass(entry, cutEdges, mirrored)][all]},
                         mixerSet, mirrorSet(possible, mirrored), mirrorCode(code, mirrored)),
          mirrored);
      if (entry.code == 4 && cutEdges == 0) firstCut_ = entry.fanIndex;
      cutEdges += entry.code == 4;
      const uint8_t bit = uint8_t(1u << std::min(entry.code - 1, 2));
      if (crowdedFans()) {
        const size_t edge = index - begin_[1];
        for (uint32_t k = fanStart_[edge]; k < fanStart_[edge + 1]; ++k) star_[fanList_[k]].fanCodes |= bit;
      } else {
        for (const uint32_t neighbour : entry.links)
          if (neighbour != kNoSimplex) star_[neighbour].fanCodes |= bit;
      }
    } else if (entry.dimension == 2 && geometric) {
      // Here the triangle has both its edges through v (else
      // possibleCodes() returned 0).
      Entry& first = star_[entry.links[0]];
      Entry& second = star_[entry.links[1]];
      const int slack = pairedTriangles > 0 ? pairingSlack(entry) : kUnpaired;
      const bool paired = slack != kUnpaired;
      // Pairing class: 1 when an edge has its two code-4 triangles, 2 when
      // an edge needs every candidate it has left, 0 otherwise.
      const int pairing = !paired || slack > 0 ? 0 : first.addedTriangles >= 2 || second.addedTriangles >= 2 ? 1 : 2;
      if (paired) {
        --first.pairedTriangles;
        --second.pairedTriangles;
        --pairedTriangles;  // the search for the next ends with the last
        ++statistics_.pairedTriangles;
      }
      // A triangle whose two other vertices lie in v2's half is coded
      // mirrored (the class does not say which half).
      const bool mirrored =
          cosines_[entry.links[0] - begin_[1]] > 0 && cosines_[entry.links[1] - begin_[1]] > 0;
      const uint8_t possibleHere = mirrorSet(possible, mirrored);
      entry.code = mirrorCode(codeSymbol(coder, triangleModels_[pairing][triangleClass(entry)][possibleHere],
                                         possibleHere, mirrorCode(code, mirrored)),
                              mirrored);
      if (entry.code == 4) {
        ++first.addedTriangles;
        ++second.addedTriangles;
      }
    } else if (entry.dimension == 0) {
      entry.code = codeSymbol(coder, vertexModels_[vertexClass(balance)], possible, code);
    } else {
      entry.code = codeSymbol(coder, codeModels_[entry.dimension][possible], possible, code);
    }
    codedThree |= entry.code == 3;
    ++statistics_.codes[entry.dimension][entry.code - 1];
  }

  return true;
}

template <class Coder>
void VertexSplitter::codeFanExpansion(Coder& coder) {
  const int n = fanSize_;
  const size_t firstEdge = begin_[1];
  auto cosineAt = [&](int k) { return cosines_[fanOrder_[size_t(k)] - firstEdge]; };
  // The side an edge's direction points to: 2 for v2's half.
  auto sideAt = [&](int k) { return uint8_t(cosineAt(k) > 0 ? 2 : 1); };
  // The encoder's code of the edge at fan position k (ignored by the decoder).
  auto recorded = [&](int k) { return uint8_t((star_[fanOrder_[size_t(k)]].record & split_record::kCodeMask) + 1); };
  auto bucketAt = [&](int k) { return directionBucket(cosineAt(k)); };
  // The walk starts at the steepest edge, the surest of its side.
  int start = 0;
  double steepest = std::fabs(cosineAt(0));
  for (int k = 1; k < n; ++k) {
    const double steepness = std::fabs(cosineAt(k));
    const bool steeper = steepness > steepest;  // a select, not a branch
    start = steeper ? k : start;
    steepest = steeper ? steepness : steepest;
  }
  slotSides_.resize(size_t(n));
  // Each edge's code goes straight to its star entry.
  auto give = [&](int k, uint8_t code) {
    star_[fanOrder_[size_t(k)]].code = code;
    ++statistics_.codes[1][code - 1];
  };
  int cuts = 0;
  int cutAt[2] = {0, 0};  // the cuts' fan positions, the first once cuts > 0
  uint8_t side;  // of the arc the walk is in
  const int next = fanNext(start);
  if (coder.bit(startCutModels_[bucketAt(start)], recorded(start) == 4)) {
    cutAt[cuts++] = start;
    give(start, 4);
    // The arc after the cut: the next edge's side, or, when that is the
    // other cut, the opposite of the edge after it.
    const uint8_t arc = recorded(next) != 4 ? recorded(next) : uint8_t(3 - recorded(fanNext(next)));
    side = uint8_t(coder.bit(arcSideModel_, arc != sideAt(next)) ? 3 - sideAt(next) : sideAt(next));
  } else {
    side = uint8_t(coder.bit(startSideModels_[bucketAt(start)], recorded(start) != sideAt(start)) ? 3 - sideAt(start)
                                                                                                 : sideAt(start));
    give(start, side);
  }
  slotSides_[size_t(start)] = side;
  for (int step = 1, k = next; step < n; ++step, k = fanNext(k)) {
    const int after = fanNext(k);
    const int left = n - step;  // edges left, this one included
    bool cut = false;
    if (cuts + left == 2) {  // no cut and two edges left, or one and one
      cut = true;  // the cuts still missing must be the last edges
    } else if (cuts < 2) {
      const int band = cuts > 0 ? cutBand(k, cutAt[0]) : 0;
      const bool longer = lengths_[fanOrder_[size_t(k)] - firstEdge] > meanLength_;
      int context = cuts;
      context = context * 2 + (sideAt(k) == side);
      context = context * 2 + (sideAt(after) == side);
      context = context * 2 + (std::fabs(cosineAt(k)) <= std::fabs(cosineAt(after)));
      context = context * 4 + bucketAt(k);
      context = context * 4 + bucketAt(after);
      context = context * 2 + longer;
      context = context * kCutBands + band;
      context = context * 4 + std::min(left, 3);
      cut = coder.bit(fanCutModels_[context], recorded(k) == 4);
    }
    if (cut) {
      cutAt[cuts++] = k;
      side = uint8_t(3 - side);
    }
    give(k, cut ? 4 : side);
    slotSides_[size_t(k)] = side;
  }
  star_[0].code = 4;
  ++statistics_.codes[0][3];
  slotTriangles_.resize(size_t(n));
  for (size_t t = begin_[2]; t < begin_[3]; ++t) {
    const int slot = fanSlot(star_[t]);
    slotTriangles_[size_t(slot)] = uint32_t(t);
    const uint8_t code = slotSides_[size_t(slot)];
    star_[t].code = code;
    ++statistics_.codes[2][code - 1];
  }
  const uint32_t cutA = fanOrder_[size_t(cutAt[0])], cutB = fanOrder_[size_t(cutAt[1])];
  fanCutEntries_ = {std::min(cutA, cutB), std::max(cutA, cutB)};
  fanExpansionCoded_ = true;
  ++statistics_.fanExpansions;
}

template <class Coder, class Oracle, class LabelOracle>
bool VertexSplitter::split(Coder& coder, uint32_t v, uint32_t v2, int level, int balance, Oracle&& oracle,
                           LabelOracle&& labelOracle) {
  newVertex_ = v2;
  if (!gatherClosedFan(v)) {
    gatherStar(store_, v, star_, begin_);
    linkFans();
  }
  measureEdges(v, level);
  const bool geometric = geometry_.geometric(level);
  ++statistics_.vertexSplits;
  int cutEdges = 0;  // edges coded 4: an edge expansion has two
  bool codedThree = false;
  // The encoder's records come in canonical order.
  if constexpr (!std::is_same_v<std::decay_t<Oracle>, NoRecords>)
    for (Entry& entry : star_) entry.record = oracle();
  bool coded = false;
  fanExpansionCoded_ = false;
  if (fanExpansions_ && geometric && closedFanStar()) {
    const int sizeClass = std::min(fanSize_, 9) - 3;
    coded = coder.bit(fanExpansionModels_[sizeClass][balance], recordsFormFanExpansion());
    if (coded) {
      codeFanExpansion(coder);
      cutEdges = 2;
    }
  }
  if (!coded && !codeEntries(coder, geometric, balance, cutEdges, codedThree)) return false;

  statistics_.edgeExpansions += star_[0].code == 4 && cutEdges == 2 && !codedThree;
  if (star_[0].code == 3) {  // v and v2 not joined: is either left in no simplex?
    bool toFirst = false, toSecond = false;
    for (size_t i = 1; i < star_.size(); ++i) {
      toFirst |= star_[i].code != 2;
      toSecond |= star_[i].code != 1;
    }
    if (!toSecond) geometry_.adoptNeighbourhood(v2, v, !toFirst);
    else if (!toFirst) geometry_.adoptNeighbourhood(v, v2, false);
  }
  for (int d = 1; d <= SimplexStore::kMaxDimension; ++d) store_.detach(d, v);
  if (star_[0].code == 4) {
    const uint32_t edge[2] = {v, v2};
    star_[0].added = store_.add(1, edge, 0);
    if (star_[0].added == kNoSimplex) return false;
  }
  // Each entry's simplex goes to v or v2 and joins its list there; those
  // coded 3 or 4 then add their copy at v2 and, for 4, the simplex one
  // dimension up, in star order. Of a fan expansion's entries only its two
  // cut edges are, which it knows without testing each code.
  auto relink = [&](size_t first, size_t last, int d) {
    for (size_t i = first; i < last; ++i) {
      const Entry& entry = star_[i];
      // v stays v unless the code sends the simplex to v2: no branch on the code.
      store_.setVertex(d, entry.simplex, entry.position, entry.code == 2 ? v2 : v);
      if (d == 2) geometry_.forgetAcross(entry.simplex, entry.position);
      store_.link(d, entry.simplex, entry.position);
    }
  };
  auto addChildren = [&](Entry& entry, int d) {
    const uint8_t undecided = d >= 2 ? SimplexStore::kUndecided : 0;
    uint32_t tuple[5];
    std::copy(store_.vertices(d, entry.simplex), store_.vertices(d, entry.simplex) + d + 1, tuple);
    // Edges have no orientation, and nothing flips one (orientations are
    // decided, and twins flipped by the decimation, from triangles up): a
    // cut edge's children start unflipped without loading its flags, which
    // nothing else in the split touches.
    const uint8_t flipped = d == 1 ? 0 : uint8_t(store_.flags(d, entry.simplex) & SimplexStore::kFlipped);
#ifdef KDMESH_CHECK_VOTES
    if ((store_.flags(d, entry.simplex) & SimplexStore::kFlipped) != flipped) std::abort();
#endif
    tuple[entry.position] = v2;
    entry.copy = store_.add(d, tuple, uint8_t(flipped | undecided));
    if (entry.copy == kNoSimplex) return false;
    if (entry.code == 4) {
      tuple[entry.position] = v;
      tuple[d + 1] = v2;
      entry.added = store_.add(d + 1, tuple, uint8_t(flipped | (d + 1 >= 2 ? SimplexStore::kUndecided : 0)));
      if (entry.added == kNoSimplex) return false;
    }
    return true;
  };
  if (fanExpansionCoded_) {
    size_t next = begin_[1];
    for (const uint32_t cut : fanCutEntries_) {
      relink(next, cut + 1, 1);
      if (!addChildren(star_[cut], 1)) return false;
      next = cut + 1;
    }
    relink(next, begin_[2], 1);
    relink(begin_[2], begin_[3], 2);
  } else {
    for (size_t i = 1; i < star_.size(); ++i) {
      const int d = star_[i].dimension;
      relink(i, i + 1, d);
      if (star_[i].code >= 3 && !addChildren(star_[i], d)) return false;
    }
  }

  // around() builds each dimension's lists and facet index again when first
  // asked; a vote that does not ask (triangleNeighbours()) must not find
  // the index of an earlier split.
  aroundReady_.fill(false);
  for (std::vector<FacetEntry>& facets : facets_) facets.clear();
  auto orientAdded = [&](const Entry& entry) {
    decideOrientation(coder, entry.dimension + 1, entry.added, entry, false,
                      uint8_t((entry.record >> split_record::kNewTargetShift) & 3));
  };
  if (fanExpansionCoded_) {
    // Its only new simplices with an orientation: the triangles that the
    // two cut edges added, in star order as below.
    for (const uint32_t cut : fanCutEntries_) orientAdded(star_[cut]);
  } else {
    for (const Entry& entry : star_) {
      const int d = entry.dimension;
      if (entry.copy != kNoSimplex && d >= 2)
        decideOrientation(coder, d, entry.copy, entry, true,
                          uint8_t((entry.record >> split_record::kCopyTargetShift) & 3));
      if (entry.added != kNoSimplex && d + 1 >= 2) orientAdded(entry);
    }
  }
  if (labels_) {
    const double before = coder.cost();
    // Per dimension, whether the star's simplices had more than one label
    // (a split inside a region makes simplices of its label), and the
    // first two labels (a new simplex that does not take its parent's
    // likely takes the other).
    std::array<bool, 4> mixed{};
    std::array<std::array<uint32_t, 2>, 4> seen;
    for (int d = 1; d <= 3; ++d) {
      seen[size_t(d)] = {kNoLabel, kNoLabel};
      if (begin_[size_t(d)] == begin_[size_t(d) + 1]) continue;
      seen[size_t(d)][0] = store_.label(d, star_[begin_[size_t(d)]].simplex);
      for (size_t i = begin_[size_t(d)] + 1; i < begin_[size_t(d) + 1] && !mixed[size_t(d)]; ++i) {
        const uint32_t label = store_.label(d, star_[i].simplex);
        mixed[size_t(d)] = label != seen[size_t(d)][0];
        seen[size_t(d)][1] = label;
      }
    }
    for (const Entry& entry : star_) {
      const int d = entry.dimension;
      // The new edge v v2 has no parent: it takes the star's first edge's place.
      const uint32_t parent = d == 0 ? seen[1][0] : store_.label(d, entry.simplex);
      for (const bool isCopy : {true, false}) {
        const uint32_t simplex = isCopy ? entry.copy : entry.added;
        if (simplex == kNoSimplex) continue;
        const int dimension = isCopy ? d : d + 1;
        const std::array<uint32_t, 2>& both = seen[size_t(dimension)];
        const uint32_t other = both[0] != parent ? both[0] : mixed[size_t(dimension)] ? both[1] : kNoLabel;
        const uint32_t label =
            labels_->code(coder, dimension, isCopy, mixed[size_t(dimension)], parent, other, labelOracle());
        if (label == kNoLabel) return false;
        store_.label(dimension, simplex) = label;
      }
    }
    labelBits_ += coder.cost() - before;
  }
  return true;
}

}  // namespace kdmesh
