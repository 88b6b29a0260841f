// `autoshovel train predictor --machine M -o STEM` (no database): trains the penetration predictor
// on machine M's simulated plant (plant_training.h), by default for the main job's scoop profile
// (attack at 1.5 m/s, speed reference falling at 0.6 m/s², 40 % dug faces, travel curve and
// intake factor: the recipe of models/prediction/penetration_svr_fast). M is a name under the
// models folder or a description's path.
//
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
// never over the shipped model). Only samples of runs of --machine are used (a database may
// hold several machines' runs).
//
// Either way `<out>.meta.yaml` records the machine (name, description SHA-256) and where the
// samples came from (runtime/prediction/model_provenance.h).
#pragma once

#include <iosfwd>
#include <string>

#include "identification/predictor/plant_training.h"

namespace autoshovel::predictor {

struct RetrainOptions {
  std::string database;  ///< results.sqlite of a campaign or a run; empty: train on the plant
  std::string machine = "xcmg_968ev";
  std::string models_dir;
  std::string base;  ///< the model to compare with; empty: <models>/prediction/penetration_svr
  std::string out;   ///< path stem of the new model (.model, .scale); required
  std::string strategy = "just_in_out";  ///< samples of this scoop only; "all": every sample
  int threads = 0;                       ///< 0: every core
  /// Without a database: the plant training's settings (machine, models_dir, out, threads and
  /// command are taken from the fields above; compare_with from `base` when given).
  PlantTrainingOptions plant = MainJobPlantTraining();

  /// The recipe of the main job's model (identification/predictor/README.md, "The main job's
  /// model"): 2000 runs, seed 1, attack 1.5 m/s, 0.6 m/s², 40 % dug faces, travel curve, κ.
  static PlantTrainingOptions MainJobPlantTraining();
};

/// 0 on success, 2 on bad input (named on `err`), 1 when too few samples to train.
int RunRetrainPredictor(const RetrainOptions& options, std::ostream& out, std::ostream& err);

}  // namespace autoshovel::predictor
