#include "runtime/prediction/scoop_volume_prediction.h"

#include <algorithm>
#include <cmath>
#include <exception>

namespace autoshovel::prediction {

V2Prediction PredictV2(const model::MachineDescription& machine,
                       const generated::MachineFunctions& functions, const HeightGrid& map,
                       const model::Material& material, const PenetrationPredictor& predictor,
                       const std::vector<Eigen::Vector3d>& tip_path, const DecisionState& state,
                       double v1, double bucket_max, double boom_lift) {
  // Features (penetration_predictor.h): v, V1, material, h1..h6 on the map k·Δl ahead of the
  // tip along the heading, mean of five points across the bucket width. The pre-contact map is
  // used: ahead of the bucket the pile is as it was.
  V2Prediction out;
  out.features.speed = state.speed;
  out.features.shoveled_volume = v1;
  out.features.material = material.name;
  // Unknown cells count as floor; map noise below the floor as the floor.
  out.features.heights = SampleHeightsAhead(
      [&](double x, double y) {
        const double h = map.HeightAt(x, y);
        return std::isfinite(h) ? std::max(h, 0.0) : 0.0;
      },
      tip_path.back().head<2>(), state.heading, machine.bucket.width);
  const PenetrationPrediction d = predictor.Predict(out.features);
  if (!d.ok) return out;
  out.penetration = d.penetration;
  try {
    const std::vector<double> q = {state.q_boom, state.q_bucket};
    ScoopPlan plan = ScoopPlanFromMachine(machine, functions, q, 1.0, 1.0,
                                          std::max(bucket_max - state.q_bucket, 0.0), boom_lift);
    // The travel within d as the model predicts it, when it has a travel curve.
    plan.travel_times = predictor.scaling().travel_times;
    plan.travel_at = d.travel;
    MachineAtTrigger at;
    at.hinge_xy = state.hinge_xy;
    at.heading = state.heading;
    at.speed = std::max(state.speed, 0.0);
    at.q = q;
    FutureVolume future = PredictFutureVolume(machine, map, tip_path, at, d.penetration, plan);
    out.v2 = future.total();
    out.path = std::move(future.path);
    out.ok = true;
  } catch (const std::exception&) {
    out.v2 = 0;
  }
  return out;
}

}  // namespace autoshovel::prediction
