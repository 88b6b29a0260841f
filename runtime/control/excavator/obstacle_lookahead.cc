#include "runtime/control/excavator/obstacle_lookahead.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "runtime/control/excavator/script_rollout.h"

namespace autoshovel::control {

void Validate(const LookAheadSettings& s) {
  if (!(std::isfinite(s.horizon) && s.horizon > 0)) {
    throw std::invalid_argument("LookAheadSettings: horizon must be positive");
  }
  if (!(std::isfinite(s.integration_step) && s.integration_step > 0 &&
        s.integration_step <= LoadingScript::kPeriod)) {
    throw std::invalid_argument(
        "LookAheadSettings: integration_step must be positive and at most the script period");
  }
  if (!std::isfinite(s.height_margin)) {
    throw std::invalid_argument("LookAheadSettings: height_margin must be finite");
  }
  if (!(std::isfinite(s.stop_time_limit) && s.stop_time_limit > 0)) {
    throw std::invalid_argument("LookAheadSettings: stop_time_limit must be positive");
  }
}

ObstacleLookAhead::ObstacleLookAhead(const LinkageEnvelope& envelope,
                                     const LookAheadSettings& settings)
    : envelope_(envelope), settings_(settings) {
  Validate(settings_);
}

bool ObstacleLookAhead::Collides(const JointVector& q, double time, const HeightGrid& map,
                                 const Eigen::Isometry3d& T_world_base,
                                 std::vector<EnvelopePoint>& scratch,
                                 LookAheadResult& result) const {
  ++result.states_checked;
  envelope_.Underside(q, T_world_base, scratch);
  for (const EnvelopePoint& point : scratch) {
    const double h = map.HeightAt(point.p.x(), point.p.y());
    const bool unknown = std::isnan(h);
    if (unknown) ++result.unknown_points;
    if ((unknown && settings_.unknown_blocks) ||
        (!unknown && point.p.z() < h + settings_.height_margin)) {
      result.verdict = LookAheadVerdict::kCollision;
      result.collision = PredictedCollision{time, point.p, point.link, h, q};
      result.reason = "predicted collision of the " + std::string(LinkName(point.link)) + " in " +
                      std::to_string(time) + " s";
      return true;
    }
  }
  return false;
}

std::optional<ExcavatorSimulator> ObstacleLookAhead::Prepare(const ExcavatorState& measured,
                                                             const ExcavatorSimulator& commands,
                                                             LookAheadResult& result) const {
  const int bad_q = FirstNonFinite(measured.q);
  const int bad_qd = FirstNonFinite(measured.qd);
  if (bad_q >= 0 || bad_qd >= 0) {
    const int bad = bad_q >= 0 ? bad_q : bad_qd;
    result.verdict = LookAheadVerdict::kInvalidState;
    result.reason = std::string("non-finite ") + (bad_q >= 0 ? "position" : "rate") + " of the " +
                    std::string(JointName(kAllExcavatorJoints[bad])) +
                    " in the measured state: stop";
    return std::nullopt;
  }
  ExcavatorSimulator predicted = commands;
  predicted.Resync(measured);
  predicted.set_integration_step(settings_.integration_step);
  return predicted;
}

LookAheadResult ObstacleLookAhead::Check(const ExcavatorState& measured,
                                         const ExcavatorSimulator& commands,
                                         const LoadingScript* script, double next_evaluation,
                                         const HeightGrid& map,
                                         const Eigen::Isometry3d& T_world_base) const {
  LookAheadResult result;
  std::optional<ExcavatorSimulator> predicted = Prepare(measured, commands, result);
  if (!predicted) return result;
  if (!(std::isfinite(next_evaluation) && next_evaluation >= 0)) {
    throw std::invalid_argument("ObstacleLookAhead::Check: next_evaluation must be >= 0");
  }
  std::vector<EnvelopePoint> scratch;
  ExcavatorSimulator& machine = *predicted;
  // The prediction must reach past the time a stop issued now would take to bring every joint
  // to rest from the fastest it moves in the prediction (the seed asks for a prediction long
  // enough for a complete stop), plus one evaluation period for the report to be seen.
  double horizon = settings_.horizon;
  auto extend = [&](const ExcavatorState& state) {
    for (int j = 0; j < kNumExcavatorJoints; ++j) {
      horizon = std::max(horizon,
                         StoppingTime(machine.models()[j], state.qd[j]) + LoadingScript::kPeriod);
    }
    result.horizon = horizon;
  };
  auto visit = [&](double elapsed) {
    extend(machine.state());
    if (Collides(machine.state().q, elapsed, map, T_world_base, scratch, result)) return false;
    return elapsed < horizon - 1e-9;
  };
  if (script != nullptr) {
    LoadingScript rolled = *script;
    RollOut(machine, rolled, settings_.horizon + settings_.stop_time_limit, next_evaluation, visit);
  } else {
    const double dt = settings_.integration_step;
    for (int i = 0; visit(i * dt); ++i) machine.Advance(dt);
  }
  return result;
}

LookAheadResult ObstacleLookAhead::CheckStop(const ExcavatorState& measured,
                                             const ExcavatorSimulator& commands,
                                             const HeightGrid& map,
                                             const Eigen::Isometry3d& T_world_base) const {
  LookAheadResult result;
  std::optional<ExcavatorSimulator> predicted = Prepare(measured, commands, result);
  if (!predicted) return result;
  ExcavatorSimulator& machine = *predicted;
  machine.Command(ExcavatorCommand{JointVector::Zero(), true});
  double latest = 0;
  for (const JointModelParams& p : machine.models()) latest = std::max(latest, p.latency);
  std::vector<EnvelopePoint> scratch;
  const double dt = settings_.integration_step;
  if (Collides(machine.state().q, 0.0, map, T_world_base, scratch, result)) return result;
  for (double t = dt; t <= settings_.stop_time_limit + 0.5 * dt; t += dt) {
    machine.Advance(dt);
    if (Collides(machine.state().q, t, map, T_world_base, scratch, result)) return result;
    if (t > latest && machine.state().qd.cwiseAbs().maxCoeff() < 1e-6) return result;
  }
  result.verdict = LookAheadVerdict::kInvalidState;
  result.reason = "the stop does not come to rest within stop_time_limit";
  return result;
}

}  // namespace autoshovel::control
