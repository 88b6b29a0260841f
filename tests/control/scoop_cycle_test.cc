// One closed-loop scoop on the simulated plant per material (wheel-loader seed §6.2, §7.4.2).
#include "runtime/control/scoop_cycle.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

#include "tests/control/control_test_support.h"

namespace autoshovel::control {
namespace {

constexpr const char* kMachine = "xcmg_968ev";

const prediction::PenetrationPredictor& Predictor() {
  // The exploration may try another model (docs/scooping_control.md); the tests use the shipped.
  const char* stem = std::getenv("AUTOSHOVEL_SCOOP_MODEL");
  static const prediction::PenetrationPredictor predictor = prediction::PenetrationPredictor::Load(
      stem != nullptr ? std::string(stem)
                      : std::string(AUTOSHOVEL_SOURCE_DIR) + "/models/prediction/penetration_svr");
  return predictor;
}

// The pushing scoop's model (identification/predictor/README.md), for the exit-lift test.
const prediction::PenetrationPredictor& PushingPredictor() {
  static const prediction::PenetrationPredictor predictor = prediction::PenetrationPredictor::Load(
      std::string(AUTOSHOVEL_SOURCE_DIR) + "/models/prediction/penetration_svr_push");
  return predictor;
}

enum class TriggerKind { kPredicted, kPerception, kPressure };

// What a test changes from the default cycle.
struct Variant {
  double scoop_deceleration = NAN;  ///< NaN: the default (or AUTOSHOVEL_SCOOP_DECEL)
  const prediction::PenetrationPredictor* predictor = nullptr;  ///< null: Predictor()
  bool attitude_feed_forward = true;
};

struct Outcome {
  ScoopResult result;
  bool commands_finite = true;
  long plant_refused = 0;
  std::map<std::string, plant::Energy> plant_energy;
};

Outcome RunScoop(const std::string& material, TriggerKind kind, ScoopPolicy policy,
                 double pressure_threshold = 0, const Variant& variant = {}) {
  testing::ConeYard yard(kMachine, material, 3.0, 4.0);
  const prediction::HeightGrid map = testing::ToHeightGrid(yard.world.terrain);
  plant::Plant loader(yard.machine, plant::testing::Functions(kMachine), yard.world, yard.start);
  testing::PlantMachine machine(loader);
  ScoopCycleOptions options;
  options.attack_pose = yard.attack_pose;
  options.policy = policy;
  // The exploration's knobs (docs/scooping_control.md): the scoop's fixed deceleration and the
  // perception-only trigger's target.
  if (const char* decel = std::getenv("AUTOSHOVEL_SCOOP_DECEL")) {
    options.scoop_deceleration = std::atof(decel);
  }
  if (std::isfinite(variant.scoop_deceleration)) {
    options.scoop_deceleration = variant.scoop_deceleration;
  }
  options.attitude_feed_forward = variant.attitude_feed_forward;
  const double target = options.target_fill * yard.machine.bucket.rated_capacity;
  std::unique_ptr<ScoopTrigger> trigger;
  if (kind == TriggerKind::kPredicted) trigger = std::make_unique<PredictedVolumeTrigger>(target);
  if (kind == TriggerKind::kPerception) {
    const char* v1_target = std::getenv("AUTOSHOVEL_SCOOP_V1_TARGET");
    trigger = std::make_unique<PerceptionTrigger>(v1_target ? std::atof(v1_target) : target);
  }
  if (kind == TriggerKind::kPressure) {
    trigger = std::make_unique<BoomPressureTrigger>(pressure_threshold);
  }
  ScoopCycle cycle(yard.machine, plant::testing::Functions(kMachine), map, *yard.material, *trigger,
                   variant.predictor != nullptr ? variant.predictor : &Predictor(), options);
  Outcome out;
  out.result = cycle.Run(machine);
  out.commands_finite = machine.all_commands_finite();
  out.plant_refused = loader.counters().refused_commands;
  out.plant_energy = loader.phase_energy();
  const ScoopResult& r = out.result;
  std::printf(
      "[scoop] %s trigger=%s policy=%s ok=%d %s reason=%s strategy=%s steps=%d actions=%d "
      "fill=%.3f payload=%.3f V1@trig=%.3f V2@trig=%.3f trig_after_contact=%.2f "
      "motion_delay=%.2f contact->scoop_end %.2f s %.1f kJ\n",
      material.c_str(), trigger->Name().c_str(), ToString(policy), r.ok, r.failure.c_str(),
      r.trigger_reason.c_str(), ToString(r.strategy), r.stairway_steps, r.atomic_actions,
      r.fill_rate, r.payload, r.v1_at_trigger, r.v2_at_trigger, r.trigger_after_contact,
      r.arm_motion_after_trigger, r.ContactToScoopEndTime(), r.ContactToScoopEndEnergy() / 1e3);
  std::printf(
      "[scoop]   payload after scoop %.3f, boom p contact %.1f bar trigger %.1f bar, travel after "
      "trigger %.2f m, crowd %.1f kJ, Eq19 true path at scoop end %.3f, exit-lift attitude "
      "error %.3f rad\n",
      r.payload_after_scoop, r.boom_pressure_at_contact / 1e5, r.boom_pressure_at_trigger / 1e5,
      r.travel_after_trigger, r.Phase("crowd") ? r.Phase("crowd")->energy / 1e3 : NAN,
      r.feedback_volume, r.exit_lift_attitude_error);
  for (const PhaseRecord& p : r.phases) {
    const plant::Energy& e = out.plant_energy[p.name];
    std::printf("[scoop]   %-8s %6.2f s %7.1f kJ (plant: travel %.1f hydraulic %.1f kJ)\n",
                p.name.c_str(), p.duration, p.energy / 1e3, e.travel / 1e3, e.hydraulic / 1e3);
  }
  return out;
}

// What every closed-loop scoop must show, whatever the strategy.
void ExpectSound(const Outcome& out) {
  const ScoopResult& r = out.result;
  ASSERT_TRUE(r.ok) << r.failure;
  EXPECT_TRUE(out.commands_finite);
  EXPECT_EQ(r.non_finite_blocked, 0);
  EXPECT_EQ(r.refused_commands, 0);
  EXPECT_EQ(out.plant_refused, 0);
  EXPECT_EQ(r.prediction_failures, 0);
  const char* kPhases[] = {"approach", "crowd", "scoop", "level", "shake", "retreat"};
  ASSERT_EQ(r.phases.size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) {
    const PhaseRecord& p = r.phases[i];
    EXPECT_EQ(p.name, kPhases[i]);
    EXPECT_GT(p.duration, 0) << p.name;
    EXPECT_GT(p.energy, 0) << p.name;
    // The cycle's booking agrees with the plant's per-phase counters.
    EXPECT_NEAR(p.energy, out.plant_energy.at(p.name).total(), 1e-6 * p.energy + 1e-3) << p.name;
  }
  EXPECT_GT(r.trigger_after_contact, 0);
  EXPECT_GT(r.arm_motion_after_trigger, 0);
  // The bucket volume before each atomic action and after the last: the last is the scoop's.
  ASSERT_EQ(r.payload_at_actions.size(), static_cast<std::size_t>(r.atomic_actions) + 1);
  EXPECT_DOUBLE_EQ(r.payload_at_actions.back(), r.payload_after_scoop);
  for (double v : r.payload_at_actions) {
    EXPECT_GE(v, 0.0);
    EXPECT_LE(v, 1.01 * r.target_volume);  // V_t: the rated heaped capacity (target fill 1)
  }
}

// Algorithm 3 on gravel: the predicted volume fires before the machine stalls and "Just in &
// out" is chosen. Issue 6's goal is a fill rate of at least 95 % (measured 0.993).
TEST(ScoopCycle, GravelAutoSelectionIsJustInAndOut) {
  const Outcome out = RunScoop("big_gravel", TriggerKind::kPredicted, ScoopPolicy::kAutoSelection);
  ExpectSound(out);
  const ScoopResult& r = out.result;
  EXPECT_EQ(r.trigger_reason, "predicted_volume");
  EXPECT_EQ(r.strategy, ScoopStrategy::kJustInOut);
  EXPECT_EQ(r.atomic_actions, 2);
  EXPECT_GE(r.v1_at_trigger + r.v2_at_trigger, r.target_volume);
  EXPECT_GE(r.fill_rate, 0.95);
}

// Algorithm 3 on river sand (γ ∈ 𝒴): "Stairway" with at least one step, fill at least 95 %
// (measured 0.991).
TEST(ScoopCycle, SandAutoSelectionIsStairway) {
  const Outcome out = RunScoop("river_sand", TriggerKind::kPredicted, ScoopPolicy::kAutoSelection);
  ExpectSound(out);
  const ScoopResult& r = out.result;
  EXPECT_EQ(r.strategy, ScoopStrategy::kStairway);
  EXPECT_GE(r.stairway_steps, 1);
  EXPECT_LE(r.stairway_steps, StrategyParameters{}.max_steps);
  EXPECT_GE(r.fill_rate, 0.95);
}

// Fig. 10 (c) vs (d): with the same target, the prediction triggers earlier than perception
// without prediction (which on this pile only ends by the stop detector).
TEST(ScoopCycle, PredictionTriggersEarlierThanPerceptionAlone) {
  const Outcome predicted =
      RunScoop("big_gravel", TriggerKind::kPredicted, ScoopPolicy::kJustInOut);
  const Outcome perceived =
      RunScoop("big_gravel", TriggerKind::kPerception, ScoopPolicy::kJustInOut);
  ExpectSound(predicted);
  ExpectSound(perceived);
  EXPECT_LT(predicted.result.trigger_after_contact, perceived.result.trigger_after_contact);
  EXPECT_LT(predicted.result.ContactToScoopEndEnergy(), perceived.result.ContactToScoopEndEnergy());
}

// The pressure-triggered "Stairway #3" baseline (Table 5, first row) runs to the end.
TEST(ScoopCycle, PressureTriggeredStairway3Baseline) {
  const Outcome out =
      RunScoop("big_gravel", TriggerKind::kPressure, ScoopPolicy::kStairwayFixed, 120e5);
  ExpectSound(out);
  EXPECT_EQ(out.result.trigger_reason, "boom_pressure");
  EXPECT_EQ(out.result.stairway_steps, 3);
  EXPECT_GE(out.result.boom_pressure_at_trigger, 120e5);
}

// The exit lift holds the bucket's attitude (racked, no further back than level) while a Z-bar
// arm tips it back as the boom rises. The bucket PID alone answers 0.6 s late, by when a
// full-speed boom has tipped the bucket back ~0.1 rad; in the yard's sand bin that poured
// 0.22 m³ of a full pushing scoop over the back wall. The tilt feed-forward from the boom's
// demand and the Smith predictor hold it closer and the lift loses nothing. Measured (held / PID
// only): braking scoop 0.068 / 0.180 rad, 0.000 / 0.118 m³ lost; pushing 0.020 / 0.077 rad,
// nothing lost either way. (Triggered later, by the model without its intake factor, the
// pushing scoop's boom stalled in the pile a while, which the feed-forward learns only as it
// happens: 0.073 / 0.109 rad.) With the drive easing when the boom stalls in the steps
// (boom_stall_time) the pushing scoop measures 0.039 / 0.123 rad and loses 0.006 / 0.000 m³:
// "loses no more" is held to 0.01 m³, 0.3 % of the bucket.
TEST(ScoopCycle, ExitLiftHoldsTheBucketsAttitude) {
  // What the exit lift (the last action) changed of the bucket's volume [m³].
  auto lift_loss = [](const ScoopResult& r) {
    const std::size_t n = r.payload_at_actions.size();
    return n < 2 ? NAN : r.payload_at_actions[n - 2] - r.payload_at_actions[n - 1];
  };
  for (const bool pushing : {false, true}) {
    SCOPED_TRACE(pushing ? "pushing scoop" : "braking scoop");
    Variant with;
    if (pushing) with.scoop_deceleration = 0.3, with.predictor = &PushingPredictor();
    Variant without = with;
    without.attitude_feed_forward = false;
    const Outcome held =
        RunScoop("river_sand", TriggerKind::kPredicted, ScoopPolicy::kStairwayFixed, 0, with);
    const Outcome free =
        RunScoop("river_sand", TriggerKind::kPredicted, ScoopPolicy::kStairwayFixed, 0, without);
    ExpectSound(held);
    ExpectSound(free);
    std::printf(
        "[exit lift] %s: attitude error %.3f rad held, %.3f rad PID only; lift loses "
        "%.3f / %.3f m^3\n",
        pushing ? "pushing" : "braking", held.result.exit_lift_attitude_error,
        free.result.exit_lift_attitude_error, lift_loss(held.result), lift_loss(free.result));
    // 0.12 rad (was 0.1 with the diagonal mass matrix): since issue 39 the plant's full
    // mass matrix couples the boom's acceleration into the bucket joint, which the attitude
    // feed-forward (kinematic only) does not model; the braking scoop now ends at 0.104 rad,
    // against 0.24 rad with the PID alone.
    EXPECT_LT(held.result.exit_lift_attitude_error, 0.12);
    EXPECT_LT(held.result.exit_lift_attitude_error, 0.8 * free.result.exit_lift_attitude_error);
    EXPECT_LE(lift_loss(held.result), lift_loss(free.result) + 0.01);
    EXPECT_LE(lift_loss(held.result), 0.01);
  }
}

// The crowd look-ahead's stop (RequestStop) brakes from the speed the machine has. Stalled in
// the pile the speed profile's reference sits at the attack speed with the PI's integral wound
// up; braking from those kept pushing for seconds, and once a Stairway lift freed the bucket
// the machine drove on over a metre past the request (a side wall came 0.47 m close). The
// travel after the request is at most what the look-ahead reckons with, v / f + v² / 2 a_dec
// (f = 20 Hz) at the request's speed, plus 0.05 m of PI lag.
TEST(ScoopCycle, StopRequestBrakesFromTheSpeedTheMachineHas) {
  testing::ConeYard yard(kMachine, "big_gravel", 3.0, 4.0);
  const prediction::HeightGrid map = testing::ToHeightGrid(yard.world.terrain);
  plant::Plant loader(yard.machine, plant::testing::Functions(kMachine), yard.world, yard.start);
  testing::PlantMachine machine(loader);
  ScoopCycleOptions options;
  options.attack_pose = yard.attack_pose;
  options.policy = ScoopPolicy::kStairwayFixed;
  BoomPressureTrigger trigger(120e5);
  ScoopCycle cycle(yard.machine, plant::testing::Functions(kMachine), map, *yard.material, trigger,
                   &Predictor(), options);
  cycle.Start(machine);
  double scoop_since = NAN, request_speed = NAN, request_heading = 0, travel = 0;
  Eigen::Vector2d request_xy = Eigen::Vector2d::Zero();
  while (cycle.Tick(machine)) {
    machine.Advance(options.tick);
    const Proprioception s = machine.Sense();
    const std::string phase = cycle.phase_name();
    if (phase == "scoop" && std::isnan(scoop_since)) scoop_since = s.time;
    // Three seconds into the steps: stalled at 0.08 m/s between two lifts. Braking from the
    // profile's reference, the machine drove on 0.113 m here; from its speed, 0.001 m.
    if (std::isnan(request_speed) && !std::isnan(scoop_since) && s.time - scoop_since > 3.0) {
      cycle.RequestStop("obstacle_beside");
      request_speed = std::max(s.speed, 0.0);
      request_xy = s.hinge_xy;
      request_heading = s.heading;
    }
    if (!std::isnan(request_speed) && phase != "retreat" && phase != "done") {
      travel = std::max(
          travel, (s.hinge_xy - request_xy)
                      .dot(Eigen::Vector2d(std::cos(request_heading), std::sin(request_heading))));
    }
  }
  const ScoopResult r = cycle.Finish(machine);
  ASSERT_TRUE(r.ok) << r.failure;
  ASSERT_FALSE(std::isnan(request_speed));
  const double a_dec = options.speed_gains.max_deceleration;
  const double allowed = request_speed / 20 + request_speed * request_speed / (2 * a_dec) + 0.05;
  std::printf("[scoop] stop requested at %.2f m/s: drove on %.3f m (allowed %.3f m)\n",
              request_speed, travel, allowed);
  EXPECT_LE(travel, allowed);
  EXPECT_GT(r.fill_rate, 0.0);  // the steps still scoop, without crowding on
}

TEST(ScoopCycle, Explore) {
  if (std::getenv("AUTOSHOVEL_SCOOP_EXPLORE") == nullptr) GTEST_SKIP();
  const char* which = std::getenv("AUTOSHOVEL_SCOOP_EXPLORE");
  for (const char* m : {"big_gravel", "river_sand"}) {
    if (which[0] == 'q') {
      RunScoop(m, TriggerKind::kPredicted, ScoopPolicy::kStairway);
      continue;
    }
    RunScoop(m, TriggerKind::kPredicted, ScoopPolicy::kAutoSelection);
    RunScoop(m, TriggerKind::kPredicted, ScoopPolicy::kJustInOut);
    RunScoop(m, TriggerKind::kPredicted, ScoopPolicy::kStairway);
    RunScoop(m, TriggerKind::kPerception, ScoopPolicy::kJustInOut);
    RunScoop(m, TriggerKind::kPerception, ScoopPolicy::kStairwayFixed);
    RunScoop(m, TriggerKind::kPressure, ScoopPolicy::kStairwayFixed, std::atof(which) * 1e5);
  }
}

// The V2 path against the machine's (docs/scooping_control.md): one predicted-trigger
// "Just in & out" scoop per material, the tip, joints and travel after the trigger every 0.1 s
// beside the predicted path at the same time (plan time step 0.02 s). Off unless asked.
TEST(ScoopCycle, TraceAfterTrigger) {
  const char* which = std::getenv("AUTOSHOVEL_SCOOP_TRACE");
  if (which == nullptr) GTEST_SKIP();
  for (const char* m : {"big_gravel", "river_sand"}) {
    if (which[0] != '*' && std::string(which) != m) continue;
    testing::ConeYard yard(kMachine, m, 3.0, 4.0);
    const prediction::HeightGrid map = testing::ToHeightGrid(yard.world.terrain);
    plant::Plant loader(yard.machine, plant::testing::Functions(kMachine), yard.world, yard.start);
    testing::PlantMachine machine(loader);
    ScoopCycleOptions options;
    options.attack_pose = yard.attack_pose;
    options.policy = ScoopPolicy::kJustInOut;
    if (const char* decel = std::getenv("AUTOSHOVEL_SCOOP_DECEL")) {
      options.scoop_deceleration = std::atof(decel);
    }
    // AUTOSHOVEL_TRACE_V1=x: fire at V1 ≥ x instead (V2 still computed, for its path).
    struct V1Trigger : ScoopTrigger {
      double target = 0, threshold = 0;
      bool Fire(const TriggerInputs& in) override {
        return threshold > 0 ? in.v1 >= threshold : in.v1 + in.v2 >= target;
      }
      bool NeedsPrediction() const override { return true; }
      std::string Name() const override { return "trace"; }
    } trigger;
    trigger.target = options.target_fill * yard.machine.bucket.rated_capacity;
    if (const char* v1 = std::getenv("AUTOSHOVEL_TRACE_V1")) trigger.threshold = std::atof(v1);
    ScoopCycle cycle(yard.machine, plant::testing::Functions(kMachine), map, *yard.material,
                     trigger, &Predictor(), options);
    cycle.Start(machine);
    struct Row {
      double t, travel, speed, q_boom, q_bucket, x, z, payload;
    };
    std::vector<Row> rows;
    double t_trig = NAN;
    Eigen::Vector2d xy0 = Eigen::Vector2d::Zero();
    double heading0 = 0;
    while (cycle.Tick(machine)) {
      machine.Advance(options.tick);
      const Proprioception s = machine.Sense();
      const std::string phase = cycle.phase_name();
      if (phase == "scoop" && std::isnan(t_trig)) {
        t_trig = s.time, xy0 = s.hinge_xy, heading0 = s.heading;
      }
      if (!std::isnan(t_trig) && phase == "scoop") {
        const Eigen::Vector2d u(std::cos(heading0), std::sin(heading0));
        const Eigen::Vector2d tip = prediction::TipInBase(yard.machine, s.q_boom, s.q_bucket);
        rows.push_back({s.time - t_trig, (s.hinge_xy - xy0).dot(u), s.speed, s.q_boom, s.q_bucket,
                        (s.hinge_xy - xy0).dot(u) + tip.x(), tip.y(), machine.PayloadVolume()});
      }
    }
    const ScoopResult r = cycle.Finish(machine);
    std::printf(
        "[trace] %s trigger %.2f s after contact, V1 %.3f V2 %.3f, fill %.3f, predicted d %.3f, "
        "travel after trigger %.3f, Eq19 true path %.3f, crowd %.1f kJ\n",
        m, r.trigger_after_contact, r.v1_at_trigger, r.v2_at_trigger, r.fill_rate,
        r.has_features_at_trigger ? Predictor().Predict(r.features_at_trigger).penetration : NAN,
        r.travel_after_trigger, r.feedback_volume,
        r.Phase("crowd") ? r.Phase("crowd")->energy / 1e3 : NAN);
    const Eigen::Vector2d u(std::cos(heading0), std::sin(heading0));
    const std::vector<Eigen::Vector3d>& pred = r.predicted_tip_path;
    for (std::size_t i = 0; i < rows.size(); i += 10) {
      const Row& w = rows[i];
      const std::size_t k = static_cast<std::size_t>(std::lround(w.t / 0.02));
      double px = NAN, pz = NAN;
      if (k < pred.size()) {
        px = (pred[k].head<2>() - xy0).dot(u);
        pz = pred[k].z();
      }
      std::printf(
          "[trace] t %.2f travel %.3f v %.2f q_boom %.3f q_bucket %.3f tip x %.3f z %.3f | "
          "predicted x %.3f z %.3f | payload %.3f\n",
          w.t, w.travel, w.speed, w.q_boom, w.q_bucket, w.x, w.z, px, pz, w.payload);
    }
  }
}

}  // namespace
}  // namespace autoshovel::control
