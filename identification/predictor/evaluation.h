// Scoring the penetration predictor the way the wheel-loader seed reports it (§7.4.1): the share
// of test samples whose absolute penetration error is within 0.1, 0.15 and 0.2 m, the mean
// squared error, and the final volume prediction accuracy, 1 − mean(|V̂ − V| / V) over the runs,
// with V̂ = κ_M·(V1 + V2) predicted at the trigger (V2 along the SVR's penetration,
// volume_estimation.h; κ_M the model's intake factor, 1 when it has none)
// and V the payload the plant's bucket holds at the end of the scoop.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "identification/predictor/crowding_runs.h"
#include "runtime/prediction/penetration_predictor.h"

namespace autoshovel::predictor {

struct PredictorEvaluation {
  int samples = 0;
  int refused = 0;              ///< features the predictor refused (counted as misses)
  double within_010 = 0;        ///< fraction with |error| ≤ 0.10 m
  double within_015 = 0;        ///< ≤ 0.15 m
  double within_020 = 0;        ///< ≤ 0.20 m
  double mse = 0;               ///< [m²]
  double mean_penetration = 0;  ///< of the truth [m]
  double volume_accuracy = 0;   ///< 1 − mean |V̂ − V|/V, V̂ = V1 + V2(SVR), runs not full [-]
  double volume_accuracy_capped = 0;  ///< all runs, V̂ capped at the capacity
  double oracle_volume_accuracy = 0;  ///< runs not full, V2 along the true penetration
  int full_runs = 0;                  ///< runs whose payload reached 95 % of the capacity
  double mean_payload = 0;            ///< [m³]
  double mean_predicted_volume = 0;   ///< [m³]
  int volume_samples = 0;        ///< runs not full with a payload ≥ 0.2 m³ (the ratio needs one)
  int capped_samples = 0;        ///< all runs with a payload ≥ 0.2 m³
  int travel_knots = 0;          ///< knots of the model's travel curve (0: none)
  double travel_within_010 = 0;  ///< fraction of (run, knot) pairs within 0.10 m
  double travel_mse = 0;         ///< over the (run, knot) pairs [m²]
};

/// `capacity`: what the bucket holds when full, racked back [m³] (the plant's bucket holds less
/// than the rated heaped capacity once racked back: train_predictor passes the largest payload
/// of the training runs). Runs whose payload reaches 95 % of it are "full": Eq. (19) counts the
/// whole column above the tip path, the bucket pushes the excess ahead, so their volume is scored
/// with V̂ capped at `capacity` and separately from the rest.
PredictorEvaluation EvaluatePredictor(const prediction::PenetrationPredictor& predictor,
                                      const model::MachineDescription& machine,
                                      const std::vector<const CrowdingRun*>& runs, double capacity);

/// κ_M per material of `runs` (penetration_predictor.h, the intake factor): the least-squares
/// gain through the origin of the payload on V1 + V2 (V2 along the predictor's penetration and
/// travel curve) over the runs whose payload is at least 0.2 m³ and below 95 % of `capacity`
/// (a full bucket's payload is capped and says nothing about the intake).
std::map<std::string, double> FitIntakeFactors(const prediction::PenetrationPredictor& predictor,
                                               const model::MachineDescription& machine,
                                               const std::vector<const CrowdingRun*>& runs,
                                               double capacity);

std::string FormatEvaluation(const PredictorEvaluation& e);

}  // namespace autoshovel::predictor
