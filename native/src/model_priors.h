// Starting probabilities for the adaptive models that have many contexts,
// and starting weights for the mixers.
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
#include <vector>

#include "range_coder.h"

namespace kdmesh {

// Every family of models with learned priors, declared once: its name, the
// array of model_priors.inc that holds its priors, and how many models it
// has. The enumeration, the sizes, the priming and the trainer read this
// list; the classes that own the models list theirs with forEachFamily().
#define KDMESH_MODEL_FAMILIES(X)                                   \
  X(OneVertexSplits, kOneVertexSplitPriors, 9000)                  \
  X(EdgeCodes, kEdgeCodePriors, 11760)                             \
  X(CellCounts, kCellCountPriors, 3042)                            \
  X(OneVertexByPlane, kOneVertexByPlanePriors, 300)                \
  X(OneVertexByCentroid, kOneVertexByCentroidPriors, 250)          \
  X(EdgeCodesByDirection, kEdgeCodeByDirectionPriors, 294)         \
  X(TriangleCodes, kTriangleCodePriors, 864)                       \
  X(OneVertexByParallelogram, kOneVertexByParallelogramPriors, 648) \
  X(CellCountsByParallelogram, kCellCountByParallelogramPriors, 768) \
  X(EdgeCodesByBalance, kEdgeCodeByBalancePriors, 2646)            \
  X(EdgeCodesByRun, kEdgeCodeByRunPriors, 1980)                    \
  X(VertexCodes, kVertexCodePriors, 36)                            \
  X(OneVertexByRefinement, kOneVertexByRefinementPriors, 8192)     \
  X(CellCountsByRefinement, kCellCountByRefinementPriors, 4096)  \
  X(OneVertexAlongAxis, kOneVertexAlongAxisPriors, 4096)

#define KDMESH_FAMILY_NAME(name, priors, ...) name,
#define KDMESH_FAMILY_SIZE(name, priors, size) size_t{size},
enum class ModelFamily { KDMESH_MODEL_FAMILIES(KDMESH_FAMILY_NAME) };
constexpr std::array kFamilySize = {KDMESH_MODEL_FAMILIES(KDMESH_FAMILY_SIZE)};
constexpr int kModelFamilies = int(kFamilySize.size());

// model_priors.inc holds each family run-length coded: half the models of
// the large families were never used in training and start at 1/2; a run of
// them is kPriorRunMarker followed by the run's length in two bytes, low
// byte first. Prior codes are 1..255, so the marker is no prior.
constexpr uint8_t kPriorRunMarker = 0;

// Priors are stored one byte each, as their logit: code q stands for
// P(0) = squash((q − 128) · 16) · 8 in units of 2^-15 (mixer.h's logistic
// functions, exact integers), q in 1..255; 128 is exactly 1/2. Half the
// size of 15-bit probabilities in the WebAssembly module, and fine where a
// prior's precision matters, near 0 and 1, where a byte of plain
// probability would step coarsely.
constexpr uint8_t kHalfPriorCode = 128;
uint8_t priorCode(uint32_t probabilityOfZero);
uint16_t priorOfCode(uint8_t code);

// The run-length coding of a family's prior codes (one per model) as
// model_priors.inc holds it, written by the trainer.
std::vector<uint8_t> runLengthCodePriors(const std::vector<uint8_t>& codes);
// The length of the run whose marker is at coded[marker].
constexpr size_t priorRunLength(const uint8_t* coded, size_t marker) {
  return size_t(coded[marker + 1]) | size_t(coded[marker + 2]) << 8;
}
// Reads the coding back: visit(code) for each model in turn.
template <class Visit>
constexpr void forEachPriorCode(const uint8_t* coded, size_t size, Visit&& visit) {
  for (size_t i = 0; i < size; ++i) {
    if (coded[i] == kPriorRunMarker) {
      for (size_t run = priorRunLength(coded, i); run > 0; --run) visit(kHalfPriorCode);
      i += 2;
    } else {
      visit(coded[i]);
    }
  }
}

// As many observations as a prior is worth: the slow estimator then starts
// at a moderate rate and still follows the model at hand.
constexpr uint16_t kPriorObservations = 24;

// The mixers whose starting weights are learned the same way (the final
// weights of each weight vector, averaged over the training meshes by how
// often the vector was used): a small model's mixer codes many of its bits
// before its weights have moved far from any fixed start. One-vertex
// splits average three mixers
// (codeWithMixers in mixer.h), with weight vectors chosen by the
// neighbourhood's scale, elongation and agreement, by the parallelogram
// bucket, and by the centroid and plane buckets; edge codes mix four rows
// of models (VertexSplitter::split).
// Declared once as the model families are: name, array of starting
// weights in model_priors.inc, weight vectors, inputs.
#define KDMESH_MIXER_FAMILIES(X)                                           \
  X(OneVertexSplits, kOneVertexMixerPriors, 45, 6)                         \
  X(CellCounts, kCellCountMixerPriors, 39, 4)                              \
  X(OneVertexByParallelogram, kOneVertexByParallelogramMixerPriors, 12, 6) \
  X(OneVertexByPlaneAndCentroid, kOneVertexByPlaneAndCentroidMixerPriors, 60, 6) \
  X(EdgeCodes, kEdgeCodeMixerPriors, 8, 4)

#define KDMESH_MIXER_SETS(name, priors, sets, inputs) size_t{sets},
#define KDMESH_MIXER_INPUTS(name, priors, sets, inputs) size_t{inputs},
enum class MixerFamily { KDMESH_MIXER_FAMILIES(KDMESH_FAMILY_NAME) };
constexpr std::array kMixerSets = {KDMESH_MIXER_FAMILIES(KDMESH_MIXER_SETS)};
constexpr std::array kMixerInputs = {KDMESH_MIXER_FAMILIES(KDMESH_MIXER_INPUTS)};
constexpr int kMixerFamilies = int(kMixerSets.size());
// The starting weights of a mixer family: kMixerSets × kMixerInputs values,
// weight vector by weight vector, in units of 2^-16.
const int32_t* mixerPriors(MixerFamily family);

// Sets `models` (kFamilySize of the family) to the family's priors, each
// held with the confidence of kPriorObservations observations.
void primeModels(ModelFamily family, BitModel* models);

}  // namespace kdmesh
