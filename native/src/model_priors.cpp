#include "model_priors.h"

#include <iterator>

namespace kdmesh {
namespace {

// kOneVertexSplitPriors, kEdgeCodePriors, kCellCountPriors,
// kOneVertexByPlanePriors, kOneVertexByCentroidPriors,
// kEdgeCodeByDirectionPriors, kTriangleCodePriors,
// kOneVertexByParallelogramPriors, kCellCountByParallelogramPriors,
// kEdgeCodeByBalancePriors: P(bit == 0) in units of 2^-15, one per model,
// run-length coded (model_priors.h);
// kOneVertexMixerPriors, kCellCountMixerPriors,
// kOneVertexByParallelogramMixerPriors,
// kOneVertexByPlaneAndCentroidMixerPriors: starting mixer weights.
#include "model_priors.inc"

static_assert(std::size(kOneVertexMixerPriors) == kMixerSets[0] * kMixerInputs[0]);
static_assert(std::size(kCellCountMixerPriors) == kMixerSets[1] * kMixerInputs[1]);
static_assert(std::size(kOneVertexByParallelogramMixerPriors) == kMixerSets[2] * kMixerInputs[2]);
static_assert(std::size(kOneVertexByPlaneAndCentroidMixerPriors) == kMixerSets[3] * kMixerInputs[3]);

// How many models a run-length coded family primes.
template <size_t kCoded>
constexpr size_t expandedSize(const uint16_t (&coded)[kCoded]) {
  size_t models = 0;
  for (size_t i = 0; i < kCoded; ++i) {
    if (coded[i] == kPriorRunMarker) {
      models += coded[++i];
    } else {
      ++models;
    }
  }
  return models;
}

static_assert(expandedSize(kOneVertexSplitPriors) == kFamilySize[0]);
static_assert(expandedSize(kEdgeCodePriors) == kFamilySize[1]);
static_assert(expandedSize(kCellCountPriors) == kFamilySize[2]);
static_assert(expandedSize(kOneVertexByPlanePriors) == kFamilySize[3]);
static_assert(expandedSize(kOneVertexByCentroidPriors) == kFamilySize[4]);
static_assert(expandedSize(kEdgeCodeByDirectionPriors) == kFamilySize[5]);
static_assert(expandedSize(kTriangleCodePriors) == kFamilySize[6]);
static_assert(expandedSize(kOneVertexByParallelogramPriors) == kFamilySize[7]);
static_assert(expandedSize(kCellCountByParallelogramPriors) == kFamilySize[8]);
static_assert(expandedSize(kEdgeCodeByBalancePriors) == kFamilySize[9]);

struct CodedFamily {
  const uint16_t* values;
  size_t size;
};
template <size_t kCoded>
constexpr CodedFamily codedFamily(const uint16_t (&coded)[kCoded]) {
  return {coded, kCoded};
}

}  // namespace

const int32_t* mixerPriors(MixerFamily family) {
  static constexpr const int32_t* kPriors[kMixerFamilies] = {kOneVertexMixerPriors, kCellCountMixerPriors,
                                                             kOneVertexByParallelogramMixerPriors,
                                                             kOneVertexByPlaneAndCentroidMixerPriors};
  return kPriors[int(family)];
}

void primeModels(ModelFamily family, BitModel* models) {
  static constexpr CodedFamily kPriors[kModelFamilies] = {
      codedFamily(kOneVertexSplitPriors),      codedFamily(kEdgeCodePriors),
      codedFamily(kCellCountPriors),           codedFamily(kOneVertexByPlanePriors),
      codedFamily(kOneVertexByCentroidPriors), codedFamily(kEdgeCodeByDirectionPriors),
      codedFamily(kTriangleCodePriors),        codedFamily(kOneVertexByParallelogramPriors),
      codedFamily(kCellCountByParallelogramPriors), codedFamily(kEdgeCodeByBalancePriors)};
  const CodedFamily& coded = kPriors[int(family)];
  auto prime = [&models](uint16_t prior) {
    models->fast = models->slow = prior;
    models->seen = kPriorObservations;
    ++models;
  };
  for (size_t i = 0; i < coded.size; ++i) {
    if (coded.values[i] == kPriorRunMarker) {
      for (uint16_t run = coded.values[++i]; run > 0; --run) prime(uint16_t(kProbabilityOne / 2));
    } else {
      prime(coded.values[i]);
    }
  }
}

}  // namespace kdmesh
