// Training the penetration predictor on a machine's simulated plant: crowding runs of that
// machine (crowding_runs.h), the ε-SVR fit on 80 % of them and the §7.4.1 scores on the other
// 20 % (wheel-loader seed §6.1, §7.4.1). What the `train_predictor` tool and `autoshovel train
// predictor --machine M` (without a database) run; README.md gives the commands that made the
// shipped models.
//
// Beside the model it writes `<out>.meta.yaml` (runtime/prediction/model_provenance.h): the
// machine's name and description SHA-256 and the plant the runs were made on, so that a command
// driving another machine with the model warns.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "identification/predictor/crowding_runs.h"
#include "identification/predictor/svr_training.h"

namespace autoshovel::predictor {

struct PlantTrainingOptions {
  std::string machine = "xcmg_968ev";  ///< a name under models_dir, or a description's path
  std::string models_dir;
  std::string out;          ///< path stem: <out>.model, .scale, .meta.yaml (required)
  std::string samples_csv;  ///< also write every sample here (empty: no)
  int runs = 1000;
  std::uint64_t seed = 1;
  int threads = 1;
  /// v0 range and the other per-run settings; scoop_deceleration and dug_face_fraction below.
  CrowdingRunOptions run_options;
  double scoop_deceleration = 0;  ///< CrowdingRunOptions::scoop_deceleration [m/s²]
  double dug_face_fraction = 0;   ///< CrowdingRunOptions::dug_face_fraction [-]
  bool travel_curve = false;      ///< also the travel-curve models (penetration_predictor.h)
  std::vector<double> travel_times = {0.5, 1.0, 1.5, 2.0, 2.5, 3.0};  ///< [s]
  bool intake_factor = false;    ///< also κ per material in the .scale file
  std::string compare_with;      ///< also score this model (path stem) on the test runs
  double envelope_speed = 1.25;  ///< test runs split at this approach speed [m/s]
  SvrGrid grid;
  /// Names the command in the .scale note and the provenance ("train_predictor" or
  /// "autoshovel train predictor").
  std::string command = "train_predictor";
};

/// Runs the training and prints progress and scores on `out`. 0 on success, 2 on bad input
/// (named on `err`, prefixed with the command), 1 when training failed.
int RunPlantTraining(const PlantTrainingOptions& options, std::ostream& out, std::ostream& err);

}  // namespace autoshovel::predictor
