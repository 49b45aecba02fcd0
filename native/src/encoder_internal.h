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
};

EncodeResult encode(const Complex& complex, const EncodeOptions& options, TrainedModels* finalModels);

}  // namespace kdmesh
