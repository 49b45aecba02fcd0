// Coding of the kd-tree counts: how many of the p vertices of a cell fall in
// its first half, a value in [0, p].
//
// The value is binarised by bisection of [0, p]: each binary decision halves
// the interval of candidates, and is coded with an adaptive model chosen by
//   - the population p (exact up to 15, then by its power of two),
//   - the kd-tree level (cell size relative to the sampling density),
//   - whether the parent split sent all its vertices to one side, and
//   - the node of the bisection tree (the decisions taken so far),
//   - and, in a complex, a class of the cell's neighbourhood
//     (PositionPredictor::countContext) and where the neighbours'
//     parallelogram predictions put the cell's vertex (after a one-sided
//     parent split), whose models are mixed with the one above.
//     Populations above 15 share one neighbourhood model per class and
//     tree node: few cells are that large, and a row per bit width of the
//     population learns more slowly,
//   - and by where the neighbours lie along the split axis, and which of
//     them have split at this level already (PositionPredictor::
//     refinementClass), a fourth model mixed in.
// After six decisions the few remaining candidates of a large cell are nearly
// equiprobable and are coded uniformly.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "mixer.h"
#include "model_priors.h"
#include "range_coder.h"

namespace kdmesh {

// What the neighbourhood of a cell says about its split
// (PositionPredictor::countContext): a class 1..kNeighbourhoodClasses-1 (0:
// nothing), and whether the prediction favours the first half, in which case
// the count of the second half is coded instead (mirroring).
struct CountContext {
  static constexpr int kElongationGroups = 3;
  int neighbourhoodClass = 0;
  bool mirrored = false;
  // How the neighbours spread along the split axis (0..2), which picks the
  // mixer weights of a class.
  int elongation = 0;
  // Where the neighbours' parallelogram predictions put the cell's vertex
  // (PositionPredictor), kParallelogramBuckets - 1 for nowhere.
  static constexpr int kParallelogramBuckets = 12;
  int parallelogram = kParallelogramBuckets - 1;
  // Where the neighbours lie along the split axis, and which have split at
  // this level already (PositionPredictor::refinementClass without the far
  // halves), 0..kRefinementClasses-1.
  static constexpr int kRefinementClasses = 1024;
  int refinement = 0;
};

class CountCoder {
 public:
  static constexpr int kNeighbourhoodClasses = 13;

  // `neighbourhoods`: code() may be given neighbourhood classes (streams
  // with connectivity).
  CountCoder(int levels, bool neighbourhoods)
      : levels_(levels < 1 ? 1 : levels),
        mixer_(CountContext::kElongationGroups * kNeighbourhoodClasses, mixerPriors(MixerFamily::CellCounts)) {
    static_assert(size_t(CountContext::kElongationGroups) * kNeighbourhoodClasses ==
                      kMixerSets[int(MixerFamily::CellCounts)] &&
                  kMixerInputs[int(MixerFamily::CellCounts)] == 4);
    models_.resize(size_t(levels_) * kParentClasses * kContextsPerLevel);
    static_assert(size_t(kNeighbourhoodClasses) * kNeighbourhoodNodes == kFamilySize[int(ModelFamily::CellCounts)]);
    if (neighbourhoods) {
      neighbourhoodModels_.resize(kFamilySize[int(ModelFamily::CellCounts)]);
      static_assert(size_t(kPopulationGroups) * CountContext::kParallelogramBuckets * kParallelogramNodes ==
                    kFamilySize[int(ModelFamily::CellCountsByParallelogram)]);
      parallelogramModels_.resize(kFamilySize[int(ModelFamily::CellCountsByParallelogram)]);
      static_assert(size_t(CountContext::kRefinementClasses) * kRefinementNodes ==
                    kFamilySize[int(ModelFamily::CellCountsByRefinement)]);
      refinementModels_.resize(kFamilySize[int(ModelFamily::CellCountsByRefinement)]);
      forEachFamily(primeModels);
    }
  }

  // Its model families with learned priors (none without neighbourhoods)
  // and its mixer, as PositionPredictor::forEachFamily() lists its own.
  template <class Visit>
  void forEachFamily(Visit&& visit) {
    if (neighbourhoodModels_.empty()) return;
    visit(ModelFamily::CellCounts, neighbourhoodModels_.data());
    visit(ModelFamily::CellCountsByParallelogram, parallelogramModels_.data());
    visit(ModelFamily::CellCountsByRefinement, refinementModels_.data());
  }
  template <class Visit>
  void forEachMixer(Visit&& visitMixer) const {
    visitMixer(MixerFamily::CellCounts, mixer_);
  }

  // The count of a one-vertex cell, 1 when the vertex is in the first half;
  // the same model as code() with population 1, in a loop-free form.
  template <class Coder>
  bool codeSingle(Coder& coder, int level, bool parentOneSided, bool inFirstHalf) {
    return coder.bit(models_[(size_t(level) * kParentClasses + parentOneSided) *
                                 kContextsPerLevel + 1],
                     inFirstHalf);
  }

  // `parentOneSided`: the parent cell's split left one half empty.
  // On the encoder returns `firstHalf`; on the decoder returns the decoded count.
  template <class Coder>
  uint32_t code(Coder& coder, uint32_t population, int level, bool parentOneSided,
                uint32_t firstHalf, const CountContext& context = {}) {
    const uint32_t coded = codeOrdered(coder, population, level, parentOneSided,
                                       context.mirrored ? population - firstHalf : firstHalf, context);
    return context.mirrored ? population - coded : coded;
  }

 private:
  template <class Coder>
  uint32_t codeOrdered(Coder& coder, uint32_t population, int level, bool parentOneSided,
                       uint32_t firstHalf, const CountContext& context) {
    const int neighbourhoodClass = context.neighbourhoodClass;
    BitModel* models = &models_[(size_t(level) * kParentClasses + parentOneSided) * kContextsPerLevel +
                                populationOffset(population)];
    // With a neighbourhood class, each decision mixes the class's model with
    // the level's.
    BitModel* byNeighbourhood =
        neighbourhoodClass > 0
            ? &neighbourhoodModels_[size_t(neighbourhoodClass) * kNeighbourhoodNodes +
                                    (population <= kExactPopulations ? populationOffset(population) : kSmallNodes)]
            : nullptr;
    // And with the model of where the parallelogram predictions put the
    // cell's vertex, by population group (2, 3, 4-7, more) and tree node
    // (from the 15th on, one model).
    const int populationGroup = population <= 2 ? 0 : population == 3 ? 1 : population <= 7 ? 2 : 3;
    BitModel* byParallelogram =
        neighbourhoodClass > 0
            ? &parallelogramModels_[size_t(populationGroup * CountContext::kParallelogramBuckets +
                                           context.parallelogram) *
                                    kParallelogramNodes]
            : nullptr;
    // And with the model of where the neighbours lie along the split axis,
    // by tree node (the root, the two of the second decision, then one;
    // not by population group as well, whose priors cost more than they
    // gain: docs/EXPERIMENTS.md).
    BitModel* byRefinement =
        neighbourhoodClass > 0 ? &refinementModels_[size_t(context.refinement) * kRefinementNodes] : nullptr;
    uint32_t low = 0, candidates = population + 1, node = 1;
    while (candidates > 1) {
      if (node >= kTreeNodes)
        return low + coder.uniform(firstHalf - low, candidates);
      const uint32_t lowerHalf = candidates >> 1;
      bool upper = firstHalf - low >= lowerHalf;
      if (byNeighbourhood)
        upper = mixer_.code(coder, context.elongation * kNeighbourhoodClasses + neighbourhoodClass,
                            {&byNeighbourhood[node], &models[node],
                             &byParallelogram[std::min(node, kParallelogramNodes - 1)],
                             &byRefinement[std::min(node, kRefinementNodes) - 1]},
                            upper);
      else
        upper = coder.bit(models[node], upper);
      if (upper) {
        low += lowerHalf;
        candidates -= lowerHalf;
      } else {
        candidates = lowerHalf;
      }
      node = node * 2 + upper;
    }
    return low;
  }

  static constexpr uint32_t kExactPopulations = 15;  // p = 1..15 get own models
  static constexpr uint32_t kTreeNodes = 64;         // six bisection levels
  static constexpr uint32_t kParentClasses = 2;
  // Populations 1..15 need 2^ceil(log2(p+1)) nodes; larger ones, grouped by
  // bit width 5..32, use the full tree.
  static constexpr uint32_t kSmallNodes = 2 + 4 * 2 + 8 * 4 + 16 * 8;
  static constexpr uint32_t kContextsPerLevel = kSmallNodes + 28 * kTreeNodes;
  static constexpr uint32_t kNeighbourhoodNodes = kSmallNodes + kTreeNodes;
  static constexpr int kPopulationGroups = 4;
  static constexpr uint32_t kParallelogramNodes = 16;
  static constexpr uint32_t kRefinementNodes = 4;

  static uint32_t populationOffset(uint32_t p) {
    if (p <= kExactPopulations) {
      // Populations with the same tree size are laid out consecutively.
      if (p == 1) return 0;
      if (p <= 3) return 2 + (p - 2) * 4;
      if (p <= 7) return 10 + (p - 4) * 8;
      return 42 + (p - 8) * 16;
    }
    int width = 0;
    for (uint32_t v = p; v != 0; v >>= 1) ++width;
    return kSmallNodes + uint32_t(width - 5) * kTreeNodes;
  }

  int levels_;
  std::vector<BitModel> models_, neighbourhoodModels_, parallelogramModels_, refinementModels_;
  Mixer<4> mixer_;
};

}  // namespace kdmesh
