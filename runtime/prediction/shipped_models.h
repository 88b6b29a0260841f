// Where the shipped penetration predictors live under the models folder, and which one the main
// job drives with. Kept apart from penetration_predictor.h so the retraining tool (which must
// not link PCL) and the main job name the same file.
#pragma once

#include <string>

namespace autoshovel::prediction {

/// The main job's scoop profile: attack at 1.5 m/s, keep pushing while the arm curls and let the
/// speed reference fall at 0.6 m/s² (app::ShovelRunOptions). Trained for exactly that profile
/// (identification/predictor/README.md, "The main job's model").
inline constexpr const char* kMainJobPredictor = "prediction/penetration_svr_fast";
/// The braking scoop (attack at up to 1.25 m/s, brake at 1 m/s² once the arm moves): the
/// scoop cycle's library defaults (control::ScoopCycleOptions) and the seed's regime as first
/// reproduced.
inline constexpr const char* kBrakingScoopPredictor = "prediction/penetration_svr";

/// `models_dir`/kMainJobPredictor.
inline std::string MainJobPredictor(const std::string& models_dir) {
  return models_dir + "/" + kMainJobPredictor;
}

}  // namespace autoshovel::prediction
