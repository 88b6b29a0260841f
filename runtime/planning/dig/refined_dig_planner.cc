#include "runtime/planning/dig/refined_dig_planner.h"

#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "runtime/planning/dig/budgeted_search.h"
#include "runtime/planning/dig/swept_volume.h"

namespace autoshovel::planning {
namespace {

void ValidateRegion(const DigRegion& region) {
  const bool finite = std::isfinite(region.swing_min) && std::isfinite(region.swing_max) &&
                      std::isfinite(region.radius_min) && std::isfinite(region.radius_max) &&
                      std::isfinite(region.z_min) && std::isfinite(region.z_max);
  if (!finite || !(region.swing_max > region.swing_min) || !(region.radius_min >= 0) ||
      !(region.radius_max > region.radius_min) || !(region.z_max > region.z_min)) {
    throw std::invalid_argument(
        "RefinedDigPlanner::Plan: region must be finite with swing_min < swing_max, 0 <= "
        "radius_min < radius_max and z_min < z_max, got swing [" +
        std::to_string(region.swing_min) + ", " + std::to_string(region.swing_max) +
        "] rad, radius [" + std::to_string(region.radius_min) + ", " +
        std::to_string(region.radius_max) + "] m, z [" + std::to_string(region.z_min) + ", " +
        std::to_string(region.z_max) + "] m");
  }
}

DigCandidateStatus FromGrid(DigGridRejection rejection) {
  switch (rejection) {
    case DigGridRejection::kUnknownSurface:
      return DigCandidateStatus::kUnknownSurface;
    case DigGridRejection::kNoMaterial:
      return DigCandidateStatus::kNoMaterial;
    case DigGridRejection::kRepeatedCut:
      return DigCandidateStatus::kRepeatedCut;
    case DigGridRejection::kNone:
      break;
  }
  return DigCandidateStatus::kNotEvaluated;
}

const RefinedDigConfig& Validated(const RefinedDigConfig& config) {
  Validate(config);
  return config;
}

DigCostTerms NanCost() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return {nan, nan, nan, nan, nan};
}

}  // namespace

std::string_view ToString(DigCandidateStatus status) {
  switch (status) {
    case DigCandidateStatus::kScored:
      return "scored";
    case DigCandidateStatus::kUnknownSurface:
      return "unknown surface";
    case DigCandidateStatus::kNoMaterial:
      return "no material";
    case DigCandidateStatus::kRepeatedCut:
      return "repeated cut";
    case DigCandidateStatus::kUnreachable:
      return "unreachable";
    case DigCandidateStatus::kCollision:
      return "collision";
    case DigCandidateStatus::kNotEvaluated:
      return "not evaluated";
    case DigCandidateStatus::kNotExecuted:
      return "not executed";
    case DigCandidateStatus::kTooLittle:
      return "too little";
    case DigCandidateStatus::kPathCollision:
      return "path collision";
  }
  return "unknown status";
}

RefinedDigConfig DefaultRefinedDigConfig(const model::MachineDescription& machine) {
  if (!(machine.bucket.rated_capacity > 0)) {
    throw std::invalid_argument("DefaultRefinedDigConfig: " + machine.name +
                                " has no bucket.rated_capacity");
  }
  RefinedDigConfig config;
  if (!(machine.bucket.width > 0)) {
    throw std::invalid_argument("DefaultRefinedDigConfig: " + machine.name +
                                " has no bucket.width");
  }
  config.cost.bucket_capacity = machine.bucket.rated_capacity;
  config.bucket_width = machine.bucket.width;
  config.geometry.undercarriage_radius = UndercarriageRadius(machine);
  return config;
}

void Validate(const RefinedDigConfig& config) {
  const std::string what = "RefinedDigConfig";
  Validate(config.grid, what + ".grid");
  Validate(config.geometry, what + ".geometry");
  Validate(config.cost, what + ".cost");
  if (!(std::isfinite(config.bucket_width) && config.bucket_width > 0)) {
    throw std::invalid_argument(what + ".bucket_width: must be finite and > 0 m, got " +
                                std::to_string(config.bucket_width));
  }
  if (!(std::isfinite(config.min_volume) && config.min_volume >= 0)) {
    throw std::invalid_argument(what + ".min_volume: must be finite and >= 0 m^3, got " +
                                std::to_string(config.min_volume));
  }
  if (config.max_evaluations < 1) {
    throw std::invalid_argument(what + ".max_evaluations: must be >= 1, got " +
                                std::to_string(config.max_evaluations));
  }
  if (config.coarse_evaluations < 1 || config.coarse_evaluations > config.max_evaluations) {
    throw std::invalid_argument(what + ".coarse_evaluations: must be in [1, max_evaluations = " +
                                std::to_string(config.max_evaluations) + "], got " +
                                std::to_string(config.coarse_evaluations));
  }
}

RefinedDigPlanner::RefinedDigPlanner(const control::ExcavatorKinematics& kinematics,
                                     const RefinedDigConfig& config)
    : config_(Validated(config)), reachability_(kinematics, config.geometry) {}

std::vector<DigCandidate> RefinedDigPlanner::GeometricCandidates(
    const DigRegion& region, const control::HeightGrid& map_base,
    const std::vector<control::ObstacleBox>& keep_out_base) const {
  ValidateRegion(region);
  for (std::size_t b = 0; b < keep_out_base.size(); ++b) {
    Validate(keep_out_base[b],
             ("RefinedDigPlanner: keep_out_base[" + std::to_string(b) + "]").c_str());
  }
  std::vector<DigCandidate> out;
  for (DigGridPoint& point : EnumerateDigGrid(config_.grid, region, map_base)) {
    DigCandidate c;
    c.grid_index = point.index;
    c.action = point.action;
    c.cost = NanCost();
    c.status = FromGrid(point.rejection);
    c.why = std::move(point.why);
    if (point.rejection == DigGridRejection::kNone) {
      std::string why;
      if (!reachability_.Reachable(c.action, why)) {
        c.status = DigCandidateStatus::kUnreachable;
        c.why = std::move(why);
      } else if (PathCollides(NominalTipPath(c.action, config_.geometry.lift_clearance),
                              keep_out_base, config_.geometry, why)) {
        c.status = DigCandidateStatus::kCollision;
        c.why = "nominal path: " + why;
      } else {
        c.swept_volume = SweptVolumeEstimate(map_base, c.action, config_.bucket_width,
                                             config_.geometry.path_spacing);
      }
    }
    out.push_back(std::move(c));
  }
  return out;
}

DigPlan RefinedDigPlanner::Plan(const DigRegion& region, const control::HeightGrid& map_base,
                                DigForwardModel& model,
                                const std::vector<control::ObstacleBox>& keep_out_base) const {
  DigPlan plan;
  plan.cost = NanCost();
  plan.candidates = GeometricCandidates(region, map_base, keep_out_base);

  std::vector<int> survivors;
  std::vector<DigGridIndex> points;
  for (int i = 0; i < static_cast<int>(plan.candidates.size()); ++i) {
    if (plan.candidates[i].status == DigCandidateStatus::kNotEvaluated) {
      survivors.push_back(i);
      points.push_back(plan.candidates[i].grid_index);
    }
  }
  plan.geometric_survivors = static_cast<int>(survivors.size());

  // Screening calibrated on the way: the forward model's volume against the swept estimate,
  // k = Σ V V̂ / Σ V̂² over the usable predictions so far (1 before any), so that a fill factor
  // the map cannot know (spill, a bucket that does not fill) moves the screening toward digs
  // the model says fill the bucket.
  double volume_products = 0, estimate_squares = 0;
  const std::function<double(int)> prior = [&](int k) {
    const double scale = estimate_squares > 0 ? volume_products / estimate_squares : 1.0;
    return VolumeCost(scale * plan.candidates[survivors[k]].swept_volume, config_.cost);
  };
  const std::function<double(int)> evaluate = [&](int k) {
    DigCandidate& c = plan.candidates[survivors[k]];
    c.evaluated = true;
    ++plan.evaluations;
    c.prediction = model.Predict(c.action);
    std::string why;
    if (!IsUsable(c.prediction, why)) {
      c.status = DigCandidateStatus::kNotExecuted;
      c.why = std::move(why);
      return std::numeric_limits<double>::quiet_NaN();
    }
    volume_products += c.prediction.volume * c.swept_volume;
    estimate_squares += c.swept_volume * c.swept_volume;
    if (PathCollides(c.prediction.tip_path, keep_out_base, config_.geometry, why)) {
      c.status = DigCandidateStatus::kPathCollision;
      c.why = "predicted path: " + why;
      return std::numeric_limits<double>::quiet_NaN();
    }
    if (c.prediction.volume < config_.min_volume) {
      c.status = DigCandidateStatus::kTooLittle;
      c.why = "predicted volume " + std::to_string(c.prediction.volume) + " m^3 below min_volume " +
              std::to_string(config_.min_volume) + " m^3";
      return std::numeric_limits<double>::quiet_NaN();
    }
    c.cost = DigCost(c.prediction, config_.cost);
    c.status = DigCandidateStatus::kScored;
    return c.cost.total;
  };
  BudgetedSearch(points, DigGridExtent(config_.grid, region), config_.max_evaluations,
                 config_.coarse_evaluations, prior, evaluate);

  for (int i = 0; i < static_cast<int>(plan.candidates.size()); ++i) {
    const DigCandidate& c = plan.candidates[i];
    if (c.status != DigCandidateStatus::kScored) continue;
    if (plan.chosen < 0 || c.cost.total < plan.candidates[plan.chosen].cost.total) plan.chosen = i;
  }
  if (plan.chosen >= 0) {
    const DigCandidate& best = plan.candidates[plan.chosen];
    plan.status = DigPlanStatus::kPlanned;
    plan.action = best.action;
    plan.prediction = best.prediction;
    plan.cost = best.cost;
    return plan;
  }
  std::map<DigCandidateStatus, int> counts;
  for (const DigCandidate& c : plan.candidates) ++counts[c.status];
  plan.why = "no feasible dig in region (column " + std::to_string(region.column) + ", band " +
             std::to_string(region.band) + ") among " + std::to_string(plan.candidates.size()) +
             " candidates:";
  bool first = true;
  for (const auto& [status, count] : counts) {
    plan.why += (first ? " " : ", ") + std::to_string(count) + " " + std::string(ToString(status));
    first = false;
  }
  return plan;
}

}  // namespace autoshovel::planning
