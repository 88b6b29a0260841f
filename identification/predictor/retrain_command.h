// `autoshovel train predictor DB`: retrains the penetration predictor at a new site from the
// crowding samples a campaign (or `autoshovel run`) logged (wheel-loader seed §7.6: "if material
// properties differ substantially, the volume prediction model may need retraining with newly
// collected scooping data").
//
// A crowding sample is the predictor's input at the scoop trigger (v, V1, material, h1..h6) and
// the machine's forward travel from the trigger to the end of the scoop phase. Only "Just in &
// out" cycles are used by default: the regime the shipped model was trained in (the machine runs
// on into the pile while the bucket racks back); a Stairway's travel is another quantity.
//
// Every fifth sample (by a hash of run and cycle, so the split is stable as a database grows) is
// held out. The shipped model and the retrained one are scored on the held-out samples with the
// buckets of seed §7.4.1; the new model is written to `--out` (never over an existing file, and
// never over the shipped model).
#pragma once

#include <iosfwd>
#include <string>

namespace autoshovel::predictor {

struct RetrainOptions {
  std::string database;  ///< results.sqlite of a campaign or a run
  std::string machine = "xcmg_968ev";
  std::string models_dir;
  std::string base;  ///< the model to compare with; empty: <models>/prediction/penetration_svr
  std::string out;   ///< path stem of the new model (.model, .scale); required
  std::string strategy = "just_in_out";  ///< samples of this scoop only; "all": every sample
  int threads = 0;                       ///< 0: every core
};

/// 0 on success, 2 on bad input (named on `err`), 1 when too few samples to train.
int RunRetrainPredictor(const RetrainOptions& options, std::ostream& out, std::ostream& err);

}  // namespace autoshovel::predictor
