// "Just in & out", "Stairway" (adaptive) and "Stairway #N", seed §6.2 and §7.4.2.
#include "runtime/control/scooping_strategies.h"

#include <cmath>
#include <stdexcept>

namespace autoshovel::control {

namespace {
constexpr double kRackedTolerance = 0.02;  // [rad] a bucket this close to racked counts as racked
}

const char* ToString(ScoopStrategy strategy) {
  switch (strategy) {
    case ScoopStrategy::kJustInOut:
      return "just_in_out";
    case ScoopStrategy::kStairway:
      return "stairway";
    case ScoopStrategy::kStairwayFixed:
      return "stairway_fixed";
    case ScoopStrategy::kOptimal:
      return "optimal";
  }
  return "?";
}

std::string StrategyParameters::Invalid() const {
  const double values[] = {exit_boom_lift, step_boom_lift, step_retract, step_pause};
  for (double v : values) {
    if (!std::isfinite(v) || v < 0) return "strategy: angles and pause must be finite and >= 0";
  }
  if (max_steps < 1) return "strategy: max_steps must be >= 1";
  if (fixed_steps < 1) return "strategy: fixed_steps must be >= 1";
  return {};
}

std::string FinishingParameters::Invalid() const {
  const double values[] = {level_hold, shake_duty, shake_pulse};
  for (double v : values) {
    if (!std::isfinite(v) || v < 0) return "finishing: values must be finite and >= 0";
  }
  if (!std::isfinite(carry_tilt_back) || std::abs(carry_tilt_back) > 0.5) {
    return "finishing: carry_tilt_back must be finite and within ±0.5 rad";
  }
  if (shake_duty > 1) return "finishing: shake_duty must be <= 1";
  if (shake_pulses < 0) return "finishing: shake_pulses must be >= 0";
  return {};
}

ScoopSequencer::ScoopSequencer(ScoopStrategy strategy, const StrategyParameters& parameters,
                               const ArmLimits& limits)
    : strategy_(strategy),
      parameters_(parameters),
      limits_(limits),
      stage_(strategy == ScoopStrategy::kJustInOut ? Stage::kRackBack : Stage::kSteps) {
  if (const std::string why = parameters.Invalid(); !why.empty()) {
    throw std::invalid_argument(why);
  }
}

std::optional<AtomicAction> ScoopSequencer::Issue(const AtomicAction& action) {
  ++actions_;
  return action;
}

std::optional<AtomicAction> ScoopSequencer::Next(const ArmTargets& targets, double feedback_volume,
                                                 double target_volume) {
  const bool racked = targets.bucket >= limits_.bucket_max - kRackedTolerance;
  if (stage_ == Stage::kSteps) {
    if (!lift_next_) {  // second half of a step
      lift_next_ = true;
      return Issue(RetractBucket(parameters_.step_retract, parameters_.step_pause));
    }
    bool more = !racked;
    if (strategy_ == ScoopStrategy::kStairwayFixed) {
      more = more && steps_ < parameters_.fixed_steps;
    } else {
      // Feedback between actions (§6.2): one step at least, then only while short of V_t.
      const bool short_of_target = !(feedback_volume >= target_volume);  // NaN: keep going
      more = more && steps_ < parameters_.max_steps && (steps_ == 0 || short_of_target);
    }
    if (more) {
      ++steps_;
      lift_next_ = false;
      return Issue(LiftBoom(parameters_.step_boom_lift));
    }
    stage_ = Stage::kRackBack;
  }
  if (stage_ == Stage::kRackBack) {
    stage_ = Stage::kExitLift;
    if (!racked) return Issue(RetractBucket(limits_.bucket_max - targets.bucket));
  }
  if (stage_ == Stage::kExitLift) {
    stage_ = Stage::kDone;
    return Issue(LiftBoom(parameters_.exit_boom_lift));
  }
  return std::nullopt;
}

}  // namespace autoshovel::control
