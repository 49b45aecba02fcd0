// The encoder with its adaptive models' final states, for learning their
// priors offline (tools/train_priors.cpp).
#pragma once

#include <array>
#include <vector>

#include "kdmesh/kdmesh.h"
#include "model_priors.h"

namespace kdmesh {

struct TrainedModels {
  std::array<std::vector<BitModel>, kModelFamilies> families;  // empty for point clouds
  // Per mixer family, the final weights (kMixerSets × kMixerInputs) and how
  // often each weight vector was used.
  std::array<std::vector<int32_t>, kMixerFamilies> mixerWeights;
  std::array<std::vector<uint32_t>, kMixerFamilies> mixerUses;
};

EncodeResult encode(const Complex& complex, const EncodeOptions& options, TrainedModels* finalModels);

}  // namespace kdmesh
