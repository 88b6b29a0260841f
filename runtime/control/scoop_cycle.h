// One scoop of a wheel loader, wheel-loader seed §6 (Fig. 9, Algorithm 3, §6.2), as a state
// machine stepped on the machine's clock: low-level control (joint PIDs, speed PID) every tick
// (100 Hz), decisions (stop detector, V1, V2, trigger, strategy, atomic actions) every
// `decision_every` ticks (20 Hz), §7 "Shoveling action execution and strategy selection are
// implemented via a state machine with an output frequency of 20 Hz".
//
// Phases (each booked to its own energy counter and timed):
//   approach — bucket held at the attack pose, speed PID at the attack speed, until the bucket
//              touches the pile, read as V1 > contact_volume (Algorithm 3 line 3: "while V1 > 0");
//   crowd    — the same commands; every decision computes V1 (Eq. 19 over the tip path on the
//              pre-contact map), V2 when the trigger reads it (penetration SVR → V21 + V22), the
//              stop detector; ends when the trigger fires or the machine stops (line 13);
//   scoop    — the strategy's atomic actions (Algorithm 3 picks it under kAutoSelection). The
//              drive keeps crowding through the hydraulic delay until the bucket moves (Fig. 21
//              (a)–(b)); then "fixed acceleration control" (speed target 0 at the profile's
//              deceleration) for "Just in & out" and the final rack/lift of "Stairway", whose
//              steps crowd on (that is how they cut through the pile);
//   level, shake — FinishingParameters (scooping_strategies.h), machine braked;
//   retreat  — bucket racked, reversing until the hinge is `retreat_beyond_contact` behind where
//              it was at contact, then stopping.
// The machine is seen through ScoopMachine only (proprioception, commands, the clock, energy and
// payload meters): the simulated plant and a real machine both implement it (DESIGN.md: control
// never includes plant/).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "generated/machine_functions.h"
#include "runtime/control/arm_feed_forward.h"
#include "runtime/control/atomic_actions.h"
#include "runtime/control/joint_pid.h"
#include "runtime/control/scoop_triggers.h"
#include "runtime/control/scooping_strategies.h"
#include "runtime/control/speed_pid.h"
#include "runtime/control/stop_detector.h"
#include "runtime/control/strategy_selection.h"
#include "runtime/core/actuator_command.h"
#include "runtime/model/description.h"
#include "runtime/prediction/penetration_predictor.h"
#include "runtime/prediction/scoop_volume_prediction.h"
#include "runtime/prediction/volume_estimation.h"

namespace autoshovel::control {

/// What the machine's own sensors report at one instant.
struct Proprioception {
  double time = 0;                                     ///< machine clock [s]
  Eigen::Vector2d hinge_xy = Eigen::Vector2d::Zero();  ///< localisation, world [m]
  double heading = 0;                                  ///< front frame [rad]
  double articulation = 0;                             ///< γ, steering encoder [rad]
  double speed = 0;                                    ///< forward [m/s]
  double q_boom = 0, q_bucket = 0;                     ///< joints (IMUs, Eq. 1) [rad]
  double qd_boom = 0, qd_bucket = 0;                   ///< [rad/s]
  double boom_pressure = 0;                            ///< boom cylinder cap side [Pa]
  /// The other chambers [Pa]: what a positive valve opening feeds is the cap side, a negative
  /// one the rod side. NaN where the machine has no transducer (the safety supervisor then
  /// cannot tell a stall under load from a stuck valve: app/safety_supervisor.h).
  double boom_pressure_rod = NAN;
  double bucket_pressure_cap = NAN, bucket_pressure_rod = NAN;
  /// The pump's output pressure [Pa]; NaN where not sensed. With a load-sensing pump it rises to
  /// its limit only while an open valve feeds a chamber at that limit, which is how a stall
  /// under load is told from a trapped chamber pressed up by an outside load.
  double pump_pressure = NAN;
};

/// What a planner is given at contact: the machine, the pile ahead and the volume wanted.
struct ScoopPlanRequest {
  double speed = 0;                 ///< [m/s]
  double q_boom = 0, q_bucket = 0;  ///< [rad]
  double payload_volume = 0;        ///< already in the bucket [m³]
  double target_volume = 0;         ///< V_t [m³]
  /// The pre-contact map's heights along the heading from the hinge, every `profile_spacing`
  /// metres from the hinge, above the floor (unknown cells read as floor) [m].
  double profile_spacing = 0.05;
  std::vector<double> profile_heights;
};

/// A planned scoop: references over the time since contact, ending at rest.
struct PlannedScoop {
  std::vector<double> time;              ///< since contact, increasing [s]
  std::vector<double> speed;             ///< [m/s]
  std::vector<double> q_boom, q_bucket;  ///< [rad]
  double energy = 0;                     ///< what the plan expects to draw [J]
  double volume = 0;                     ///< and to take [m³]
  double solve_seconds = 0;              ///< planning time [s]
};

/// Plans a scoop at contact; nullopt (and `why`) when it cannot.
using ScoopPlanner =
    std::function<std::optional<PlannedScoop>(const ScoopPlanRequest& request, std::string* why)>;

/// The machine as the scoop cycle sees it.
class ScoopMachine {
 public:
  virtual ~ScoopMachine() = default;
  virtual Proprioception Sense() const = 0;
  /// Sends a command; false (and `why`) when the machine refuses it.
  virtual bool Command(const core::ActuatorCommand& command, std::string* why) = 0;
  /// Lets one control tick of `dt` [s] pass (the simulated clock, or a real-time wait).
  virtual void Advance(double dt) = 0;
  /// Names the phase the following energy is booked to.
  virtual void SetPhase(const std::string& phase) = 0;
  /// Energy drawn so far [J] (travel + hydraulic).
  virtual double Energy() const = 0;
  /// Volume in the bucket [m³] (a weighing system; the plant's payload in simulation).
  virtual double PayloadVolume() const = 0;
};

enum class ScoopPolicy {
  kAutoSelection,  ///< Algorithm 3
  kJustInOut,
  kStairway,       ///< adaptive (volume feedback between actions)
  kStairwayFixed,  ///< "Stairway #N", N = StrategyParameters::fixed_steps
  /// A trajectory planned at contact by a ScoopPlanner (the optimal-control scoop of
  /// runtime/optimal in app/), tracked by the speed and joint PIDs; no trigger.
  kOptimal,
};
const char* ToString(ScoopPolicy policy);

struct ScoopCycleOptions {
  double tick = 0.01;         ///< low-level control period [s] (100 Hz)
  int decision_every = 5;     ///< ticks per state-machine decision (20 Hz)
  double attack_speed = 1.0;  ///< approach and crowding speed [m/s]
  /// Seed §6.2, "fixed acceleration control upon scooping initiation": once the final curl
  /// moves the arm, the speed reference falls from the attack speed at this rate and the drive
  /// follows it. 1 m/s² (the speed profile's a_dec) stops the machine within about its
  /// hydraulic-delay travel: the braking scoop, the regime models/prediction/penetration_svr is
  /// trained in, and this struct's default. Gentler rates crowd while curling (the main job
  /// attacks at 1.5 m/s and falls at 0.6 m/s²: app::ShovelRunOptions); docs/scooping_control.md
  /// gives what they do to fill and why the Eq. (19) volume model then mispredicts the intake.
  double scoop_deceleration = 1.0;      ///< [m/s²]
  double retreat_speed = 1.0;           ///< reversing speed [m/s]
  double retreat_beyond_contact = 1.0;  ///< [m]
  double target_fill = 1.0;             ///< V_t as a fraction of the rated capacity [-]
  double contact_volume = 0.005;        ///< V1 above which the bucket is in the pile [m³]
  double rack_back_margin = 0.1;        ///< racked target below the bucket joint limit [rad]
  double boom_margin = 0.05;            ///< highest boom target below its limit [rad]
  /// While the bucket holds an attitude (exit lift, levelling, carrying), also open the tilt
  /// valve as the boom valve's demand will move the boom (arm_feed_forward.h); false leaves the
  /// attitude to the bucket PID alone, which lags the boom by the valves' delay.
  bool attitude_feed_forward = true;
  double arm_motion = 0.02;     ///< joint travel that shows the scoop has begun moving [rad]
  double action_timeout = 4.0;  ///< an atomic action that has not arrived by then is over [s]
  /// Feathering the drive: while scooping, a boom opened at least `boom_stall_opening` to lift
  /// that rises slower than `boom_stall_rate` for `boom_stall_time` (after the valve's delay)
  /// is pinned by the drive pressing the bucket into the pile (a Stairway step deep in sand).
  /// The drive then eases to a stop until the next atomic action, as an operator lifts off
  /// the throttle to let the boom rise. 1 s, half the supervisor's stuck-valve time: a
  /// shorter stall frees itself (at 0.5 s the adaptive Stairway eased where it did not need to
  /// and spent 45 % more energy lifting through the heap). A boom that stalls for another
  /// reason (a stuck valve) stays stalled, and the supervisor still sees it. 0 s: never.
  double boom_stall_time = 1.0;     ///< [s]
  double boom_stall_rate = 0.005;   ///< [rad/s]
  double boom_stall_opening = 0.5;  ///< [-]
  double path_spacing = 0.01;       ///< tip path points at least this far apart [m]
  /// Gain k of the boom and bucket angle complementary filter (joint_angle_filter.h) every
  /// tick; 1 uses the readings as they come.
  double joint_filter_gain = 0.1;
  ArmTargets attack_pose;  ///< bucket on the floor (plant/poses.h BucketOnFloor in tests)
  ScoopPolicy policy = ScoopPolicy::kAutoSelection;
  StrategyParameters strategy;
  FinishingParameters finishing;
  JointPidGains boom_gains;
  JointPidGains bucket_gains;
  SpeedPidGains speed_gains;
  /// Phase time limits [s]: a phase running longer ends the cycle as failed.
  double max_approach = 30, max_crowd = 12, max_scoop = 20, max_retreat = 20;

  std::string Invalid() const;
};

struct PhaseRecord {
  std::string name;
  double start = 0;     ///< [s]
  double duration = 0;  ///< [s]
  double energy = 0;    ///< [J]
};

/// One state-machine decision of the digging phases (approach, crowd, scoop): the report's
/// volume-against-time figure.
struct ScoopSample {
  double time = 0;  ///< machine clock [s]
  double v1 = 0;    ///< Eq. (19) [m³]
  /// κ_M·(V1 + V2), the predicted volume the trigger compares with V_t, when V2 was computed
  /// at this decision [m³] (κ_M = 1 for a model without an intake factor).
  double v1_plus_v2 = NAN;
  bool triggered = false;                         ///< the scoop has been triggered
  Eigen::Vector3d tip = Eigen::Vector3d::Zero();  ///< bucket tip, world [m]
  /// The state the decision saw (a recording keeps it: `autoshovel replay` predicts V2 again
  /// from it): localisation, speed and the filtered joint angles.
  prediction::DecisionState state;
  std::size_t path_points = 0;  ///< ScoopResult::tip_path's points at this decision
  double v2 = NAN;              ///< V2 computed at this decision [m³] (NaN: none was)
};

struct ScoopResult {
  bool ok = false;
  std::string failure;
  std::vector<PhaseRecord> phases;        ///< in order
  double contact_time = NAN;              ///< first decision with V1 > contact_volume [s]
  double trigger_time = NAN;              ///< [s]
  double trigger_after_contact = NAN;     ///< [s]
  double arm_motion_after_trigger = NAN;  ///< command-to-motion delay seen [s]
  std::string trigger_reason;             ///< the trigger's name, or "stopped"
  ScoopStrategy strategy = ScoopStrategy::kJustInOut;
  double v1_at_trigger = 0, v2_at_trigger = 0;  ///< [m³]
  double intake_factor = 1;    ///< κ_M the predicted-volume trigger scaled V1 + V2 by [-]
  double target_volume = 0;    ///< V_t [m³]
  double feedback_volume = 0;  ///< V1 at the end of the scoop phase [m³]
  int atomic_actions = 0;
  std::vector<std::string> action_names;  ///< the atomic actions in order (atomic_actions.h)
  /// Bucket volume (ScoopMachine::PayloadVolume) each time the sequencer was asked for the next
  /// atomic action: before the first, then as each one ended (actions + 1 entries) [m³]. Shows
  /// which action took material in and which let it go.
  std::vector<double> payload_at_actions;
  int stairway_steps = 0;
  /// The drive eased at least once because the boom stalled lifting
  /// (ScoopCycleOptions::boom_stall_time).
  bool drive_eased_for_boom = false;
  /// Stalls under load the cycle was told of (JointStalledUnderLoad), each with the phase it
  /// came in: "scoop: boom stalls under load at relief (…)".
  std::vector<std::string> stalls;
  double boom_pressure_at_contact = 0;  ///< [Pa]
  double boom_pressure_at_trigger = 0;  ///< [Pa]
  double payload_after_scoop = 0;       ///< before levelling and shaking [m³]
  /// Largest |q_boom + q_bucket − held attitude| while the final lift raises the racked bucket
  /// out of the pile [rad], from when the bucket first reaches that attitude (over the whole
  /// lift if it never does): tipped back or forward this far, a heaped load pours out.
  double exit_lift_attitude_error = 0;
  double payload = 0;           ///< at the end [m³]
  double fill_rate = 0;         ///< payload / rated capacity [-]
  long non_finite_blocked = 0;  ///< commands with a NaN stopped before the machine (must be 0)
  long refused_commands = 0;    ///< commands the machine refused
  long prediction_failures = 0;
  double start_time = 0;                            ///< [s]
  double end_time = 0;                              ///< [s]
  std::vector<ScoopSample> samples;                 ///< every decision while digging
  std::vector<Eigen::Vector3d> tip_path;            ///< actual tip, approach to scoop end, world
  std::vector<Eigen::Vector3d> predicted_tip_path;  ///< V2's predicted path at the trigger
  /// The penetration predictor's inputs at the trigger (when V2 was computed there) and the
  /// machine's forward travel from the trigger to the end of the scoop phase, along its heading
  /// at the trigger: the (features, target) pair the predictor is trained on, logged by
  /// campaigns for retraining at a new site (seed §7.6).
  bool has_features_at_trigger = false;
  prediction::PenetrationFeatures features_at_trigger;
  double travel_after_trigger = NAN;  ///< [m]
  /// The predictor's travel for the features at the trigger [m]: NaN unless
  /// has_features_at_trigger and the prediction succeeded. Against travel_after_trigger it shows
  /// how the predictor does in the closed loop (issue 41, item 5).
  double predicted_travel_at_trigger = NAN;
  /// ScoopPolicy::kOptimal: what the plan expected (energy [J], volume [m³]) and its solve
  /// time [s]; NaN otherwise.
  double planned_energy = NAN, planned_volume = NAN, plan_solve_seconds = NAN;

  const PhaseRecord* Phase(const std::string& name) const;
  /// Contact to the end of the scoop phase (the seed's Table 6/7 "time"): crowd + scoop.
  double ContactToScoopEndTime() const;
  double ContactToScoopEndEnergy() const;  ///< [J]
};

class ScoopCycle {
 public:
  /// `map`: heights before the bucket came (the elevation map), `material`: the pile's material
  /// (from the semantic map), `trigger`: when to scoop, `predictor`: needed when the trigger
  /// reads V2 (may be null otherwise). All referenced objects must outlive the cycle. Throws
  /// std::invalid_argument for invalid options, an arm that is not a two-link loader arm, or a
  /// trigger that needs a missing predictor.
  ScoopCycle(const model::MachineDescription& machine, const generated::MachineFunctions& functions,
             const prediction::HeightGrid& map, const model::Material& material,
             ScoopTrigger& trigger, const prediction::PenetrationPredictor* predictor,
             const ScoopCycleOptions& options);

  ~ScoopCycle();

  /// Runs the whole cycle on `machine`; returns when retreated, or failed.
  ScoopResult Run(ScoopMachine& machine);

  // The same, one control tick at a time, for an executive that runs other tasks between ticks
  // (app/): Start(); while (Tick()) { the executive advances the machine by options.tick };
  // Finish(). Tick() decides every `decision_every` ticks and commands the machine; it returns
  // false once the cycle is over (nothing commanded).
  void Start(ScoopMachine& machine);
  bool Tick(ScoopMachine& machine);
  ScoopResult Finish(ScoopMachine& machine);
  bool done() const;
  /// Ends crowding: before the trigger at the next decision, as if the machine had stopped
  /// (Algorithm 3's v ≈ 0 branch: Stairway) with `reason` as the trigger reason; after it, the
  /// Stairway steps stop crowding on. The drive is held from then on. What the executive calls
  /// when an obstacle comes too close ahead; before contact it ends the cycle as failed.
  void RequestStop(const std::string& reason);
  /// `joint` (0: boom, 1: bucket) stalls under load: its valve open, the chamber it feeds at the
  /// most the supply holds, and it does not move (app/safety_supervisor.h tells this from a
  /// stuck valve). Forcing on cannot lift the load and only blows oil over the relief valve, so
  /// from the next tick the joint is held where it stalled (its target set to where it is) and
  /// the drive stops pushing. In the scoop phase the running atomic action is over; a stalled
  /// boom also ends the action sequence (the steps left would lift the same load): the cycle
  /// goes on to level, shake and retreat, keeping what the bucket holds, and backing out frees
  /// the bucket from the pile. While crowding, a stalled boom ends crowding as RequestStop does
  /// (reason "boom_stall"). Recorded in ScoopResult::stalls.
  void JointStalledUnderLoad(int joint, const std::string& reason);
  const char* phase_name() const;
  double tick() const { return options_.tick; }
  /// The planner ScoopPolicy::kOptimal asks at contact (required for that policy).
  void SetPlanner(ScoopPlanner planner) { planner_ = std::move(planner); }

 private:
  enum class Phase { kApproach, kCrowd, kScoop, kLevel, kShake, kRetreat, kDone };
  struct Runtime;
  void Decide(ScoopMachine& machine, const Proprioception& s, Runtime& rt);
  // Decide's phases; `elapsed`: time in the phase [s].
  void DecideApproach(ScoopMachine& machine, const Proprioception& s, Runtime& rt, double elapsed);
  void DecideCrowd(ScoopMachine& machine, const Proprioception& s, Runtime& rt, double elapsed,
                   bool stopped);
  void DecideScoop(ScoopMachine& machine, const Proprioception& s, Runtime& rt, double elapsed);
  void DecideFinishing(ScoopMachine& machine, const Proprioception& s, Runtime& rt, double elapsed);
  double ComputeV2(const Proprioception& s, double v1, Runtime& rt);
  /// The scoop phase is over (its actions or its plan): record what the bucket holds, level.
  void EndScoopPhase(ScoopMachine& machine, const Proprioception& s, Runtime& rt);
  /// The scoop phase ran past ScoopCycleOptions::max_scoop: the cycle fails.
  void ScoopTimedOut(Runtime& rt) const;
  /// ScoopPolicy::kOptimal at contact: asks the planner and starts tracking its plan.
  void StartPlan(ScoopMachine& machine, const Proprioception& s, Runtime& rt);
  void EnterPhase(ScoopMachine& machine, Phase phase, const Proprioception& s, Runtime& rt);
  /// The bucket joint target that gives `attitude` (q_boom + q_bucket) at this boom angle,
  /// within the bucket's range.
  double BucketTargetForAttitude(double attitude, double q_boom) const;
  /// While holding an attitude with the feed-forward on: sets the bucket target, the bucket
  /// angle the PID compares it with (Smith predictor) and the tilt feed-forward opening.
  void HoldAttitudeAhead(const Proprioception& s, Runtime& rt, double& bucket_now,
                         double& feed_forward) const;
  /// Scoop phase, every tick: whether the drive is to ease because the boom, opened to lift,
  /// has stalled for ScoopCycleOptions::boom_stall_time (latched until the next action).
  bool BoomPinnedByTheDrive(const Proprioception& s, Runtime& rt) const;
  /// The drive's speed reference this tick, by phase (the scoop's plan, Fig. 21's crowd and
  /// deceleration, a held or pinned drive, the retreat); resets the speed PID where a hold
  /// begins.
  double SpeedTarget(const Proprioception& s, Runtime& rt);
  /// Acts on one JointStalledUnderLoad report (see there).
  void HoldStalledJoint(const Proprioception& s, Runtime& rt, int joint,
                        const std::string& reason) const;

  const model::MachineDescription& machine_;
  const generated::MachineFunctions& functions_;
  const prediction::HeightGrid& map_;
  const model::Material& material_;
  ScoopTrigger& trigger_;
  const prediction::PenetrationPredictor* predictor_;
  ScoopCycleOptions options_;
  ArmLimits limits_;
  int boom_valve_ = -1, bucket_valve_ = -1;
  double bucket_delay_ = 0;  ///< transport delay + spool time constant of the bucket valve [s]
  std::optional<AttitudeHoldFeedForward> attitude_feed_forward_;  ///< when the option is on
  std::size_t boom_delay_ticks_ = 0, bucket_delay_ticks_ = 0;     ///< valve delays in ticks
  double level_attitude_ = 0;  ///< bucket attitude with the opening level, plus carry tilt [rad]
  std::unique_ptr<Runtime> rt_;
  ScoopPlanner planner_;
  double plan_lead_ = 0;  ///< valve dead time the joint references are sent ahead by [s]
};

}  // namespace autoshovel::control
