// Starting probabilities for the adaptive models that have many contexts.
//
// A context seen a few times in a small model codes its first symbols near
// 1/2 while it learns; the statistics of these contexts (where an edge goes
// given its direction, where a vertex lies given its neighbourhood) are much
// the same from one surface to the next, so they start from probabilities
// learned offline instead: scripts/train-priors.sh encodes meshes that are
// not in the benchmark tables and averages the final states of the models
// (tools/train_priors.cpp), writing model_priors.inc. The priors are part
// of the stream format: changing them changes every stream.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "range_coder.h"

namespace kdmesh {

enum class ModelFamily {
  OneVertexSplits,
  EdgeCodes,
  CellCounts,
  OneVertexByPlane,
  OneVertexByCentroid,
  EdgeCodesByDirection,
  TriangleCodes,
  OneVertexByParallelogram,
  CellCountsByParallelogram,
};
constexpr int kModelFamilies = 9;
constexpr std::array<size_t, kModelFamilies> kFamilySize = {9000, 11760, 3042, 300, 250, 294, 864, 648, 768};

// model_priors.inc holds each family run-length coded: half the models of
// the large families were never used in training and start at 1/2; a run of
// them is the pair (kPriorRunMarker, run length). Priors are clamped to
// [31, 2^15 - 31], so the marker is no prior.
constexpr uint16_t kPriorRunMarker = 0;

// As many observations as a prior is worth: the slow estimator then starts
// at a moderate rate and still follows the model at hand.
constexpr uint16_t kPriorObservations = 24;

// Sets `models` (kFamilySize of the family) to the family's priors, each
// held with the confidence of kPriorObservations observations.
void primeModels(ModelFamily family, BitModel* models);

}  // namespace kdmesh
