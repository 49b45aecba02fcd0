// Learns the model priors of native/src/model_priors.h: encodes each
// training mesh at 12 bits and averages, model by model, the final
// probability of the slow estimator, weighted by how often the model was
// used in that mesh (capped, so that no mesh dominates), then writes
// model_priors.inc. Each mesh is also encoded for fast decoding; the
// families only that coding uses learn from it. Models the meshes used fewer than kMinWeight times in
// all start at 1/2. The mixers' starting weights are averaged the same way,
// weight vector by weight vector; one that no mesh used keeps its compiled
// value.
//
// Learning starts from the priors compiled in, so a retrained family moves
// the others' final states too; `--only` retrains the named families (array
// names, comma-separated) and writes the others as they are compiled in.
//
//   kdmesh_train_priors [--only NAMES] OUTPUT.inc MESH...   (see scripts/train-priors.sh)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "encoder_internal.h"
#include "kdmesh/io.h"

namespace {

constexpr double kMaxWeight = 256;
// A model used fewer times than this in all the training meshes together
// keeps 1/2: its average is mostly noise, and a run of models at 1/2 takes
// three bytes in the module however long (the refinement families of
// format 16: 11,668 bytes of priors without the rule, 7,653 with it, at
// +0.001 to +0.008 bits per vertex).
constexpr double kMinWeight = 16;
// A weight vector is used thousands of times in a mesh, far more than a
// model; capped too, so that no mesh dominates.
constexpr double kMaxMixerUses = 2048;
constexpr int kFamilies = kdmesh::kModelFamilies + kdmesh::kMixerFamilies;
// The families' array names in model_priors.inc, model families first.
const std::string kNames[kFamilies] = {
#define KDMESH_NAME_OF(name, priors, ...) #priors,
    KDMESH_MODEL_FAMILIES(KDMESH_NAME_OF) KDMESH_MIXER_FAMILIES(KDMESH_NAME_OF)};
}  // namespace

int main(int argc, char** argv) {
  std::vector<bool> retrain(kFamilies, true);
  std::string only;
  if (argc > 2 && std::string(argv[1]) == "--only") {
    only = argv[2];
    for (int f = 0; f < kFamilies; ++f)
      retrain[size_t(f)] = ("," + only + ",").find("," + kNames[f] + ",") != std::string::npos;
    if (std::count(retrain.begin(), retrain.end(), true) == 0) {
      std::fprintf(stderr, "--only %s: no such family (names as in model_priors.inc)\n", argv[2]);
      return 2;
    }
    argc -= 2;
    argv += 2;
  }
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s [--only NAMES] OUTPUT.inc MESH...\n", argv[0]);
    return 2;
  }
  // Per coding (default, fast decoding), family and model.
  std::vector<std::vector<double>> sum[2], weight[2];
  for (int coding = 0; coding < 2; ++coding)
    for (int f = 0; f < kdmesh::kModelFamilies; ++f) {
      sum[coding].emplace_back(kdmesh::kFamilySize[size_t(f)], 0.0);
      weight[coding].emplace_back(kdmesh::kFamilySize[size_t(f)], 0.0);
    }
  // Per mixer family: weighted sums of each weight, and the weight of each vector.
  std::vector<std::vector<double>> mixerSum(kdmesh::kMixerFamilies), mixerWeight(kdmesh::kMixerFamilies);
  for (int f = 0; f < kdmesh::kMixerFamilies; ++f) {
    mixerSum[size_t(f)].assign(kdmesh::kMixerSets[size_t(f)] * kdmesh::kMixerInputs[size_t(f)], 0);
    mixerWeight[size_t(f)].assign(kdmesh::kMixerSets[size_t(f)], 0);
  }
  for (int i = 2; i < argc; ++i) {
    kdmesh::Complex complex;
    kdmesh::io::Notes notes;
    if (const kdmesh::Status s = kdmesh::io::readFile(argv[i], complex, notes); !s.ok()) {
      std::fprintf(stderr, "%s: %s\n", argv[i], s.message.c_str());
      return 1;
    }
    kdmesh::TrainedModels models;  // of the default coding, whose mixers are learned
    for (int coding = 0; coding < 2; ++coding) {
      kdmesh::EncodeOptions options;
      options.bits = 12;
      options.fastDecode = coding == 1;
      kdmesh::TrainedModels trained;
      const kdmesh::EncodeResult result = kdmesh::encode(complex, options, &trained);
      if (!result.status.ok() || trained.families[0].empty()) {
        std::fprintf(stderr, "%s: %s\n", argv[i], result.status.ok() ? "no connectivity" : result.status.message.c_str());
        return 1;
      }
      std::fprintf(stderr, "%s%s: %zu vertices, %.3f bits/vertex\n", argv[i], coding ? " (fast decoding)" : "",
                   complex.vertexCount(), 8.0 * double(result.bytes.size()) / double(complex.vertexCount()));
      for (int f = 0; f < kdmesh::kModelFamilies; ++f)
        for (size_t m = 0; m < trained.families[size_t(f)].size(); ++m) {  // empty: a family the coding lacks
          const kdmesh::BitModel& model = trained.families[size_t(f)][m];
          // Primed models start with some observations already counted.
          const double used =
              std::min<double>(kMaxWeight, std::max(0, int(model.seen) - int(kdmesh::kPriorObservations)));
          sum[coding][size_t(f)][m] += used * model.slow;
          weight[coding][size_t(f)][m] += used;
        }
      if (coding == 1) continue;
      models = std::move(trained);
    }
    for (int f = 0; f < kdmesh::kMixerFamilies; ++f) {
      const size_t inputs = kdmesh::kMixerInputs[size_t(f)];
      for (size_t set = 0; set < kdmesh::kMixerSets[size_t(f)]; ++set) {
        const double used = std::min<double>(kMaxMixerUses, models.mixerUses[size_t(f)][set]);
        for (size_t i = 0; i < inputs; ++i)
          mixerSum[size_t(f)][set * inputs + i] += used * models.mixerWeights[size_t(f)][set * inputs + i];
        mixerWeight[size_t(f)][set] += used;
      }
    }
  }
  std::FILE* out = std::fopen(argv[1], "w");
  if (!out) {
    std::perror(argv[1]);
    return 1;
  }
  std::fprintf(out, "// Generated by scripts/train-priors.sh from %d meshes%s%s%s; do not edit.\n", argc - 2,
               only.empty() ? "" : " (retrained: ", only.c_str(), only.empty() ? "" : "; the others as they were)");
  for (int f = 0; f < kdmesh::kModelFamilies; ++f) {
    std::vector<kdmesh::BitModel> compiled(kdmesh::kFamilySize[size_t(f)]);
    kdmesh::primeModels(kdmesh::ModelFamily(f), compiled.data());
    // The default coding's statistics, unless it never used the family.
    const std::vector<double>& defaultWeight = weight[0][size_t(f)];
    const int coding = std::all_of(defaultWeight.begin(), defaultWeight.end(), [](double w) { return w == 0; });
    std::vector<uint8_t> codes;
    for (size_t m = 0; m < kdmesh::kFamilySize[size_t(f)]; ++m) {
      const double w = weight[coding][size_t(f)][m];
      const int prior = !retrain[size_t(f)] ? int(compiled[m].slow)
                        : w >= kMinWeight ? int(sum[coding][size_t(f)][m] / w + 0.5)
                                        : int(kdmesh::kProbabilityOne / 2);
      codes.push_back(kdmesh::priorCode(uint32_t(prior)));
    }
    const std::vector<uint8_t> coded = kdmesh::runLengthCodePriors(codes);
    std::fprintf(out, "constexpr uint8_t %s[%zu] = {", kNames[f].c_str(), coded.size());
    for (size_t i = 0; i < coded.size(); ++i)
      std::fprintf(out, "%s%s%d", i ? "," : "", i % 16 == 0 ? "\n    " : " ", coded[i]);
    std::fprintf(out, "};\n");
  }
  for (int f = 0; f < kdmesh::kMixerFamilies; ++f) {
    const size_t inputs = kdmesh::kMixerInputs[size_t(f)], values = kdmesh::kMixerSets[size_t(f)] * inputs;
    const int32_t* compiled = kdmesh::mixerPriors(kdmesh::MixerFamily(f));
    const bool learn = retrain[size_t(kdmesh::kModelFamilies + f)];
    std::fprintf(out, "constexpr int32_t %s[%zu] = {", kNames[kdmesh::kModelFamilies + f].c_str(), values);
    for (size_t i = 0; i < values; ++i) {
      const double w = mixerWeight[size_t(f)][i / inputs];
      const long weight = learn && w > 0 ? std::lround(mixerSum[size_t(f)][i] / w) : long(compiled[i]);
      std::fprintf(out, "%s%s%ld", i ? "," : "", i % inputs == 0 ? "\n    " : " ", weight);
    }
    std::fprintf(out, "};\n");
  }
  return std::fclose(out) == 0 ? 0 : 1;
}
