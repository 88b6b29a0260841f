// V2 at one trigger decision (wheel-loader seed §6.1, Fig. 9): the penetration predictor's
// travel from the machine's state and the pre-contact map, then V21 + V22 along the tip path that
// travel gives (volume_estimation.h). One function for the scoop cycle's trigger
// (control::ScoopCycle) and for `autoshovel replay`, which evaluates it on recorded states.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "generated/machine_functions.h"
#include "runtime/model/description.h"
#include "runtime/prediction/penetration_predictor.h"
#include "runtime/prediction/volume_estimation.h"

namespace autoshovel::prediction {

/// The machine at a decision, as the scoop cycle's state estimate gives it.
struct DecisionState {
  Eigen::Vector2d hinge_xy = Eigen::Vector2d::Zero();  ///< world [m]
  double heading = 0;                                  ///< [rad]
  double speed = 0;                                    ///< [m/s]
  double q_boom = 0, q_bucket = 0;                     ///< filtered joint angles [rad]
};

struct V2Prediction {
  bool ok = false;  ///< false: the predictor or the plan failed; `v2` is then 0
  double v2 = 0;    ///< V21 + V22 [m³]
  PenetrationFeatures features;
  double penetration = NAN;           ///< the predictor's travel d [m]
  std::vector<Eigen::Vector3d> path;  ///< the predicted tip path, world [m]
};

/// V2 for machine `machine` at `state`, with V1 = `v1` so far along `tip_path` (world, non-empty)
/// over `map` (heights before the bucket came), digging `material`. The scoop the prediction
/// assumes curls the bucket by what is left to `bucket_max` [rad], then lifts the boom by
/// `boom_lift` [rad], both valves fully open.
V2Prediction PredictV2(const model::MachineDescription& machine,
                       const generated::MachineFunctions& functions, const HeightGrid& map,
                       const model::Material& material, const PenetrationPredictor& predictor,
                       const std::vector<Eigen::Vector3d>& tip_path, const DecisionState& state,
                       double v1, double bucket_max, double boom_lift);

}  // namespace autoshovel::prediction
