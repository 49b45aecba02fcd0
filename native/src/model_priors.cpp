#include "model_priors.h"

namespace kdmesh {
namespace {

// kOneVertexSplitPriors, kEdgeCodePriors, kCellCountPriors,
// kOneVertexByPlanePriors, kOneVertexByCentroidPriors,
// kEdgeCodeByDirectionPriors, kTriangleCodePriors: P(bit == 0) in units of
// 2^-15, one per model.
#include "model_priors.inc"

static_assert(sizeof(kOneVertexSplitPriors) / sizeof(uint16_t) == kFamilySize[0]);
static_assert(sizeof(kEdgeCodePriors) / sizeof(uint16_t) == kFamilySize[1]);
static_assert(sizeof(kCellCountPriors) / sizeof(uint16_t) == kFamilySize[2]);
static_assert(sizeof(kOneVertexByPlanePriors) / sizeof(uint16_t) == kFamilySize[3]);
static_assert(sizeof(kOneVertexByCentroidPriors) / sizeof(uint16_t) == kFamilySize[4]);
static_assert(sizeof(kEdgeCodeByDirectionPriors) / sizeof(uint16_t) == kFamilySize[5]);
static_assert(sizeof(kTriangleCodePriors) / sizeof(uint16_t) == kFamilySize[6]);

}  // namespace

void primeModels(ModelFamily family, BitModel* models) {
  static const uint16_t* const kPriors[kModelFamilies] = {kOneVertexSplitPriors, kEdgeCodePriors,
                                                          kCellCountPriors, kOneVertexByPlanePriors,
                                                          kOneVertexByCentroidPriors, kEdgeCodeByDirectionPriors,
                                                          kTriangleCodePriors};
  const uint16_t* priors = kPriors[int(family)];
  for (size_t i = 0; i < kFamilySize[size_t(family)]; ++i) {
    models[i].fast = models[i].slow = priors[i];
    models[i].seen = kPriorObservations;
  }
}

}  // namespace kdmesh
