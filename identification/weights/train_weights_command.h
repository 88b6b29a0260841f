// `autoshovel train weights`: tunes the Eq. (18) weights k_t, k_s, k_c, k_e, k_a by CMA-ES on
// expert demonstrations (wheel-loader seed §5, Table 1) and reports the agreement with the
// expert on held-out demonstrations before (Table 1's weights) and after.
//
// With `--generate N` it first writes N simulated demonstrations (demonstration_generation.h)
// to the `--demos` file; otherwise it reads that file (a recorded dataset in the same format,
// docs/weight_tuning.md). Every fifth demonstration (id mod 5 = 4) is held out: 80/20.
// The weights are written as YAML to `--out`, never over an existing file.
#pragma once

#include <iosfwd>
#include <string>

namespace autoshovel::identification {

struct TrainWeightsOptions {
  std::string machine = "xcmg_968ev";
  std::string models_dir;
  std::string demos = "demonstrations.sqlite";
  int generate = 0;             ///< > 0: generate this many into `demos` first
  unsigned long long seed = 1;  ///< of the generated scenes and of CMA-ES
  std::string out = "shovel_weights.yaml";
  int evaluations = 3000;  ///< CMA-ES budget
  int threads = 0;         ///< for generation and scoring; 0: every core
};

/// 0 on success, 1 when tuning failed, 2 on bad input (named on `err`).
int RunTrainWeights(const TrainWeightsOptions& options, std::ostream& out, std::ostream& err);

}  // namespace autoshovel::identification
