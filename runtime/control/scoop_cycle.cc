// One scoop: approach, crowd, trigger, scoop (Algorithm 3), level, shake, retreat (seed §6.2).
#include "runtime/control/scoop_cycle.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <stdexcept>
#include <utility>

#include "runtime/control/joint_angle_filter.h"
#include "runtime/model/interpreted_model.h"
#include "runtime/prediction/scoop_volume_prediction.h"

namespace autoshovel::control {

namespace {

const char* PhaseName(int phase) {
  static const char* kNames[] = {"approach", "crowd", "scoop", "level", "shake", "retreat", "done"};
  return kNames[phase];
}

bool Finite(const Proprioception& s) {
  const double values[] = {s.time,   s.hinge_xy.x(), s.hinge_xy.y(), s.heading,  s.speed,
                           s.q_boom, s.q_bucket,     s.qd_boom,      s.qd_bucket};
  return std::all_of(std::begin(values), std::end(values),
                     [](double v) { return std::isfinite(v); });
}

// Low-pass estimate of the achieved over the modelled joint rate, updated only while the
// modelled rate is large enough to tell (time constant 0.1 s: a few sensor samples). In
// [0, 1.5]: 0 for a joint held fast in the pile, above 1 where the joint runs faster than the
// valve model says (the loaded boom of the sand-bin cycle rose at ~0.18 rad/s at full opening,
// the model's 0.16).
void UpdateResponse(double& response, double measured_rate, double modelled_rate, double dt) {
  constexpr double kMinRate = 0.02, kTimeConstant = 0.1, kMaxRatio = 1.5;  // [rad/s], [s], [-]
  if (std::abs(modelled_rate) < kMinRate || !std::isfinite(measured_rate)) return;
  const double ratio = std::clamp(measured_rate / modelled_rate, 0.0, kMaxRatio);
  response += std::min(dt / kTimeConstant, 1.0) * (ratio - response);
}

void RememberOpening(std::deque<double>& openings, double opening, std::size_t keep) {
  openings.push_back(opening);
  while (openings.size() > keep) openings.pop_front();
}

}  // namespace

const char* ToString(ScoopPolicy policy) {
  switch (policy) {
    case ScoopPolicy::kAutoSelection:
      return "auto_selection";
    case ScoopPolicy::kJustInOut:
      return "just_in_out";
    case ScoopPolicy::kStairway:
      return "stairway";
    case ScoopPolicy::kStairwayFixed:
      return "stairway_fixed";
    case ScoopPolicy::kOptimal:
      return "optimal";
  }
  return "?";
}

std::string ScoopCycleOptions::Invalid() const {
  if (!(tick > 0) || !std::isfinite(tick)) return "scoop cycle: tick must be > 0 s";
  if (decision_every < 1) return "scoop cycle: decision_every must be >= 1";
  const double stall[] = {boom_stall_time, boom_stall_rate, boom_stall_opening};
  for (double v : stall) {
    if (!(v >= 0) || !std::isfinite(v)) return "scoop cycle: boom stall limits must be >= 0";
  }
  const double positive[] = {attack_speed, scoop_deceleration, retreat_speed,
                             target_fill,  max_approach,       max_crowd,
                             max_scoop,    max_retreat,        action_timeout};
  for (double v : positive) {
    if (!(v > 0) || !std::isfinite(v)) return "scoop cycle: speeds, fill and limits must be > 0";
  }
  const double non_negative[] = {retreat_beyond_contact,
                                 contact_volume,
                                 rack_back_margin,
                                 boom_margin,
                                 arm_motion,
                                 path_spacing};
  for (double v : non_negative) {
    if (!(v >= 0) || !std::isfinite(v)) return "scoop cycle: margins must be finite and >= 0";
  }
  if (!(joint_filter_gain > 0 && joint_filter_gain <= 1)) {
    return "scoop cycle: joint_filter_gain must be in (0, 1]";
  }
  if (!std::isfinite(attack_pose.boom) || !std::isfinite(attack_pose.bucket)) {
    return "scoop cycle: attack_pose must be finite";
  }
  if (std::string why = strategy.Invalid(); !why.empty()) return why;
  if (std::string why = finishing.Invalid(); !why.empty()) return why;
  for (const JointPidGains* g : {&boom_gains, &bucket_gains}) {
    if (std::string why = g->Invalid(); !why.empty()) return why;
  }
  return speed_gains.Invalid();
}

const PhaseRecord* ScoopResult::Phase(const std::string& name) const {
  for (const PhaseRecord& p : phases) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

double ScoopResult::ContactToScoopEndTime() const {
  const PhaseRecord* crowd = Phase("crowd");
  const PhaseRecord* scoop = Phase("scoop");
  return (crowd ? crowd->duration : 0) + (scoop ? scoop->duration : 0);
}

double ScoopResult::ContactToScoopEndEnergy() const {
  const PhaseRecord* crowd = Phase("crowd");
  const PhaseRecord* scoop = Phase("scoop");
  return (crowd ? crowd->energy : 0) + (scoop ? scoop->energy : 0);
}

// Everything that changes during one Run().
struct ScoopCycle::Runtime {
  Phase phase = Phase::kApproach;
  std::optional<PlannedScoop> plan;  ///< ScoopPolicy::kOptimal, from contact
  double plan_start = NAN;           ///< machine clock at contact [s]
  ScoopResult result;
  double phase_start_time = 0;
  double phase_start_energy = 0;
  ArmTargets targets;
  std::optional<ScoopSequencer> sequencer;
  std::optional<AtomicAction> action;
  double action_start = 0;
  double arrived_at = NAN;  ///< when the running action reached its target [s]
  bool arm_moving = false;
  double q_bucket_at_trigger = 0;
  double q_boom_at_trigger = 0;
  bool finishing_drive = false;  ///< scoop: the final rack/lift runs
  double slowing_since = NAN;    ///< scoop: when the drive began its fixed deceleration [s]
  double shake_start = 0;
  Eigen::Vector2d contact_hinge = Eigen::Vector2d::Zero();
  std::vector<Eigen::Vector3d> tip_path;  ///< world [m]
  double v1 = 0;
  StopDetector stop;
  double open_loop_bucket = NAN;  ///< a duty bypassing the bucket PID (shaking) [-]
  bool stopping = false;          ///< retreat: reversed far enough, stopping
  /// When finite, the bucket target follows the boom so the bucket keeps this attitude
  /// q_boom + q_bucket in the arm plane [rad] (exit lift, levelling, carrying).
  double hold_attitude = NAN;
  std::string stop_request;         ///< RequestStop's reason: crowding ends at the next decision
  bool drive_held = false;          ///< after a stop request the scoop does not crowd on
  double boom_lifting_since = NAN;  ///< scoop: the boom valve opened to lift since [s]
  double boom_stalled_since = NAN;  ///< scoop: the boom slower than the stall rate since [s]
  bool drive_eased = false;         ///< scoop: eased for a stalled boom, until the next action
  bool drive_hold_started = false;  ///< the speed profile restarted from the speed at the hold
  /// JointStalledUnderLoad's reports not yet acted on: (joint, reason).
  std::vector<std::pair<int, std::string>> pending_stalls;
  bool sequence_ended = false;  ///< scoop: a stalled boom ended the atomic actions
  std::vector<Eigen::Vector3d> last_predicted_path;  ///< of the last V2 [m]
  double last_v2 = NAN;                              ///< [m³]
  double v2_this_decision = NAN;  ///< V2 if the running decision computed one [m³]
  std::optional<prediction::PenetrationFeatures> last_features;  ///< of the last V2
  double last_penetration = NAN;  ///< the predictor's travel of the last V2, NaN: failed [m]
  Eigen::Vector2d trigger_hinge = Eigen::Vector2d::Zero();
  double trigger_heading = 0;
  std::optional<JointPid> boom_pid, bucket_pid;
  /// Spool openings sent within each valve's delay (transport + spool lag), oldest first.
  std::deque<double> boom_openings, bucket_openings;
  /// Achieved over modelled rate of each joint while holding an attitude [-] (1: as modelled).
  double boom_response = 1, bucket_response = 1;
  bool exit_hold_reached = false;  ///< the exit lift's bucket has reached the held attitude
  double exit_error_held = 0, exit_error_overall = 0;  ///< largest |attitude − held| [rad]
  std::optional<JointAngleFilter> boom_filter, bucket_filter;
  std::optional<SpeedPid> speed_pid;
  core::ActuatorCommand command;
  long tick = 0;
};

ScoopCycle::ScoopCycle(const model::MachineDescription& machine,
                       const generated::MachineFunctions& functions,
                       const prediction::HeightGrid& map, const model::Material& material,
                       ScoopTrigger& trigger, const prediction::PenetrationPredictor* predictor,
                       const ScoopCycleOptions& options)
    : machine_(machine),
      functions_(functions),
      map_(map),
      material_(material),
      trigger_(trigger),
      predictor_(predictor),
      options_(options) {
  if (const std::string why = options.Invalid(); !why.empty()) throw std::invalid_argument(why);
  if (machine.links.size() != 2 || machine.swing) {
    throw std::invalid_argument("scoop cycle: machine '" + machine.name +
                                "' is not a two-link loader arm");
  }
  boom_valve_ = machine.ActuatorOfJoint(0);
  bucket_valve_ = machine.ActuatorOfJoint(1);
  if (boom_valve_ < 0 || bucket_valve_ < 0) {
    throw std::invalid_argument("scoop cycle: machine '" + machine.name +
                                "' has no actuator on the boom or bucket joint");
  }
  if (trigger.NeedsPrediction() || options.policy == ScoopPolicy::kAutoSelection) {
    if (predictor == nullptr) {
      throw std::invalid_argument("scoop cycle: trigger '" + trigger.Name() + "' / policy '" +
                                  ToString(options.policy) + "' needs a penetration predictor");
    }
  }
  limits_.boom_max = machine.links[0].joint_max - options.boom_margin;
  limits_.bucket_max = machine.links[1].joint_max - options.rack_back_margin;
  const model::Valve& valve = machine.hydraulics.actuators[bucket_valve_].valve;
  bucket_delay_ = valve.transport_delay + valve.spool_time_constant;
  if (options.attitude_feed_forward) attitude_feed_forward_.emplace(machine, functions);
  const model::Valve& boom_valve = machine.hydraulics.actuators[boom_valve_].valve;
  boom_delay_ticks_ = static_cast<std::size_t>(
      std::lround((boom_valve.transport_delay + boom_valve.spool_time_constant) / options.tick));
  bucket_delay_ticks_ = static_cast<std::size_t>(std::lround(bucket_delay_ / options.tick));
  // "The bucket's upper edge is leveled" (§6.2).
  level_attitude_ = model::BucketLevelAttitude(machine) + options.finishing.carry_tilt_back;
  // A planned trajectory's joint references go out this far ahead: a command reaches the spool
  // after the pilot and transport delays.
  for (int valve_index : {boom_valve_, bucket_valve_}) {
    const model::Valve& v = machine.hydraulics.actuators[valve_index].valve;
    plan_lead_ = std::max(plan_lead_, v.pilot_delay + v.transport_delay);
  }
}

namespace {

// A plan's reference at time t since contact, linear between its nodes, held at the ends.
double PlanAt(const std::vector<double>& time, const std::vector<double>& value, double t) {
  if (t <= time.front()) return value.front();
  if (t >= time.back()) return value.back();
  const auto it = std::upper_bound(time.begin(), time.end(), t);
  const std::size_t k = static_cast<std::size_t>(it - time.begin()) - 1;
  const double w = (t - time[k]) / std::max(time[k + 1] - time[k], 1e-9);
  return (1 - w) * value[k] + w * value[k + 1];
}

}  // namespace

double ScoopCycle::BucketTargetForAttitude(double attitude, double q_boom) const {
  return std::clamp(attitude - q_boom, machine_.links[1].joint_min, limits_.bucket_max);
}

bool ScoopCycle::BoomPinnedByTheDrive(const Proprioception& s, Runtime& rt) const {
  if (rt.drive_eased) return true;
  if (!(options_.boom_stall_time > 0) || !rt.action) return false;
  // The opening sent last tick to the boom valve (the PID's output, dead zone compensated;
  // positive lifts). A lifting opening takes the valve's delay to move the boom, so the boom counts
  // as stalled only once the opening has been held that long plus the stall time, with the boom
  // slow for the stall time.
  const bool lifting = rt.command.valve[boom_valve_] >= options_.boom_stall_opening;
  if (!lifting) rt.boom_lifting_since = NAN;
  if (lifting && std::isnan(rt.boom_lifting_since)) rt.boom_lifting_since = s.time;
  if (s.qd_boom >= options_.boom_stall_rate) rt.boom_stalled_since = NAN;
  if (s.qd_boom < options_.boom_stall_rate && std::isnan(rt.boom_stalled_since)) {
    rt.boom_stalled_since = s.time;
  }
  const double boom_delay = static_cast<double>(boom_delay_ticks_) * options_.tick;
  if (!lifting || s.time - rt.boom_lifting_since < boom_delay + options_.boom_stall_time ||
      s.time - rt.boom_stalled_since < options_.boom_stall_time) {
    return false;
  }
  // Brake from the speed the machine has (as for a held drive): the PI's integral is wound
  // up against the pile.
  rt.drive_eased = true;
  rt.result.drive_eased_for_boom = true;
  rt.speed_pid->Reset(std::max(s.speed, 0.0));
  return true;
}

void ScoopCycle::HoldAttitudeAhead(const Proprioception& s, Runtime& rt, double& bucket_now,
                                   double& feed_forward) const {
  const AttitudeHoldFeedForward& hold = *attitude_feed_forward_;
  const std::vector<double> q = {s.q_boom, s.q_bucket};
  // How much of the valve model's rate each joint gets now, from the opening acting now (sent
  // one valve delay ago): a bucket still in the pile may hold the boom back or stop it, and
  // neither the prediction nor the feed-forward may count on motion that does not come.
  const double boom_acting = rt.boom_openings.empty() ? 0.0 : rt.boom_openings.front();
  const double bucket_acting = rt.bucket_openings.empty() ? 0.0 : rt.bucket_openings.front();
  const double passive = hold.PassiveBucketPerBoom(q);
  UpdateResponse(rt.boom_response, s.qd_boom, hold.JointRate(0, boom_acting, q), options_.tick);
  UpdateResponse(rt.bucket_response, s.qd_bucket - passive * s.qd_boom,
                 hold.JointRate(1, bucket_acting, q), options_.tick);
  // Smith predictor over the valves' delay: the PID compares the joints as the openings already
  // sent will leave them, so it neither fights motion still in the pipe nor keeps pushing for
  // what it cannot see yet (the rack-back arrives still moving; the lift moves 0.6 s late).
  const double boom_ahead =
      s.q_boom + rt.boom_response * hold.JointTravel(0, rt.boom_openings, q, options_.tick);
  const double bucket_ahead =
      s.q_bucket + rt.bucket_response * hold.JointTravel(1, rt.bucket_openings, q, options_.tick) +
      passive * (boom_ahead - s.q_boom);
  const double unclamped = rt.hold_attitude - boom_ahead;
  rt.targets.bucket = BucketTargetForAttitude(rt.hold_attitude, boom_ahead);
  bucket_now = bucket_ahead;
  // The boom opening sent boom_lag() ago moves the boom when this tilt opening moves the bucket.
  // Only while the attitude is reachable: at a joint limit the bucket cannot follow.
  const auto lag_ticks = static_cast<std::size_t>(std::lround(hold.boom_lag() / options_.tick));
  const double boom_opening = rt.boom_openings.size() > lag_ticks
                                  ? rt.boom_openings[rt.boom_openings.size() - 1 - lag_ticks]
                                  : 0.0;
  feed_forward =
      rt.targets.bucket == unclamped ? hold.BucketDemand(rt.boom_response * boom_opening, q) : 0.0;
}

void ScoopCycle::EnterPhase(ScoopMachine& machine, Phase phase, const Proprioception& s,
                            Runtime& rt) {
  if (rt.phase != Phase::kDone) {
    rt.result.phases.push_back({.name = PhaseName(static_cast<int>(rt.phase)),
                                .start = rt.phase_start_time,
                                .duration = s.time - rt.phase_start_time,
                                .energy = machine.Energy() - rt.phase_start_energy});
  }
  rt.phase = phase;
  rt.phase_start_time = s.time;
  rt.phase_start_energy = machine.Energy();
  machine.SetPhase(PhaseName(static_cast<int>(phase)));
}

double ScoopCycle::ComputeV2(const Proprioception& s, double v1, Runtime& rt) {
  prediction::V2Prediction v2 =
      prediction::PredictV2(machine_, functions_, map_, material_, *predictor_, rt.tip_path,
                            {.hinge_xy = s.hinge_xy,
                             .heading = s.heading,
                             .speed = s.speed,
                             .q_boom = s.q_boom,
                             .q_bucket = s.q_bucket},
                            v1, limits_.bucket_max, options_.strategy.exit_boom_lift);
  rt.last_features = v2.features;
  if (!v2.ok) {
    ++rt.result.prediction_failures;
    if (std::isnan(v2.penetration)) return 0;
  }
  rt.last_penetration = v2.penetration;
  if (v2.ok) rt.last_predicted_path = std::move(v2.path);
  return v2.v2;
}

void ScoopCycle::EndScoopPhase(ScoopMachine& machine, const Proprioception& s, Runtime& rt) {
  rt.result.feedback_volume = rt.v1;
  rt.result.payload_after_scoop = machine.PayloadVolume();
  EnterPhase(machine, Phase::kLevel, s, rt);
  rt.hold_attitude = level_attitude_;
  rt.arrived_at = NAN;
}

void ScoopCycle::ScoopTimedOut(Runtime& rt) const {
  rt.result.failure = "scoop not complete within " + std::to_string(options_.max_scoop) + " s";
  rt.phase = Phase::kDone;
}

void ScoopCycle::StartPlan(ScoopMachine& machine, const Proprioception& s, Runtime& rt) {
  ScoopPlanRequest request;
  request.speed = std::max(s.speed, 0.0);
  request.q_boom = s.q_boom;
  request.q_bucket = s.q_bucket;
  request.payload_volume = machine.PayloadVolume();
  request.target_volume = rt.result.target_volume;
  // The pile ahead as the pre-contact map saw it; unknown cells and noise below read as floor.
  const Eigen::Vector2d forward(std::cos(s.heading), std::sin(s.heading));
  for (double x = 0; x <= 14.0 + 1e-9; x += request.profile_spacing) {
    const Eigen::Vector2d p = s.hinge_xy + x * forward;
    const double h = map_.HeightAt(p.x(), p.y());
    request.profile_heights.push_back(std::isfinite(h) ? std::max(h, 0.0) : 0.0);
  }
  std::string why = "no planner";
  std::optional<PlannedScoop> plan = planner_ ? planner_(request, &why) : std::nullopt;
  if (!plan || plan->time.size() < 2 || plan->speed.size() != plan->time.size() ||
      plan->q_boom.size() != plan->time.size() || plan->q_bucket.size() != plan->time.size()) {
    rt.result.failure = "optimal scoop: no plan at contact: " + why;
    rt.phase = Phase::kDone;
    return;
  }
  ScoopResult& r = rt.result;
  r.strategy = ScoopStrategy::kOptimal;
  r.trigger_time = s.time;
  r.trigger_after_contact = 0;
  r.trigger_reason = "plan";
  r.v1_at_trigger = rt.v1;
  r.planned_energy = plan->energy;
  r.planned_volume = plan->volume;
  r.plan_solve_seconds = plan->solve_seconds;
  rt.trigger_hinge = s.hinge_xy;
  rt.trigger_heading = s.heading;
  r.travel_after_trigger = 0;
  rt.q_bucket_at_trigger = s.q_bucket;
  rt.q_boom_at_trigger = s.q_boom;
  rt.plan = std::move(plan);
  rt.plan_start = s.time;
  rt.hold_attitude = NAN;
  EnterPhase(machine, Phase::kCrowd, s, rt);  // a crowd of no time: contact → scoop end is whole
  EnterPhase(machine, Phase::kScoop, s, rt);
}

void ScoopCycle::Decide(ScoopMachine& machine, const Proprioception& s, Runtime& rt) {
  const bool stopped = rt.stop.Update(s.speed) || !rt.stop_request.empty();
  if (rt.phase == Phase::kApproach || rt.phase == Phase::kCrowd || rt.phase == Phase::kScoop) {
    if (rt.tip_path.size() >= 2) {
      rt.v1 = prediction::Eq19Volume(map_, rt.tip_path, machine_.bucket.width).volume;
    }
  }
  const double elapsed = s.time - rt.phase_start_time;
  switch (rt.phase) {
    case Phase::kApproach:
      return DecideApproach(machine, s, rt, elapsed);
    case Phase::kCrowd:
      return DecideCrowd(machine, s, rt, elapsed, stopped);
    case Phase::kScoop:
      return DecideScoop(machine, s, rt, elapsed);
    case Phase::kLevel:
    case Phase::kShake:
    case Phase::kRetreat:
      return DecideFinishing(machine, s, rt, elapsed);
    case Phase::kDone:
      return;
  }
}

// Approach: contact once V1 passes the contact volume (then the crowd, or the plan at contact).
void ScoopCycle::DecideApproach(ScoopMachine& machine, const Proprioception& s, Runtime& rt,
                                double elapsed) {
  if (!rt.stop_request.empty()) {
    rt.result.failure = "stopped before contact: " + rt.stop_request;
    rt.phase = Phase::kDone;
    return;
  }
  if (rt.v1 > options_.contact_volume) {
    rt.result.contact_time = s.time;
    rt.result.boom_pressure_at_contact = s.boom_pressure;
    rt.contact_hinge = s.hinge_xy;
    rt.stop.Reset();
    if (options_.policy == ScoopPolicy::kOptimal) {
      StartPlan(machine, s, rt);
      return;
    }
    EnterPhase(machine, Phase::kCrowd, s, rt);
  } else if (elapsed > options_.max_approach) {
    rt.result.failure =
        "no contact with the pile within " + std::to_string(options_.max_approach) + " s";
    rt.phase = Phase::kDone;
  }
  return;
}

// Crowd: the trigger, and Algorithm 3's choice of strategy when it fires (or the machine stops).
void ScoopCycle::DecideCrowd(ScoopMachine& machine, const Proprioception& s, Runtime& rt,
                             double elapsed, bool stopped) {
  TriggerInputs in;
  in.v1 = rt.v1;
  in.boom_pressure = s.boom_pressure;
  const bool predict = trigger_.NeedsPrediction() || options_.policy == ScoopPolicy::kAutoSelection;
  rt.last_features.reset();
  rt.last_penetration = NAN;
  in.v2 = predict ? ComputeV2(s, rt.v1, rt) : 0.0;
  in.intake_factor = predictor_ != nullptr ? predictor_->IntakeFactor(material_.name) : 1.0;
  rt.last_v2 = predict ? in.v2 : NAN;
  rt.v2_this_decision = rt.last_v2;
  rt.result.intake_factor = in.intake_factor;
  const bool fired = trigger_.Fire(in);
  std::optional<ScoopStrategy> strategy;
  if (options_.policy == ScoopPolicy::kAutoSelection) {
    // Algorithm 3 with this trigger as line 7's condition.
    const ScoopDecision decision =
        fired ? (material_.difficult ? ScoopDecision::kStairway : ScoopDecision::kJustInOut)
              : SelectStrategy({.v1 = rt.v1,
                                .v2 = 0,
                                .target_volume = INFINITY,
                                .difficult = material_.difficult,
                                .stopped = stopped});
    if (decision == ScoopDecision::kJustInOut) strategy = ScoopStrategy::kJustInOut;
    if (decision == ScoopDecision::kStairway) strategy = ScoopStrategy::kStairway;
  } else if (fired || stopped) {
    strategy = options_.policy == ScoopPolicy::kJustInOut  ? ScoopStrategy::kJustInOut
               : options_.policy == ScoopPolicy::kStairway ? ScoopStrategy::kStairway
                                                           : ScoopStrategy::kStairwayFixed;
  }
  if (strategy) {
    ScoopResult& r = rt.result;
    r.trigger_time = s.time;
    r.trigger_after_contact = s.time - r.contact_time;
    r.trigger_reason = fired                      ? trigger_.Name()
                       : !rt.stop_request.empty() ? rt.stop_request
                                                  : "stopped";
    r.strategy = *strategy;
    r.v1_at_trigger = rt.v1;
    r.v2_at_trigger = in.v2;
    r.predicted_tip_path = rt.last_predicted_path;
    r.boom_pressure_at_trigger = s.boom_pressure;
    r.has_features_at_trigger = rt.last_features.has_value();
    if (rt.last_features) r.features_at_trigger = *rt.last_features;
    r.predicted_travel_at_trigger = rt.last_features ? rt.last_penetration : NAN;
    rt.trigger_hinge = s.hinge_xy;
    rt.trigger_heading = s.heading;
    r.travel_after_trigger = 0;
    rt.q_bucket_at_trigger = s.q_bucket;
    rt.q_boom_at_trigger = s.q_boom;
    rt.sequencer.emplace(*strategy, options_.strategy, limits_);
    rt.action.reset();
    EnterPhase(machine, Phase::kScoop, s, rt);
  } else if (elapsed > options_.max_crowd) {
    rt.result.failure = "no trigger within " + std::to_string(options_.max_crowd) + " s";
    rt.phase = Phase::kDone;
  }
  return;
}

// Scoop: the planned trajectory's end, or the atomic actions one after another.
void ScoopCycle::DecideScoop(ScoopMachine& machine, const Proprioception& s, Runtime& rt,
                             double elapsed) {
  rt.result.travel_after_trigger = std::max(
      rt.result.travel_after_trigger,
      (s.hinge_xy - rt.trigger_hinge)
          .dot(Eigen::Vector2d(std::cos(rt.trigger_heading), std::sin(rt.trigger_heading))));
  if (rt.plan) {
    // The plan ends at rest: once its time is over and the joints have had the valves'
    // delay to follow, the scoop is over.
    if (s.time - rt.plan_start >= rt.plan->time.back() + plan_lead_) {
      rt.result.payload_at_actions.push_back(machine.PayloadVolume());
      EndScoopPhase(machine, s, rt);
    } else if (elapsed > options_.max_scoop) {
      ScoopTimedOut(rt);
    }
    return;
  }
  // The running action is over once arrived and paused, or timed out.
  if (rt.action) {
    const bool bucket = rt.action->kind == AtomicKind::kRetractBucket;
    const double error = bucket ? rt.targets.bucket - s.q_bucket : rt.targets.boom - s.q_boom;
    const double tolerance =
        bucket ? options_.bucket_gains.tolerance : options_.boom_gains.tolerance;
    if (std::isnan(rt.arrived_at) && std::abs(error) <= 2 * tolerance) rt.arrived_at = s.time;
    const bool paused = !std::isnan(rt.arrived_at) && s.time - rt.arrived_at >= rt.action->pause;
    if (paused || s.time - rt.action_start > options_.action_timeout) rt.action.reset();
  }
  if (!rt.action) {
    rt.result.payload_at_actions.push_back(machine.PayloadVolume());
    rt.action = rt.sequence_ended ? std::nullopt
                                  : rt.sequencer->Next(rt.targets, rt.v1, rt.result.target_volume);
    if (rt.action) {
      rt.result.action_names.emplace_back(ToString(rt.action->kind));
      rt.targets = TargetsAfter(*rt.action, rt.targets, limits_);
      rt.action_start = s.time;
      rt.arrived_at = NAN;
      rt.drive_eased = false;
      // The final rack-back and lift leave the pile: stop crowding.
      const bool final_part = rt.sequencer->strategy() == ScoopStrategy::kJustInOut ||
                              rt.sequencer->actions() > 2 * rt.sequencer->steps();
      if (final_part) rt.finishing_drive = true;
      // The exit lift holds the bucket's attitude: a Z-bar arm tips the bucket back as the
      // boom rises (q_bucket is relative to the boom), which would pour the heap out over
      // the back wall; a parallel-lift linkage does this mechanically. It holds the racked
      // attitude, but no further back than the carrying one (level_attitude_): a heap is
      // largest with the opening level (bucket_terrain.cc HoldableVolume), racked past it
      // the bucket holds no more, and every further tip-back as it leaves the pile pours.
      if (final_part && rt.action->kind == AtomicKind::kLiftBoom) {
        rt.hold_attitude = std::min(s.q_boom + rt.targets.bucket, level_attitude_);
      }
    } else {
      rt.result.atomic_actions = rt.sequencer->actions();
      rt.result.stairway_steps = rt.sequencer->steps();
      EndScoopPhase(machine, s, rt);
    }
  } else if (elapsed > options_.max_scoop) {
    ScoopTimedOut(rt);
  }
  return;
}

// Level, shake, retreat (§6.2: levelling the bucket's upper edge, vibrating, backing out).
void ScoopCycle::DecideFinishing(ScoopMachine& machine, const Proprioception& s, Runtime& rt,
                                 double elapsed) {
  if (rt.phase == Phase::kLevel) {
    if (std::isnan(rt.arrived_at) && std::abs(rt.hold_attitude - (s.q_boom + s.q_bucket)) <=
                                         2 * options_.bucket_gains.tolerance) {
      rt.arrived_at = s.time;
    }
    const bool held =
        !std::isnan(rt.arrived_at) && s.time - rt.arrived_at >= options_.finishing.level_hold;
    if (held || elapsed > options_.action_timeout) {
      EnterPhase(machine, Phase::kShake, s, rt);
      rt.shake_start = s.time;
    }
    return;
  }
  if (rt.phase == Phase::kShake) {
    // Pulses, then the valve's delay for the last one to reach the spool and die out.
    const double pulses = options_.finishing.shake_pulses * options_.finishing.shake_pulse;
    if (elapsed >= pulses + bucket_delay_) {
      // Carried level (hold_attitude stays): racking back further would tip the heap out.
      EnterPhase(machine, Phase::kRetreat, s, rt);
    }
    return;
  }
  const double behind = (rt.contact_hinge - s.hinge_xy)
                            .dot(Eigen::Vector2d(std::cos(s.heading), std::sin(s.heading)));
  if (!rt.stopping && behind >= options_.retreat_beyond_contact) rt.stopping = true;
  if (rt.stopping && std::abs(s.speed) < 0.05) {
    EnterPhase(machine, Phase::kDone, s, rt);
    rt.result.ok = true;
  } else if (elapsed > options_.max_retreat) {
    rt.result.failure =
        "retreat not complete within " + std::to_string(options_.max_retreat) + " s";
    rt.phase = Phase::kDone;
  }
}

ScoopCycle::~ScoopCycle() = default;

void ScoopCycle::Start(ScoopMachine& machine) {
  rt_ = std::make_unique<Runtime>();
  Runtime& rt = *rt_;
  trigger_.Reset();
  rt.result.target_volume = options_.target_fill * machine_.bucket.rated_capacity;
  rt.boom_pid.emplace(options_.boom_gains,
                      machine_.hydraulics.actuators[boom_valve_].valve.dead_zone);
  rt.bucket_pid.emplace(options_.bucket_gains,
                        machine_.hydraulics.actuators[bucket_valve_].valve.dead_zone);
  rt.speed_pid.emplace(options_.speed_gains);
  rt.boom_filter.emplace(options_.joint_filter_gain);
  rt.bucket_filter.emplace(options_.joint_filter_gain);
  const Proprioception s = machine.Sense();
  rt.speed_pid->Reset(std::isfinite(s.speed) ? s.speed : 0.0);
  rt.targets = options_.attack_pose;
  rt.phase_start_time = s.time;
  rt.result.start_time = s.time;
  rt.phase_start_energy = machine.Energy();
  machine.SetPhase(PhaseName(static_cast<int>(Phase::kApproach)));
  rt.command.valve.assign(machine_.hydraulics.actuators.size(), 0.0);
}

void ScoopCycle::RequestStop(const std::string& reason) {
  if (rt_ == nullptr) return;
  if (rt_->stop_request.empty()) rt_->stop_request = reason;
  rt_->drive_held = true;  // after the trigger: the steps no longer crowd on
}

void ScoopCycle::JointStalledUnderLoad(int joint, const std::string& reason) {
  if (rt_ == nullptr || (joint != 0 && joint != 1)) return;
  rt_->pending_stalls.emplace_back(joint, reason);
}

void ScoopCycle::HoldStalledJoint(const Proprioception& s, Runtime& rt, int joint,
                                  const std::string& reason) const {
  rt.result.stalls.push_back(std::string(PhaseName(static_cast<int>(rt.phase))) + ": " + reason);
  if (joint == 0) {
    rt.targets.boom = s.q_boom;
    rt.drive_held = true;  // the drive pressing into the pile adds to what the boom must lift
    if (rt.phase == Phase::kScoop) {
      rt.action.reset();
      rt.sequence_ended = true;
    }
    if ((rt.phase == Phase::kApproach || rt.phase == Phase::kCrowd) && rt.stop_request.empty()) {
      rt.stop_request = "boom_stall";
    }
    return;
  }
  // The bucket: held at the attitude it has when an attitude is being held, else where it is.
  if (std::isfinite(rt.hold_attitude)) rt.hold_attitude = s.q_boom + s.q_bucket;
  rt.targets.bucket = s.q_bucket;
  if (rt.phase == Phase::kScoop) rt.action.reset();
}

bool ScoopCycle::done() const { return rt_ == nullptr || rt_->phase == Phase::kDone; }

const char* ScoopCycle::phase_name() const {
  return rt_ == nullptr ? "idle" : PhaseName(static_cast<int>(rt_->phase));
}

double ScoopCycle::SpeedTarget(const Proprioception& s, Runtime& rt) {
  double speed_target = options_.attack_speed;
  if (rt.drive_held && !rt.drive_hold_started) {
    // Brake from the speed the machine has, not from the profile's reference: stalled in the
    // pile, the reference stays at the attack speed with the PI's integral wound up, and
    // ramping that down keeps pushing for seconds (over a metre once the stairway's lifts free
    // the bucket) past where the look-ahead, reckoning v / f + v² / 2 a_dec, asked for the stop.
    rt.speed_pid->Reset(std::max(s.speed, 0.0));
    rt.drive_hold_started = true;
  }
  switch (rt.phase) {
    case Phase::kApproach:
    case Phase::kCrowd:
      break;
    case Phase::kScoop:
      if (rt.plan) {
        // The plan: the speed now, the joints where the plan has them one valve dead time
        // ahead (what is commanded now reaches the spools then).
        const double t = s.time - rt.plan_start;
        speed_target = std::max(PlanAt(rt.plan->time, rt.plan->speed, t), 0.0);
        rt.targets.boom = PlanAt(rt.plan->time, rt.plan->q_boom, t + plan_lead_);
        rt.targets.bucket = PlanAt(rt.plan->time, rt.plan->q_bucket, t + plan_lead_);
        break;
      }
      // Crowd through the hydraulic delay (Fig. 21 (a)–(b)), then decelerate at the fixed
      // rate once the final rack/lift runs and the arm moves.
      if (rt.finishing_drive && rt.arm_moving) {
        if (std::isnan(rt.slowing_since)) rt.slowing_since = s.time;
        speed_target = std::max(
            options_.attack_speed - options_.scoop_deceleration * (s.time - rt.slowing_since), 0.0);
      }
      if (BoomPinnedByTheDrive(s, rt)) speed_target = 0;
      if (rt.drive_held) speed_target = 0;
      break;
    case Phase::kLevel:
    case Phase::kShake:
      speed_target = 0;
      break;
    case Phase::kRetreat:
      speed_target = rt.stopping ? 0.0 : -options_.retreat_speed;
      break;
    case Phase::kDone:
      speed_target = 0;
      break;
  }
  return speed_target;
}

bool ScoopCycle::Tick(ScoopMachine& machine) {
  if (rt_ == nullptr) throw std::logic_error("ScoopCycle::Tick before Start");
  Runtime& rt = *rt_;
  if (rt.phase == Phase::kDone) return false;
  Proprioception s = machine.Sense();
  if (!Finite(s)) {
    rt.result.failure = "machine reports a non-finite state at t = " + std::to_string(s.time);
    rt.phase = Phase::kDone;
    return false;
  }
  // Everything below (PIDs, the tip path of Eq. (19), V2's start) sees the filtered angles.
  s.q_boom = rt.boom_filter->Update(s.q_boom, s.qd_boom, options_.tick);
  s.q_bucket = rt.bucket_filter->Update(s.q_bucket, s.qd_bucket, options_.tick);
  for (const auto& [joint, reason] : rt.pending_stalls) HoldStalledJoint(s, rt, joint, reason);
  rt.pending_stalls.clear();
  if (rt.phase == Phase::kScoop && std::isfinite(rt.hold_attitude)) {
    // Counted from when the bucket first reaches the held attitude: a rack-back that ended on
    // the cylinder's end stop starts the lift beyond it, which is not the lift's doing.
    const double error = std::abs(s.q_boom + s.q_bucket - rt.hold_attitude);
    if (error <= 2 * options_.bucket_gains.tolerance) rt.exit_hold_reached = true;
    rt.exit_error_overall = std::max(rt.exit_error_overall, error);
    if (rt.exit_hold_reached) rt.exit_error_held = std::max(rt.exit_error_held, error);
    rt.result.exit_lift_attitude_error =
        rt.exit_hold_reached ? rt.exit_error_held : rt.exit_error_overall;
  }
  const bool digging =
      rt.phase == Phase::kApproach || rt.phase == Phase::kCrowd || rt.phase == Phase::kScoop;
  if (digging) {
    const Eigen::Vector2d p = prediction::TipInBase(machine_, s.q_boom, s.q_bucket);
    const Eigen::Vector3d tip(s.hinge_xy.x() + std::cos(s.heading) * p.x(),
                              s.hinge_xy.y() + std::sin(s.heading) * p.x(), p.y());
    if (rt.tip_path.empty() || (tip - rt.tip_path.back()).norm() >= options_.path_spacing) {
      rt.tip_path.push_back(tip);
    }
  }
  if (rt.tick++ % options_.decision_every == 0) {
    rt.v2_this_decision = NAN;
    Decide(machine, s, rt);
    if (digging && !rt.tip_path.empty()) {
      rt.result.samples.push_back({.time = s.time,
                                   .v1 = rt.v1,
                                   .v1_plus_v2 = rt.result.intake_factor * (rt.v1 + rt.last_v2),
                                   .triggered = !std::isnan(rt.result.trigger_time),
                                   .tip = rt.tip_path.back(),
                                   .state = {.hinge_xy = s.hinge_xy,
                                             .heading = s.heading,
                                             .speed = s.speed,
                                             .q_boom = s.q_boom,
                                             .q_bucket = s.q_bucket},
                                   .path_points = rt.tip_path.size(),
                                   .v2 = rt.v2_this_decision});
    }
  }
  if (rt.phase == Phase::kDone) return false;

  // Low-level control, every tick.
  if (rt.phase == Phase::kScoop && !rt.arm_moving &&
      (s.q_bucket > rt.q_bucket_at_trigger + options_.arm_motion ||
       s.q_boom > rt.q_boom_at_trigger + options_.arm_motion)) {
    rt.arm_moving = true;
    rt.result.arm_motion_after_trigger = s.time - rt.result.trigger_time;
  }
  const double speed_target = SpeedTarget(s, rt);
  core::ActuatorCommand& command = rt.command;
  rt.speed_pid->SetTarget(speed_target);
  const DriveCommand drive = rt.speed_pid->Update(s.speed, options_.tick);
  command.drive = drive.drive;
  command.brake = drive.brake;
  command.articulation_rate = 0;
  command.valve[boom_valve_] =
      rt.boom_pid->Update(rt.targets.boom, s.q_boom, s.qd_boom, options_.tick);
  double bucket_feed_forward = 0;
  double bucket_now = s.q_bucket;  // what the bucket PID compares with its target
  if (std::isfinite(rt.hold_attitude)) {
    if (attitude_feed_forward_) {
      HoldAttitudeAhead(s, rt, bucket_now, bucket_feed_forward);
    } else {
      rt.targets.bucket = BucketTargetForAttitude(rt.hold_attitude, s.q_boom);
    }
  } else {
    rt.boom_response = rt.bucket_response = 1;
  }
  if (rt.phase == Phase::kShake) {
    const double t = s.time - rt.shake_start;
    const int pulse = static_cast<int>(std::floor(t / options_.finishing.shake_pulse));
    command.valve[bucket_valve_] = pulse < options_.finishing.shake_pulses
                                       ? (pulse % 2 == 0 ? 1 : -1) * options_.finishing.shake_duty
                                       : 0.0;
  } else {
    command.valve[bucket_valve_] = rt.bucket_pid->Update(rt.targets.bucket, bucket_now, s.qd_bucket,
                                                         options_.tick, bucket_feed_forward);
  }
  if (attitude_feed_forward_) {
    // The openings in flight: sent within each valve's delay, not yet moving the joint.
    const AttitudeHoldFeedForward& hold = *attitude_feed_forward_;
    RememberOpening(rt.boom_openings, hold.OpeningOfDuty(0, command.valve[boom_valve_]),
                    boom_delay_ticks_);
    RememberOpening(rt.bucket_openings, hold.OpeningOfDuty(1, command.valve[bucket_valve_]),
                    bucket_delay_ticks_);
  }
  // NaN never reaches the machine: a non-finite field is replaced by a safe value and counted.
  bool blocked = false;
  for (double& u : command.valve) {
    if (!std::isfinite(u)) u = 0, blocked = true;
  }
  if (!std::isfinite(command.drive) || !std::isfinite(command.brake)) {
    command.drive = 0, command.brake = 1, blocked = true;
  }
  if (blocked) ++rt.result.non_finite_blocked;
  std::string why;
  if (!machine.Command(command, &why)) ++rt.result.refused_commands;
  return true;
}

ScoopResult ScoopCycle::Finish(ScoopMachine& machine) {
  if (rt_ == nullptr) throw std::logic_error("ScoopCycle::Finish before Start");
  ScoopResult result = std::move(rt_->result);
  result.tip_path = std::move(rt_->tip_path);
  result.end_time = machine.Sense().time;
  result.payload = machine.PayloadVolume();
  result.fill_rate = result.payload / machine_.bucket.rated_capacity;
  rt_.reset();
  return result;
}

ScoopResult ScoopCycle::Run(ScoopMachine& machine) {
  Start(machine);
  while (Tick(machine)) machine.Advance(options_.tick);
  return Finish(machine);
}

}  // namespace autoshovel::control
