#include "identification/predictor/evaluation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace autoshovel::predictor {
namespace {

// The run's scoop plan with the model's travel curve, if it has one.
prediction::ScoopPlan PlanWithCurve(const CrowdingRun& run,
                                    const prediction::PenetrationPredictor& predictor,
                                    const prediction::PenetrationPrediction& p) {
  prediction::ScoopPlan plan = run.plan;
  plan.travel_times = predictor.scaling().travel_times;
  plan.travel_at = p.travel;
  return plan;
}

// V2 (V21 + V22) of the run from its trigger along `plan` with penetration d [m³].
double FutureVolume(const model::MachineDescription& machine, const CrowdingRun& run,
                    double penetration, const prediction::ScoopPlan& plan) {
  return prediction::PredictFutureVolume(machine, run.map, run.past_path, run.at_trigger,
                                         penetration, plan)
      .total();
}

}  // namespace

std::map<std::string, double> FitIntakeFactors(const prediction::PenetrationPredictor& predictor,
                                               const model::MachineDescription& machine,
                                               const std::vector<const CrowdingRun*>& runs,
                                               double capacity) {
  // κ_M = Σ V·V̂ / Σ V̂² per material: the least-squares gain through the origin.
  std::map<std::string, std::pair<double, double>> sums;
  for (const CrowdingRun* run : runs) {
    if (!run->ok || run->payload < 0.2 || run->payload >= 0.95 * capacity) continue;
    const prediction::PenetrationPrediction p = predictor.Predict(run->features);
    if (!p.ok) continue;
    const double swept =
        run->features.shoveled_volume +
        FutureVolume(machine, *run, p.penetration, PlanWithCurve(*run, predictor, p));
    if (!std::isfinite(swept) || swept <= 0) continue;
    auto& [payload_times_swept, swept_squared] = sums[run->features.material];
    payload_times_swept += run->payload * swept;
    swept_squared += swept * swept;
  }
  std::map<std::string, double> factors;
  for (const auto& [material, s] : sums) {
    if (s.second > 0) factors[material] = s.first / s.second;
  }
  return factors;
}

PredictorEvaluation EvaluatePredictor(const prediction::PenetrationPredictor& predictor,
                                      const model::MachineDescription& machine,
                                      const std::vector<const CrowdingRun*>& runs,
                                      double capacity) {
  PredictorEvaluation e;
  double volume_error = 0, capped_error = 0, oracle_error = 0;
  for (const CrowdingRun* run : runs) {
    if (!run->ok) continue;
    ++e.samples;
    e.mean_penetration += run->penetration;
    const prediction::PenetrationPrediction p = predictor.Predict(run->features);
    if (!p.ok) {
      ++e.refused;
      continue;
    }
    const double error = std::abs(p.penetration - run->penetration);
    e.within_010 += error <= 0.10;
    e.within_015 += error <= 0.15;
    e.within_020 += error <= 0.20;
    e.mse += error * error;
    const std::vector<double>& times = predictor.scaling().travel_times;
    e.travel_knots = static_cast<int>(times.size());
    for (std::size_t k = 0; k < times.size() && k < p.travel.size(); ++k) {
      const double travel_error = std::abs(p.travel[k] - TravelAt(*run, times[k]));
      e.travel_within_010 += travel_error <= 0.10;
      e.travel_mse += travel_error * travel_error;
    }
    if (run->payload < 0.2) continue;
    const double v1 = run->features.shoveled_volume;
    const prediction::ScoopPlan plan = PlanWithCurve(*run, predictor, p);
    const double v2 = FutureVolume(machine, *run, p.penetration, plan);
    // The oracle: the true penetration and, with a curve, the run's own travel at its knots.
    prediction::ScoopPlan true_plan = plan;
    for (std::size_t k = 0; k < plan.travel_times.size(); ++k) {
      true_plan.travel_at[k] = TravelAt(*run, plan.travel_times[k]);
    }
    const double v2_oracle = FutureVolume(machine, *run, run->penetration, true_plan);
    // What the trigger compares with V_t: V1 + V2 times the model's intake factor.
    const double intake = predictor.IntakeFactor(run->features.material);
    const double predicted = intake * (v1 + v2);
    ++e.capped_samples;
    capped_error += std::abs(std::min(predicted, capacity) - run->payload) / run->payload;
    if (run->payload >= 0.95 * capacity) {
      ++e.full_runs;
      continue;
    }
    ++e.volume_samples;
    e.mean_payload += run->payload;
    e.mean_predicted_volume += predicted;
    volume_error += std::abs(predicted - run->payload) / run->payload;
    oracle_error += std::abs(intake * (v1 + v2_oracle) - run->payload) / run->payload;
  }
  if (e.samples > 0) {
    e.within_010 /= e.samples, e.within_015 /= e.samples, e.within_020 /= e.samples;
    e.mse /= std::max(e.samples - e.refused, 1);
    e.mean_penetration /= e.samples;
    const int pairs = std::max(e.samples - e.refused, 1) * std::max(e.travel_knots, 1);
    e.travel_within_010 /= pairs, e.travel_mse /= pairs;
  }
  if (e.volume_samples > 0) {
    e.volume_accuracy = 1 - volume_error / e.volume_samples;
    e.oracle_volume_accuracy = 1 - oracle_error / e.volume_samples;
    e.mean_payload /= e.volume_samples;
    e.mean_predicted_volume /= e.volume_samples;
  }
  if (e.capped_samples > 0) e.volume_accuracy_capped = 1 - capped_error / e.capped_samples;
  return e;
}

std::string FormatEvaluation(const PredictorEvaluation& e) {
  char text[1024];
  std::snprintf(
      text, sizeof text,
      "samples %d (refused %d), mean penetration %.3f m\n"
      "  |error| <= 0.10 m: %.1f %%   <= 0.15 m: %.1f %%   <= 0.20 m: %.1f %%   "
      "MSE %.4f m^2\n"
      "  volume accuracy 1 - mean|V^-V|/V: %.1f %% over %d runs not full (V2 along the true "
      "penetration: %.1f %%; mean payload %.2f m^3, mean prediction %.2f m^3); all %d "
      "runs, V^ capped at the capacity: %.1f %% (%d full)",
      e.samples, e.refused, e.mean_penetration, 100 * e.within_010, 100 * e.within_015,
      100 * e.within_020, e.mse, 100 * e.volume_accuracy, e.volume_samples,
      100 * e.oracle_volume_accuracy, e.mean_payload, e.mean_predicted_volume, e.capped_samples,
      100 * e.volume_accuracy_capped, e.full_runs);
  std::string out = text;
  if (e.travel_knots > 0) {
    std::snprintf(text, sizeof text,
                  "\n  travel curve (%d knots): %.1f %% of the knots within 0.10 m, MSE %.4f m^2",
                  e.travel_knots, 100 * e.travel_within_010, e.travel_mse);
    out += text;
  }
  return out;
}

}  // namespace autoshovel::predictor
