#include "model_priors.h"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <iterator>

#include "mixer.h"

namespace kdmesh {
namespace {

// The arrays KDMESH_MODEL_FAMILIES names: P(bit == 0) as priorCode(), one
// byte per model, run-length coded (model_priors.h); and those
// KDMESH_MIXER_FAMILIES names: starting mixer weights.
#include "model_priors.inc"

#define KDMESH_CHECK_MIXER_SIZE(name, priors, sets, inputs) static_assert(std::size(priors) == (sets) * (inputs));
KDMESH_MIXER_FAMILIES(KDMESH_CHECK_MIXER_SIZE)

// How many models a run-length coded family primes.
template <size_t kCoded>
constexpr size_t expandedSize(const uint8_t (&coded)[kCoded]) {
  size_t models = 0;
  forEachPriorCode(coded, kCoded, [&models](uint8_t) { ++models; });
  return models;
}

#define KDMESH_CHECK_FAMILY_SIZE(name, priors, size) static_assert(expandedSize(priors) == (size));
KDMESH_MODEL_FAMILIES(KDMESH_CHECK_FAMILY_SIZE)

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
#define KDMESH_MIXER_PRIORS(name, priors, ...) priors,
  static constexpr const int32_t* kPriors[kMixerFamilies] = {KDMESH_MIXER_FAMILIES(KDMESH_MIXER_PRIORS)};
  return kPriors[int(family)];
}

void primeModels(ModelFamily family, BitModel* models) {
#define KDMESH_CODED_FAMILY(name, priors, ...) codedFamily(priors),
  static constexpr CodedFamily kPriors[kModelFamilies] = {KDMESH_MODEL_FAMILIES(KDMESH_CODED_FAMILY)};
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
