#include "model_priors.h"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <iterator>

#include "mixer.h"

namespace kdmesh {
namespace {

// kOneVertexSplitPriors, kEdgeCodePriors, kCellCountPriors,
// kOneVertexByPlanePriors, kOneVertexByCentroidPriors,
// kEdgeCodeByDirectionPriors, kTriangleCodePriors,
// kOneVertexByParallelogramPriors, kCellCountByParallelogramPriors,
// kEdgeCodeByBalancePriors, kEdgeCodeByRunPriors, kVertexCodePriors,
// kOneVertexByRefinementPriors, kCellCountByRefinementPriors: P(bit == 0) as
// priorCode(), one byte per model, run-length coded (model_priors.h);
// kOneVertexMixerPriors, kCellCountMixerPriors,
// kOneVertexByParallelogramMixerPriors,
// kOneVertexByPlaneAndCentroidMixerPriors, kEdgeCodeMixerPriors: starting
// mixer weights.
#include "model_priors.inc"

static_assert(std::size(kOneVertexMixerPriors) == kMixerSets[0] * kMixerInputs[0]);
static_assert(std::size(kCellCountMixerPriors) == kMixerSets[1] * kMixerInputs[1]);
static_assert(std::size(kOneVertexByParallelogramMixerPriors) == kMixerSets[2] * kMixerInputs[2]);
static_assert(std::size(kOneVertexByPlaneAndCentroidMixerPriors) == kMixerSets[3] * kMixerInputs[3]);
static_assert(std::size(kEdgeCodeMixerPriors) == kMixerSets[4] * kMixerInputs[4]);

// How many models a run-length coded family primes.
template <size_t kCoded>
constexpr size_t expandedSize(const uint8_t (&coded)[kCoded]) {
  size_t models = 0;
  forEachPriorCode(coded, kCoded, [&models](uint8_t) { ++models; });
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
static_assert(expandedSize(kEdgeCodeByRunPriors) == kFamilySize[10]);
static_assert(expandedSize(kVertexCodePriors) == kFamilySize[11]);
static_assert(expandedSize(kOneVertexByRefinementPriors) == kFamilySize[12]);
static_assert(expandedSize(kCellCountByRefinementPriors) == kFamilySize[13]);

struct CodedFamily {
  const uint8_t* values;
  size_t size;
};
template <size_t kCoded>
constexpr CodedFamily codedFamily(const uint8_t (&coded)[kCoded]) {
  return {coded, kCoded};
}

}  // namespace

// The nearest code (the first of equals): the inverse of priorOfCode(), so
// that writing compiled priors back gives the same codes.
uint8_t priorCode(uint32_t probabilityOfZero) {
  uint8_t best = 1;
  int bestDistance = INT32_MAX;
  for (int code = 1; code <= 255; ++code) {
    const int distance = std::abs(int(priorOfCode(uint8_t(code))) - int(probabilityOfZero));
    if (distance < bestDistance) {
      best = uint8_t(code);
      bestDistance = distance;
    }
  }
  return best;
}

uint16_t priorOfCode(uint8_t code) {
  const uint32_t p = uint32_t(Logistic::squash((int(code) - 128) * 16)) << 3;
  return uint16_t(std::clamp<uint32_t>(p, 31, kProbabilityOne - 31));
}

const int32_t* mixerPriors(MixerFamily family) {
  static constexpr const int32_t* kPriors[kMixerFamilies] = {kOneVertexMixerPriors, kCellCountMixerPriors,
                                                             kOneVertexByParallelogramMixerPriors,
                                                             kOneVertexByPlaneAndCentroidMixerPriors,
                                                             kEdgeCodeMixerPriors};
  return kPriors[int(family)];
}

void primeModels(ModelFamily family, BitModel* models) {
  static constexpr CodedFamily kPriors[kModelFamilies] = {
      codedFamily(kOneVertexSplitPriors),      codedFamily(kEdgeCodePriors),
      codedFamily(kCellCountPriors),           codedFamily(kOneVertexByPlanePriors),
      codedFamily(kOneVertexByCentroidPriors), codedFamily(kEdgeCodeByDirectionPriors),
      codedFamily(kTriangleCodePriors),        codedFamily(kOneVertexByParallelogramPriors),
      codedFamily(kCellCountByParallelogramPriors), codedFamily(kEdgeCodeByBalancePriors),
      codedFamily(kEdgeCodeByRunPriors), codedFamily(kVertexCodePriors),
      codedFamily(kOneVertexByRefinementPriors), codedFamily(kCellCountByRefinementPriors)};
  const CodedFamily& coded = kPriors[int(family)];
  forEachPriorCode(coded.values, coded.size, [&models](uint8_t code) {
    models->fast = models->slow = priorOfCode(code);
    models->seen = kPriorObservations;
    ++models;
  });
}

std::vector<uint8_t> runLengthCodePriors(const std::vector<uint8_t>& codes) {
  std::vector<uint8_t> coded;
  constexpr size_t kNoRun = SIZE_MAX, kLongestRun = 0xffff;
  size_t runAt = kNoRun;  // the marker of the run coded ends in
  for (const uint8_t code : codes) {
    if (code != kHalfPriorCode) {
      runAt = kNoRun;
      coded.push_back(code);
    } else if (runAt != kNoRun && priorRunLength(coded.data(), runAt) < kLongestRun) {
      const size_t length = priorRunLength(coded.data(), runAt) + 1;
      coded[runAt + 1] = uint8_t(length & 0xff);
      coded[runAt + 2] = uint8_t(length >> 8);
    } else {
      runAt = coded.size();
      coded.insert(coded.end(), {kPriorRunMarker, 1, 0});
    }
  }
  return coded;
}

}  // namespace kdmesh
