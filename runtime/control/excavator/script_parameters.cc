#include "runtime/control/excavator/script_parameters.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "runtime/control/excavator/excavator_simulator.h"
#include "runtime/control/excavator/linkage_clearance.h"
#include "runtime/control/excavator/script_rollout.h"

namespace autoshovel::control {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kBisections = 9;

double Wrap(double angle) { return std::remainder(angle, 2.0 * std::numbers::pi); }

double Sign(double x) { return x >= 0 ? 1.0 : -1.0; }

/// "joint has moved past `threshold` going from `from` towards `to`".
ConditionTerm Past(ExcavatorJoint joint, double from, double to, double threshold) {
  return ConditionTerm{joint, to >= from ? Comparison::kAbove : Comparison::kBelow, threshold, 0};
}

ConditionTerm Near(ExcavatorJoint joint, double value, double tolerance) {
  return ConditionTerm{joint, Comparison::kNear, value, tolerance};
}

void RequireFinite(double value, const char* what) {
  if (!std::isfinite(value)) {
    throw std::invalid_argument(std::string("ComputeScriptParameters: ") + what + " is not finite");
  }
}

void RequirePositive(double value, const char* what) {
  if (!(std::isfinite(value) && value > 0)) {
    throw std::invalid_argument(std::string("ScriptSettings: ") + what + " must be positive");
  }
}

/// Lowest height above `required` of underside points within the radial band [r_lo, r_hi] from
/// the swing axis, over the configurations given (swing 0: the band is the same at every swing).
double BandMargin(const LinkageEnvelope& envelope, double boom, double stick_lo, double stick_hi,
                  double bucket_lo, double bucket_hi, int samples, double r_lo, double r_hi,
                  double required, std::vector<EnvelopePoint>& scratch) {
  double margin = kInf;
  for (int i = 0; i < samples; ++i) {
    const double stick = stick_lo + (stick_hi - stick_lo) * i / (samples - 1);
    for (int k = 0; k < samples; ++k) {
      const double bucket = bucket_lo + (bucket_hi - bucket_lo) * k / (samples - 1);
      envelope.Underside(JointVector(boom, stick, bucket, 0.0), Eigen::Isometry3d::Identity(),
                         scratch);
      for (const EnvelopePoint& p : scratch) {
        const double r = p.p.head<2>().norm();
        if (r >= r_lo && r <= r_hi) margin = std::min(margin, p.p.z() - required);
      }
      if (bucket_hi == bucket_lo) break;
    }
  }
  return margin;
}

/// Whether a linkage `half_width` wide (margin included) swinging through [swing_lo, swing_hi]
/// can come over any part of the box's footprint: some point of the footprint's outline lies
/// within the swept sector widened by the half width at that point's radius (or the swing axis is
/// inside the footprint).
bool InSweptSector(const ObstacleBox& box, double swing_lo, double swing_hi, double half_width) {
  if (box.FootprintDistance(Eigen::Vector2d::Zero()) == 0) return true;
  Eigen::Vector2d corners[4];
  box.Corners(corners);
  const double middle = 0.5 * (swing_lo + swing_hi), half_range = 0.5 * (swing_hi - swing_lo);
  constexpr double kSpacing = 0.05;  // [m] along the outline
  for (int e = 0; e < 4; ++e) {
    const Eigen::Vector2d& a = corners[e];
    const Eigen::Vector2d& b = corners[(e + 1) % 4];
    const int pieces = std::max(1, static_cast<int>(std::ceil((b - a).norm() / kSpacing)));
    for (int i = 0; i < pieces; ++i) {
      const Eigen::Vector2d point = a + (b - a) * (double(i) / pieces);
      const double r = point.norm();
      const double widen = half_width >= r ? std::numbers::pi : std::asin(half_width / r);
      if (std::abs(Wrap(std::atan2(point.y(), point.x()) - middle)) <= half_range + widen) {
        return true;
      }
    }
  }
  return false;
}

}  // namespace

void Validate(const ScriptSettings& s) {
  RequirePositive(s.truck_clearance, "truck_clearance");
  if (!(std::isfinite(s.ground_clearance) && s.ground_clearance >= 0)) {
    throw std::invalid_argument("ScriptSettings: ground_clearance must be >= 0");
  }
  if (!(std::isfinite(s.dig_approach_height) && s.dig_approach_height >= 0)) {
    throw std::invalid_argument("ScriptSettings: dig_approach_height must be >= 0");
  }
  if (!std::isfinite(s.dig_attitude)) {
    throw std::invalid_argument("ScriptSettings: dig_attitude must be finite");
  }
  RequirePositive(s.bucket_carry_margin, "bucket_carry_margin");
  RequirePositive(s.bucket_open_margin, "bucket_open_margin");
  if (!(std::isfinite(s.stick_dump_sweep) && s.stick_dump_sweep >= 0)) {
    throw std::invalid_argument("ScriptSettings: stick_dump_sweep must be >= 0");
  }
  RequirePositive(s.arrival_tolerance, "arrival_tolerance");
  RequirePositive(s.settle_velocity, "settle_velocity");
  RequirePositive(s.prediction_step, "prediction_step");
  RequirePositive(s.max_pass_time, "max_pass_time");
}

LoadingScript BuildLoadingScript(const ScriptParameters& p, const ScriptSettings& s) {
  using J = ExcavatorJoint;
  const double eps = s.arrival_tolerance;
  std::array<JointScript, kNumExcavatorJoints> scripts;
  scripts[JointIndex(J::kSwing)] = {
      J::kSwing,
      {{"wait", {}, p.swing_start},
       {"swing to truck",
        {Past(J::kBoom, p.boom_start, p.boom_clear, p.boom_swing_start)},
        p.swing_dump},
       {"swing to dig",
        {Past(J::kBucket, p.bucket_carry, p.bucket_open, p.bucket_dumped)},
        p.swing_dig},
       {"stop and execute dig", {Near(J::kSwing, p.swing_dig, eps)}, p.swing_dig}}};
  // The boom leaves the dig by rising to φ_clear (Fig. 14) or, when the dig left it above that
  // carrying angle, by holding over the face while the swing leaves it and lowering on the way
  // to the truck; both then hold while leaving the truck and lower to dig.
  std::vector<ScriptRule> boom;
  if (std::isnan(p.swing_boom_lower)) {
    boom = {{"raise", {}, p.boom_clear}};
  } else {
    boom = {{"hold over the face", {}, p.boom_start},
            {"lower to carry",
             {Past(J::kSwing, p.swing_start, p.swing_dump, p.swing_boom_lower)},
             p.boom_clear}};
  }
  boom.push_back({"hold while leaving the truck",
                  {Past(J::kBucket, p.bucket_carry, p.bucket_open, p.bucket_dumped)},
                  p.boom_clear});
  boom.push_back(
      {"lower to dig", {Past(J::kSwing, p.swing_dump, p.swing_dig, p.swing_return)}, p.boom_dig});
  scripts[JointIndex(J::kBoom)] = {J::kBoom, std::move(boom)};
  scripts[JointIndex(J::kStick)] = {
      J::kStick,
      {{"wait", {}, p.stick_start},
       {"move to spill point",
        {Past(J::kSwing, p.swing_start, p.swing_dump, p.swing_stick_out)},
        p.stick_spill},
       {"move to dump point",
        {Past(J::kBucket, p.bucket_carry, p.bucket_open, p.bucket_sweep)},
        p.stick_dump},
       {"move to dig",
        {Past(J::kSwing, p.swing_dump, p.swing_dig, p.swing_return),
         Past(J::kBucket, p.bucket_carry, p.bucket_open, p.bucket_dumped)},
        p.stick_dig}}};
  scripts[JointIndex(J::kBucket)] = {
      J::kBucket,
      {{"curl", {}, p.bucket_carry},
       {"open",
        {Past(J::kSwing, p.swing_start, p.swing_dump, p.swing_bucket_open),
         Near(J::kStick, p.stick_spill, eps)},
        p.bucket_open},
       {"move to dig",
        {Past(J::kSwing, p.swing_dump, p.swing_dig, p.swing_return),
         Past(J::kBucket, p.bucket_carry, p.bucket_open, p.bucket_dumped)},
        p.bucket_dig}}};
  return LoadingScript(std::move(scripts));
}

PassPrediction PredictPass(const LoadingScript& script, const ExcavatorJointModels& models,
                           const ExcavatorState& start, const LinkageEnvelope& envelope,
                           const std::vector<ObstacleBox>& truck, double ground_height,
                           const ScriptSettings& settings, double abandon_below) {
  ExcavatorSimulator machine(models, start, settings.prediction_step);
  LoadingScript rolled = script;
  PassPrediction out;
  const bool check_ground = std::isfinite(ground_height);
  if (check_ground) out.min_return_height = kInf;
  std::vector<EnvelopePoint> points;
  // Coarse samples for every state; fine ones only where a decision hangs on it (near
  // `abandon_below`) and, at the end, for the states that can hold the minimum (within the
  // coarse error of the lowest coarse value): the same result as refining everything.
  const LinkageClearance clearance(envelope, truck);
  const double coarse_error = clearance.coarse_error();
  double lowest_coarse = kInf;
  std::vector<JointVector> candidates;
  bool abandoned = false;
  RollOut(machine, rolled, settings.max_pass_time, 0.0, [&](double elapsed) {
    const ExcavatorState& state = machine.state();
    const double coarse = clearance.Coarse(state.q);
    if (coarse < lowest_coarse + coarse_error) {
      candidates.push_back(state.q);
      lowest_coarse = std::min(lowest_coarse, coarse);
    }
    if (coarse < abandon_below + coarse_error &&
        clearance.Refined(state.q, abandon_below + coarse_error) < abandon_below) {
      abandoned = true;
    }
    if (out.swing_start_time < 0 && rolled.active_rule(ExcavatorJoint::kSwing) >= 1) {
      out.swing_start_time = elapsed;
      out.boom_at_swing_start = state.q[JointIndex(ExcavatorJoint::kBoom)];
    }
    if (check_ground && rolled.active_rule(ExcavatorJoint::kSwing) >= 2) {
      envelope.Underside(state.q, Eigen::Isometry3d::Identity(), points);
      for (const EnvelopePoint& p : points) {
        out.min_return_height = std::min(out.min_return_height, p.p.z() - ground_height);
      }
    }
    out.duration = elapsed;
    if (abandoned) return false;
    if (rolled.Finished(state, settings.arrival_tolerance, settings.settle_velocity)) {
      out.finished = true;
      return false;
    }
    return true;
  });
  for (const JointVector& q : candidates) {
    if (clearance.Coarse(q) < lowest_coarse + coarse_error) {
      out.min_truck_clearance =
          std::min(out.min_truck_clearance, clearance.Refined(q, lowest_coarse + coarse_error));
    }
  }
  return out;
}

void ValidateScriptInputs(const ExcavatorJointModels& models, const ExcavatorState& dig_end,
                          const LoadingGoal& goal, const ScriptSettings& settings) {
  Validate(settings);
  Validate(models);
  if (FirstNonFinite(dig_end.q) >= 0 || FirstNonFinite(dig_end.qd) >= 0) {
    throw std::invalid_argument("ComputeScriptParameters: the dig-end state is not finite");
  }
  if (!goal.p_base_dig.allFinite() || !goal.p_base_dump.allFinite()) {
    throw std::invalid_argument("ComputeScriptParameters: dig or dump point is not finite");
  }
  if (goal.truck.empty()) {
    throw std::invalid_argument("ComputeScriptParameters: no truck boxes given");
  }
  for (const ObstacleBox& box : goal.truck) Validate(box, "ComputeScriptParameters: truck");
  if (std::isinf(goal.ground_height)) RequireFinite(goal.ground_height, "ground height");
}

// The swing angles (dig and dump azimuths, unwrapped the short way from where the swing is), the
// dig pose (the dig point raised by the approach height, the bucket at the dig attitude), the
// starts and the bucket's carry and open angles.
void SetSwingAndDigPose(const ExcavatorKinematics& kinematics, const ExcavatorState& dig_end,
                        const LoadingGoal& goal, const ScriptSettings& settings,
                        ScriptParameters& p) {
  const double eps = settings.arrival_tolerance;
  const int kBoom = JointIndex(ExcavatorJoint::kBoom);
  const int kStick = JointIndex(ExcavatorJoint::kStick);
  const int kBucket = JointIndex(ExcavatorJoint::kBucket);
  const int kSwing = JointIndex(ExcavatorJoint::kSwing);
  // Swing angles: the dig and dump azimuths, unwrapped to the short way from where the swing is.
  p.swing_start = dig_end.q[kSwing];
  p.swing_dig =
      p.swing_start + Wrap(std::atan2(goal.p_base_dig.y(), goal.p_base_dig.x()) - p.swing_start);
  p.swing_dump =
      p.swing_dig + Wrap(std::atan2(goal.p_base_dump.y(), goal.p_base_dump.x()) - p.swing_dig);
  if (std::abs(p.swing_dump - p.swing_start) < 4 * eps ||
      std::abs(p.swing_dump - p.swing_dig) < 4 * eps) {
    throw std::invalid_argument(
        "ComputeScriptParameters: the dump azimuth is within a few degrees of the dig's");
  }
  p.direction = Sign(p.swing_dump - p.swing_start);

  // The dig pose: the dig point raised by the approach height, the bucket at the dig attitude.
  const Eigen::Vector3d p_base_approach =
      goal.p_base_dig + Eigen::Vector3d(0, 0, settings.dig_approach_height);
  const std::optional<JointVector> q_dig =
      kinematics.SolveTip(p_base_approach, settings.dig_attitude);
  if (!q_dig) {
    throw std::invalid_argument(
        "ComputeScriptParameters: the dig point is out of reach (or only outside the joint "
        "limits) with the bucket at the dig attitude");
  }
  p.boom_dig = (*q_dig)[kBoom];
  p.stick_dig = (*q_dig)[kStick];
  p.bucket_dig = (*q_dig)[kBucket];

  p.boom_start = dig_end.q[kBoom];
  p.stick_start = dig_end.q[kStick];
  p.bucket_carry = kinematics.joint_min()[kBucket] + settings.bucket_carry_margin;
  p.bucket_open = kinematics.joint_max()[kBucket] - settings.bucket_open_margin;
  if (!(p.bucket_open > p.bucket_carry + 4 * eps)) {
    throw std::invalid_argument("ComputeScriptParameters: bucket margins leave no opening");
  }
}

// The truck's radial band and what must be cleared over it, then the bucket pin over the dump
// point as low as the band test allows.
void SetDumpPose(const LinkageEnvelope& envelope, const LoadingGoal& goal,
                 const ScriptSettings& settings, ScriptParameters& p) {
  const ExcavatorKinematics& kinematics = envelope.kinematics();
  const int kBoom = JointIndex(ExcavatorJoint::kBoom);
  const int kStick = JointIndex(ExcavatorJoint::kStick);
  // The truck's radial band and what must be cleared over it, from the boxes the pass can sweep.
  double max_width = 0;
  for (const LinkShape& shape : envelope.config().shapes)
    max_width = std::max(max_width, shape.width);
  const double swing_lo = std::min({p.swing_start, p.swing_dump, p.swing_dig});
  const double swing_hi = std::max({p.swing_start, p.swing_dump, p.swing_dig});
  double r_lo = kInf, r_hi = 0, top = goal.p_base_dump.z();
  for (const ObstacleBox& box : goal.truck) {
    if (!InSweptSector(box, swing_lo, swing_hi, 0.5 * max_width + settings.truck_clearance)) {
      continue;
    }
    r_lo = std::min(r_lo, box.FootprintDistance(Eigen::Vector2d::Zero()));
    Eigen::Vector2d corners[4];
    box.Corners(corners);
    for (const Eigen::Vector2d& c : corners) r_hi = std::max(r_hi, c.norm());
    top = std::max(top, box.z_max);
  }
  const double margin = settings.truck_clearance;
  if (!(r_hi > 0)) {
    throw std::invalid_argument("ComputeScriptParameters: no truck box lies under the pass");
  }
  p.clearance_height = top + margin;
  const double band_lo = r_lo - margin, band_hi = r_hi + margin;

  // The bucket pin over the dump point, as low as the band test allows.
  const double r_pin = goal.p_base_dump.head<2>().norm();
  std::vector<EnvelopePoint> scratch;
  constexpr int kSamples = 7;
  struct DumpPose {
    bool reachable = false;
    double margin = -kInf;
    double boom = 0, spill = 0, dump = 0;
  };
  auto dump_pose = [&](double z_pin) {
    DumpPose d;
    const std::optional<JointVector> q =
        kinematics.SolveBucketPin(Eigen::Vector2d(r_pin, z_pin), 0.0, p.bucket_carry);
    if (!q) return d;
    d.reachable = true;
    d.boom = (*q)[kBoom];
    d.spill = (*q)[kStick];
    d.dump = std::max(d.spill - settings.stick_dump_sweep, kinematics.joint_min()[kStick]);
    const double stick_lo = std::min({p.stick_start, d.spill, d.dump});
    const double stick_hi = std::max({p.stick_start, d.spill, d.dump});
    const double carrying =
        BandMargin(envelope, d.boom, stick_lo, stick_hi, p.bucket_carry, p.bucket_carry, kSamples,
                   band_lo, band_hi, p.clearance_height, scratch);
    const double dumping =
        BandMargin(envelope, d.boom, d.dump, d.spill, p.bucket_carry, p.bucket_open, kSamples,
                   band_lo, band_hi, p.clearance_height, scratch);
    d.margin = std::min(carrying, dumping);
    return d;
  };
  auto acceptable = [](const DumpPose& d) { return d.reachable && d.margin >= 0; };
  // Scan upwards in 0.25 m steps for the first clearing height, then bisect below it (the pin
  // is rarely more than a metre below what the underside must clear: the stick hangs below it).
  double z_fail = p.clearance_height - 1.5;
  double z_pass = std::numeric_limits<double>::quiet_NaN();
  DumpPose chosen;
  for (double z = z_fail; z <= p.clearance_height + 8.0; z += 0.25) {
    const DumpPose d = dump_pose(z);
    if (acceptable(d)) {
      z_pass = z;
      chosen = d;
      break;
    }
    z_fail = z;
  }
  if (std::isnan(z_pass)) {
    throw std::invalid_argument(
        "ComputeScriptParameters: no boom and stick angle put the bucket over the dump point "
        "with the linkage " +
        std::to_string(margin) + " m above the truck within the joint limits");
  }
  for (int i = 0; i < kBisections; ++i) {
    const double z = 0.5 * (z_fail + z_pass);
    const DumpPose d = dump_pose(z);
    if (acceptable(d)) {
      z_pass = z;
      chosen = d;
    } else {
      z_fail = z;
    }
  }
  p.dump_pin_height = z_pass;
  p.boom_clear = chosen.boom;
  p.stick_spill = chosen.spill;
  p.stick_dump = chosen.dump;
}

// The thresholds that start the stick, open the bucket and sweep it, from the joint models.
void SetTimingThresholds(const ExcavatorJointModels& models, const ScriptSettings& settings,
                         ScriptParameters& p) {
  const double eps = settings.arrival_tolerance;
  const int kStick = JointIndex(ExcavatorJoint::kStick);
  const int kBucket = JointIndex(ExcavatorJoint::kBucket);
  const int kSwing = JointIndex(ExcavatorJoint::kSwing);
  // Timing thresholds from the joint models.
  const JointModelParams& swing_model = models[kSwing];
  const JointModelParams& stick_model = models[kStick];
  const JointModelParams& bucket_model = models[kBucket];
  const double swing_time = TimeToReach(swing_model, p.swing_start, p.swing_dump, eps);
  const double stick_time = TimeToReach(stick_model, p.stick_start, p.stick_spill, eps);
  const double toward_dump = p.direction;
  // A swing threshold between "just moved" and "arrived", as a distance from the start.
  const double swing_span = std::abs(p.swing_dump - p.swing_start);
  auto swing_after = [&](double elapsed) {
    const double travelled =
        toward_dump *
        (PositionAfter(swing_model, p.swing_start, p.swing_dump, elapsed) - p.swing_start);
    return p.swing_start + toward_dump * std::clamp(travelled, 0.5 * eps, swing_span - eps);
  };
  p.swing_stick_out = swing_after(std::max(0.0, swing_time - stick_time));
  p.swing_bucket_open = swing_after(std::max(0.0, swing_time - bucket_model.latency));
  const double opening = Sign(p.bucket_open - p.bucket_carry);
  const double open_speed =
      opening > 0 ? bucket_model.max_velocity_up : bucket_model.max_velocity_down;
  const double bucket_span = std::abs(p.bucket_open - p.bucket_carry);
  p.bucket_dumped = p.bucket_open -
                    opening * std::clamp(open_speed * swing_model.latency, eps, 0.5 * bucket_span);
  p.bucket_sweep = 0.5 * (p.bucket_carry + p.bucket_open);
}

ScriptParameters ComputeScriptParameters(const LinkageEnvelope& envelope,
                                         const ExcavatorJointModels& models,
                                         const ExcavatorState& dig_end, const LoadingGoal& goal,
                                         const ScriptSettings& settings) {
  ValidateScriptInputs(models, dig_end, goal, settings);
  const double eps = settings.arrival_tolerance;
  const int kBoom = JointIndex(ExcavatorJoint::kBoom);
  const int kSwing = JointIndex(ExcavatorJoint::kSwing);
  ScriptParameters p;

  SetSwingAndDigPose(envelope.kinematics(), dig_end, goal, settings, p);
  SetDumpPose(envelope, goal, settings, p);
  const double margin = settings.truck_clearance;

  SetTimingThresholds(models, settings, p);
  const JointModelParams& swing_model = models[kSwing];
  const double swing_span = std::abs(p.swing_dump - p.swing_start);

  // Bisections on predicted passes. While the swing start is searched, lowering waits until the
  // swing is nearly back at the dig, so only the way out is judged.
  const double return_span = std::abs(p.swing_dump - p.swing_dig);
  auto return_at = [&](double u) {
    return p.swing_dump - p.direction * (eps + u * (return_span - 3 * eps));
  };
  p.swing_return = return_at(1.0);
  const double boom_raise = p.boom_clear - dig_end.q[kBoom];
  const double boom_latest = p.boom_clear - Sign(boom_raise) * eps;
  auto predict = [&](double abandon_below) {
    return PredictPass(BuildLoadingScript(p, settings), models, dig_end, envelope, goal.truck,
                       goal.ground_height, settings, abandon_below);
  };
  // The sampled clearance may over-estimate the true one by the evaluator's accuracy.
  const double required = margin + LinkageClearance(envelope, {}).accuracy();
  auto clears = [&](const PassPrediction& pass) {
    return pass.finished && pass.min_truck_clearance >= required &&
           (std::isnan(pass.min_return_height) ||
            pass.min_return_height >= settings.ground_clearance);
  };
  p.swing_boom_lower = std::numeric_limits<double>::quiet_NaN();
  if (boom_raise < -eps) {
    // The dig ended with the boom above the carrying angle (lifted out over a high face).
    // Lowering it first, the swing waiting, would drive the bucket back into the face; the swing
    // starts at once (φ_swing just beyond the start, crossed at the first evaluation) and the
    // boom lowers once the swing has covered a third of its way.
    p.boom_swing_start = p.boom_start + 0.5 * eps;
    p.swing_boom_lower = p.swing_start + p.direction * swing_span / 3.0;
  } else if (!settings.overlap_swing_and_raise || std::abs(boom_raise) <= eps) {
    p.boom_swing_start = boom_latest;
  } else {
    p.boom_swing_start = boom_latest;
    if (!clears(predict(required))) {
      throw std::invalid_argument(
          "ComputeScriptParameters: even swinging after the full raise, the predicted pass does "
          "not clear the truck by the margin");
    }
    double fail = dig_end.q[kBoom], pass = boom_latest;
    for (int i = 0; i < kBisections; ++i) {
      p.boom_swing_start = 0.5 * (fail + pass);
      (clears(predict(required)) ? pass : fail) = p.boom_swing_start;
    }
    // A threshold is only seen at the 10 Hz evaluations, so a machine a little ahead of the
    // prediction may cross it one evaluation early. Raised by one period of boom travel, the
    // threshold cannot start the swing before the verified one did.
    const JointModelParams& boom_model = models[kBoom];
    const double boom_speed =
        boom_raise > 0 ? boom_model.max_velocity_up : boom_model.max_velocity_down;
    const double shifted = pass + Sign(boom_raise) * boom_speed * LoadingScript::kPeriod;
    p.boom_swing_start =
        boom_raise > 0 ? std::min(shifted, boom_latest) : std::max(shifted, boom_latest);
  }
  p.swing_return = return_at(1.0);
  if (!clears(predict(required))) {
    throw std::invalid_argument(
        "ComputeScriptParameters: the predicted pass does not clear the truck (or the ground) "
        "even when lowering only at the dig");
  }
  p.swing_return = return_at(0.0);
  if (!clears(predict(required))) {
    double fail = 0.0, pass = 1.0;
    for (int i = 0; i < kBisections; ++i) {
      const double u = 0.5 * (fail + pass);
      p.swing_return = return_at(u);
      (clears(predict(required)) ? pass : fail) = u;
    }
    // As for the swing start: moved by one period of swing travel at the return's peak rate
    // (the triangular profile's, at most v_max) towards the dig, so that an early crossing cannot
    // lower the boom before the verified threshold would.
    const double peak =
        std::min(p.direction > 0 ? swing_model.max_velocity_down : swing_model.max_velocity_up,
                 std::sqrt(swing_model.max_acceleration * return_span));
    p.swing_return =
        return_at(std::min(1.0, pass + peak * LoadingScript::kPeriod / (return_span - 3 * eps)));
  }

  const PassPrediction final_pass = predict(-kInf);
  if (!final_pass.finished) {
    throw std::invalid_argument("ComputeScriptParameters: the predicted pass does not finish in " +
                                std::to_string(settings.max_pass_time) + " s");
  }
  p.predicted_pass_time = final_pass.duration;
  p.predicted_min_truck_clearance = final_pass.min_truck_clearance;
  p.predicted_min_return_height = final_pass.min_return_height;
  return p;
}

}  // namespace autoshovel::control
