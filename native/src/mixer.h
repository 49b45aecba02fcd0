// Logistic mixing of binary predictions, in the manner of the PAQ family of
// compressors: each input model's probability is mapped to the logistic
// domain (stretched), a weighted sum of them is mapped back (squashed), and
// the weights learn online, each step following the gradient of the coding
// cost. Integer arithmetic throughout, so that the encoder and every decoder
// (native or WebAssembly) agree bit for bit.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "range_coder.h"

namespace kdmesh {

// Probabilities in 12 bits, logistic values in [-2047, 2047] (units of 1/256).
class Logistic {
 public:
  // 4096 / (1 + e^(-d/256)), interpolated linearly between knots every 128
  // units and rounded; d is clamped to [-2047, 2047]. The definition; the
  // coders read it from a table (squash()).
  static constexpr int interpolatedSquash(int d) {
    if (d > 2047) d = 2047;
    if (d < -2047) d = -2047;
    const int i = (d + 2048) >> 7, w = (d + 2048) & 127;
    return (kKnots[i] * (128 - w) + kKnots[i + 1] * w + 64) >> 7;
  }
  static int squash(int d);
  static int stretch(int p);

 private:
  // 4096 / (1 + e^(-d/256)) at d = -2048, -1920, ..., 2048, rounded. A
  // static member: a table local to a function was rebuilt on the stack at
  // every call.
  static constexpr int kKnots[33] = {1,    2,    4,    6,    10,   17,   27,   45,   74,   120,  194,
                                     311,  488,  747,  1102, 1546, 2048, 2550, 2994, 3349, 3608, 3785,
                                     3902, 3976, 4022, 4051, 4069, 4079, 4086, 4090, 4092, 4094, 4095};
};

// interpolatedSquash() at d = -2047..2047, built by the compiler: one load
// where the interpolation takes a dozen operations, four times a mixed bit.
struct SquashTable {
  std::array<int16_t, 4095> values{};
  constexpr SquashTable() {
    for (int d = -2047; d <= 2047; ++d) values[size_t(d + 2047)] = int16_t(Logistic::interpolatedSquash(d));
  }
};
inline constexpr SquashTable kSquashTable{};

inline int Logistic::squash(int d) {
  const int clamped = d < -2047 ? -2047 : d > 2047 ? 2047 : d;
  return kSquashTable.values[size_t(clamped + 2047)];
}

// The inverse of squash: for each p, the smallest d with squash(d) >= p.
// Built by the compiler: a table made on first use cost a guard test on
// every call. It covers p = 0..4096, every probability a BitModel can
// hold in 12 bits, the ends as 1 and 4095 (certainty is not mixed), so
// that a model's probability is stretched without a clamp.
struct StretchTable {
  std::array<int16_t, 4097> values{};
  constexpr StretchTable() {
    int p = 0;
    for (int d = -2047; d <= 2047; ++d)
      for (const int s = Logistic::interpolatedSquash(d); p <= s && p < 4096; ++p) values[size_t(p)] = int16_t(d);
    for (; p < 4096; ++p) values[size_t(p)] = 2047;
    values[0] = values[1];
    values[4096] = values[4095];
  }
};
inline constexpr StretchTable kStretchTable{};

inline int Logistic::stretch(int p) { return kStretchTable.values[size_t(p)]; }

template <int kInputs>
class Mixer;
template <class Coder, int kInputs, size_t kMixers>
bool codeWithMixers(Coder& coder, const std::array<Mixer<kInputs>*, kMixers>& mixers,
                    const std::array<int, kMixers>& sets, const std::array<BitModel*, kInputs>& inputs,
                    bool bit);

// Mixes kInputs models with one of `sets` weight vectors (in units of
// 2^-16), which all start at `initial`, or start at `sets` × kInputs values
// given vector by vector (learned offline: model_priors.h).
template <int kInputs>
class Mixer {
 public:
  // Weights and stretched inputs are stored in whole groups of eight
  // lanes, the lanes past kInputs zero: the weight update is then a few
  // vector operations (compilers vectorize a loop of eight 16-bit products,
  // not one of six), and a zero input leaves its weight at zero.
  static constexpr int kLanes = (kInputs + 7) / 8 * 8;
  using Weights = std::array<int32_t, kLanes>;
  using Stretched = std::array<int16_t, kLanes>;

  Mixer(int sets, const std::array<int32_t, kInputs>& initial) : weights_(size_t(sets)), uses_(size_t(sets)) {
    for (Weights& set : weights_) std::copy(initial.begin(), initial.end(), set.begin());
  }
  Mixer(int sets, const int32_t* initial) : weights_(size_t(sets)), uses_(size_t(sets)) {
    for (Weights& set : weights_)
      for (int i = 0; i < kInputs; ++i) set[size_t(i)] = *initial++;
  }

  // Per set, the weights of the kInputs inputs (then zeros to kLanes).
  const std::vector<Weights>& weights() const { return weights_; }
  // The same, set after set, without the zero lanes.
  void appendWeights(std::vector<int32_t>& out) const {
    for (const Weights& set : weights_) out.insert(out.end(), set.begin(), set.begin() + kInputs);
  }
  // How many bits each weight vector has mixed (what training averages the
  // learned starting weights by).
  const std::vector<uint32_t>& uses() const { return uses_; }

  // The mix of `inputs` in the logistic domain, clamped to [-2047, 2047].
  int logit(int set, const std::array<BitModel*, kInputs>& inputs) {
    for (int i = 0; i < kInputs; ++i)
      stretched_[size_t(i)] = Logistic::stretch(int(inputs[size_t(i)]->probabilityOfZero() >> 3));
    return logitOfStretched(set);
  }
  // The same for inputs another mixer has stretched already.
  int logit(int set, const Stretched& stretched) {
    stretched_ = stretched;
    return logitOfStretched(set);
  }
  const Stretched& stretched() const { return stretched_; }

  // P(bit == 0) in units of 2^-15 for the coder.
  uint32_t mix(int set, const std::array<BitModel*, kInputs>& inputs) {
    logit(set, inputs);
    return probabilityOfZero(mixed_);
  }

  // A squashed mix as P(0) in units of 2^-15, kept off certainty.
  static uint32_t probabilityOfZero(int squashed) {
    const uint32_t p0 = uint32_t(squashed) << 3;
    return p0 < 64 ? 64 : p0 > kProbabilityOne - 64 ? kProbabilityOne - 64 : p0;
  }

  // Codes `bit` (encoder; the decoder returns the decoded bit) with the mix
  // of `inputs`, then updates the inputs and the weights: codeWithMixers()
  // with this mixer alone.
  template <class Coder>
  [[gnu::always_inline]] bool code(Coder& coder, int set, const std::array<BitModel*, kInputs>& inputs, bool bit) {
    return codeWithMixers<Coder, kInputs, 1>(coder, {this}, {set}, inputs, bit);
  }

  void update(bool bit) {
    // A small rate: the inputs are adaptive models already, the weights
    // only settle how far to trust each.
    const int16_t error = int16_t((bit ? 0 : 4095) - mixed_);
    Weights& weights = weights_[size_t(set_)];
    for (int i = 0; i < kLanes; ++i) weights[size_t(i)] += (int32_t(stretched_[size_t(i)]) * error) >> 10;
  }

 private:
  int logitOfStretched(int set) {
    set_ = set;
    ++uses_[size_t(set)];
    int64_t dot = 0;
    for (int i = 0; i < kInputs; ++i) dot += int64_t(weights_[size_t(set)][size_t(i)]) * stretched_[size_t(i)];
    const int64_t d = dot >> 16;
    const int clamped = int(d < -2047 ? -2047 : d > 2047 ? 2047 : d);
    mixed_ = Logistic::squash(clamped);
    return clamped;
  }

  std::vector<Weights> weights_;
  std::vector<uint32_t> uses_;
  Stretched stretched_{};
  int mixed_ = 2048, set_ = 0;
};

// Codes `bit` (encoder; the decoder returns the decoded bit) with the mean,
// in the logistic domain, of several mixers of the same inputs, each mixing
// with the weight vector `sets[i]` chosen by a context of its own: each
// learns how far to trust the inputs in its context. Then the inputs and
// every mixer update, each mixer from its own logit's error.
// Inlined always: out of line, the range coder's state went through memory
// at every bit.
template <class Coder, int kInputs, size_t kMixers>
[[gnu::always_inline]] inline bool codeWithMixers(Coder& coder, const std::array<Mixer<kInputs>*, kMixers>& mixers,
                                                  const std::array<int, kMixers>& sets,
                                                  const std::array<BitModel*, kInputs>& inputs, bool bit) {
  // The first mixer stretches the inputs for all.
  int sum = mixers[0]->logit(sets[0], inputs);
  for (size_t m = 1; m < kMixers; ++m) sum += mixers[m]->logit(sets[m], mixers[0]->stretched());
  // Integer division truncates towards zero on every platform.
  const int mean = sum / int(kMixers);
  bit = coder.bitWithProbability(Mixer<kInputs>::probabilityOfZero(Logistic::squash(mean)), bit);
  for (BitModel* model : inputs) model->update(bit);
  for (Mixer<kInputs>* mixer : mixers) mixer->update(bit);
  return bit;
}

}  // namespace kdmesh
