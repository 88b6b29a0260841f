// One whole shoveling cycle per kind of yard (issue 6, item 7): perceive, select, drive the
// path, attack, crowd, trigger on V1 + V2, scoop (Algorithm 3), level, shake, retreat, on the
// simulated machine through the multi-rate executive. Simulator labels stand in for the
// segmentation network (its own tests cover it) to keep each cycle at a few seconds.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "runtime/app/shovel_run.h"
#include "tests/closed_loop/cycle_runner.h"

namespace autoshovel::app {
namespace {

ShovelRunOptions Options(const std::string& scenario) { return TestCycleOptions(scenario); }

CycleOutcome RunOne(const ShovelRunOptions& options) { return RunTestCycle(options); }

// What every cycle must show.
void ExpectSafeAndWhole(const ShovelRunOptions& options, const CycleOutcome& out) {
  const results::CycleRecord& r = out.record;
  ASSERT_TRUE(r.completed) << out.failure;
  EXPECT_EQ(r.safety_violations, 0);
  EXPECT_GE(r.safety_margin_m, options.safety_distance);
  EXPECT_EQ(out.scoop.non_finite_blocked, 0);
  EXPECT_EQ(out.scoop.refused_commands, 0);
  EXPECT_EQ(out.scoop.prediction_failures, 0);
  // The phases tile the cycle: their times add up to the total.
  EXPECT_NEAR(
      r.time_s.approach + r.time_s.crowd + r.time_s.scoop + r.time_s.level + r.time_s.retreat,
      r.time_s.total, 0.05);
  EXPECT_GT(r.energy_kj.crowd, 0);
  EXPECT_FALSE(r.samples.empty());
}

// Gravel in the open (cone_pile): Algorithm 3 picks "Just in & out" on the predicted trigger,
// which the main job's scoop (1.5 m/s, pushing on at 0.6 m/s²) lets fire within the issue's
// 0.4 s of contact (measured 0.05 s; the braking scoop: 1.80 s); fill at least the 95 %
// (measured 1.000).
TEST(ShovelCycle, GravelConeIsJustInAndOutAndFull) {
  const ShovelRunOptions options = Options("cone_pile");
  const CycleOutcome out = RunOne(options);
  ExpectSafeAndWhole(options, out);
  EXPECT_EQ(out.record.material, "big_gravel");
  EXPECT_EQ(out.record.strategy, "just_in_out");
  EXPECT_EQ(out.scoop.trigger_reason, "predicted_volume");
  EXPECT_LE(out.scoop.trigger_after_contact, 0.4);
  EXPECT_GE(out.record.fill_rate, 0.95);
  // The predictor in the closed loop (issue 41, item 5): the travel it predicted at the trigger
  // is logged beside the travel measured after it, and the shipped model, trained for this
  // profile, is near it: measured 2.283 m predicted against 2.227 m travelled. 0.5 m holds that
  // with a wide margin yet catches a sign, a unit or a factor-of-two error, or another travel.
  const double predicted = out.scoop.predicted_travel_at_trigger;
  const double actual = out.scoop.travel_after_trigger;
  std::printf("[travel] predicted %.3f m, actual %.3f m\n", predicted, actual);
  ASSERT_TRUE(std::isfinite(predicted));
  ASSERT_TRUE(std::isfinite(actual));
  EXPECT_GT(predicted, 0.0);
  EXPECT_NEAR(predicted, actual, 0.5);
  EXPECT_EQ(out.record.crowding.predicted_penetration, predicted);
  EXPECT_EQ(out.record.crowding.penetration, actual);
}

// River sand in the mixing station's bin_4 (a difficult material, γ ∈ 𝒴): "Stairway". The
// ridge lies against the bin's back wall, and the crowd look-ahead ends crowding before it:
// fill measured 0.999 (the braking scoop: 0.998; 0.974 while the exit lift left the bucket's
// attitude to its PID alone; 0.923 while the look-ahead still stopped for the wall's labels
// seen over the crest at a grazing angle; semantic_map.h), held at 0.9; clearance 1.98 m. The
// trigger fires 0.20 s after contact (the braking scoop: 7.55 s, by the stop detector).
TEST(ShovelCycle, SandInABinIsStairwayAndFull) {
  ShovelRunOptions options = Options("mixing_station");
  options.bins = {"bin_4"};
  const CycleOutcome out = RunOne(options);
  ExpectSafeAndWhole(options, out);
  EXPECT_EQ(out.record.material, "river_sand");
  EXPECT_EQ(out.record.strategy, "stairway");
  EXPECT_EQ(out.scoop.trigger_reason, "predicted_volume");
  EXPECT_LE(out.scoop.trigger_after_contact, 0.4);
  EXPECT_GE(out.record.fill_rate, 0.9);
}

// The fixed "Stairway #3" in the sand bin, triggered 0.2 s after contact at 1.5 m/s: by the
// second step the bucket is deep in the heap and the drive, still crowding, pins it there; the
// boom stalls lifting. Without easing the drive (ScoopCycleOptions::boom_stall_time = 0) 4 of
// 5 such cycles failed in `compare table5` (the stuck-valve stop, or the 20 s scoop limit).
// With it the steps go on and the bucket comes out full (measured 0.997).
TEST(ShovelCycle, SandStairwayThreeEasesTheDriveWhenTheBoomStalls) {
  ShovelRunOptions options = Options("mixing_station");
  options.bins = {"bin_4"};
  options.policy = control::ScoopPolicy::kStairwayFixed;
  const CycleOutcome out = RunOne(options);
  ExpectSafeAndWhole(options, out);
  EXPECT_EQ(out.record.strategy, "stairway_fixed");
  EXPECT_EQ(out.scoop.stairway_steps, 3);
  EXPECT_TRUE(out.scoop.drive_eased_for_boom);
  EXPECT_GE(out.record.fill_rate, 0.95);
}

// The pushing scoop (crowding on through the curl at 0.3 m/s², with the model trained for it)
// in the same bin fills the bucket in its Stairway; the exit lift then held the racked attitude
// by the bucket PID alone and poured 0.22 m³ over the back wall (fill 0.938). With the tilt
// feed-forward and the attitude held no further back than level it keeps the full load
// (measured 0.998, triggered 0.95 s after contact by κ·(V1 + V2)).
TEST(ShovelCycle, PushingScoopKeepsItsSandThroughTheExitLift) {
  ShovelRunOptions options = Options("mixing_station");
  options.bins = {"bin_4"};
  options.attack_speed = 1.0;  // the profile penetration_svr_push is trained for
  options.scoop_deceleration = 0.3;
  options.predictor = options.models_dir + "/prediction/penetration_svr_push";
  const CycleOutcome out = RunOne(options);
  ExpectSafeAndWhole(options, out);
  EXPECT_EQ(out.record.strategy, "stairway");
  const std::vector<double>& volumes = out.scoop.payload_at_actions;
  ASSERT_GE(volumes.size(), 2u);
  EXPECT_GE(volumes.back(), 0.995 * volumes[volumes.size() - 2]);  // the exit lift keeps it
  EXPECT_GE(out.record.fill_rate, 0.98);
}

// The thin low sand remainder in dim light (0.45 m high): the bucket crosses the whole pile;
// Stairway on sand. Here V1 + V2 stays short of V_t for 2.45 s of crowding. Measured 0.969
// (the braking scoop: 0.902, pouring over the lip in the rack-back); held at 0.85.
TEST(ShovelCycle, LowLyingPileIsScoopedSafely) {
  const ShovelRunOptions options = Options("low_pile");
  const CycleOutcome out = RunOne(options);
  ExpectSafeAndWhole(options, out);
  EXPECT_EQ(out.record.strategy, "stairway");
  EXPECT_GE(out.record.fill_rate, 0.85);
}

// A parked loader across the direct way (seed Fig. 19 (c), Table 4 scenario c): the selected
// point is reached round it, never closer than the safety distance, and the bucket is full.
TEST(ShovelCycle, PileBehindAParkedLoaderIsReachedRoundIt) {
  const ShovelRunOptions options = Options("pile_behind_loader");
  const CycleOutcome out = RunOne(options);
  ExpectSafeAndWhole(options, out);
  EXPECT_GE(out.record.fill_rate, 0.95);
}

// The energy audit over a whole closed-loop cycle (issue 41): per phase, its terms add up to what
// the plant's energy counters booked to that phase within 1 %, and the scoop's audit shows the
// work a scoop is made of.
TEST(ShovelCycle, EnergyAuditAddsUpPerPhase) {
  ShovelRunOptions options = Options("cone_pile");
  options.energy_audit = true;
  const CycleOutcome out = RunOne(options);
  ASSERT_TRUE(out.record.completed) << out.failure;
  ASSERT_FALSE(out.energy_audit_trace.empty());
  for (const char* name : {"crowd", "scoop", "retreat"}) {
    const control::PhaseRecord* phase = out.scoop.Phase(name);
    ASSERT_NE(phase, nullptr) << name;
    const auto it = out.energy_audit_by_phase.find(name);
    ASSERT_NE(it, out.energy_audit_by_phase.end()) << name;
    EXPECT_NEAR(it->second.total(), phase->energy, 0.01 * phase->energy + 10.0) << name;
  }
  const plant::EnergyAudit& scoop = out.energy_audit_by_phase.at("scoop");
  EXPECT_GT(scoop[plant::EnergyTerm::kLifting], 20e3);  // a full bucket rose
  EXPECT_GT(scoop.soil(), 20e3);                        // through the pile
  EXPECT_GT(scoop.hydraulic(), scoop.cylinder_work());  // the hydraulics lose some
  // The whole cycle: the audit's total is the energy the cycle record books.
  plant::EnergyAudit cycle;
  for (const auto& [name, audit] : out.energy_audit_by_phase) cycle += audit;
  EXPECT_NEAR(cycle.total() / 1e3, out.record.energy_kj.total, 0.01 * out.record.energy_kj.total);
}

TEST(ShovelCycle, UnknownBinIsRefusedNamingTheBins) {
  ShovelRunOptions options = Options("mixing_station");
  options.bins = {"bin_42"};
  try {
    ShovelJob job(options);
    FAIL() << "accepted an unknown bin";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("bin_42"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("bin_1"), std::string::npos) << e.what();
  }
}

// The main job's profile fits its model; the braking scoop's model (trained up to 1.23 m/s)
// under a 1.5 m/s attack is named as extrapolating, with the speeds.
TEST(ShovelCycle, PredictorTrainedSlowerThanTheAttackIsWarnedAbout) {
  ShovelRunOptions options = Options("cone_pile");
  EXPECT_EQ(ShovelJob(options).PredictorMismatch(), "");
  options.predictor = options.models_dir + "/prediction/penetration_svr";
  const std::string mismatch = ShovelJob(options).PredictorMismatch();
  EXPECT_NE(mismatch.find("up to 1.23 m/s"), std::string::npos) << mismatch;
  EXPECT_NE(mismatch.find("attacks at 1.50 m/s"), std::string::npos) << mismatch;
  options.attack_speed = 1.0;
  EXPECT_EQ(ShovelJob(options).PredictorMismatch(), "");
}

// The main job's pushing scoop on a revisit near a wall (docs/campaigns.md): the fifth cycle of
// this yard enters bin_1 with the frame still articulated from correcting its approach. While
// navigation stopped steering at the scoop phase, the machine drove an arc towards the side
// wall and the bucket came to 0.38 m of it (safety distance 0.5 m); steering along the planned
// line through the scoop keeps 1.63 m.
TEST(ShovelCycle, ScoopKeepsToItsPlannedLineOnARevisitNearAWall) {
  ShovelRunOptions options = Options("mixing_station");
  options.cycles = 5;
  options.seed = 4596321354816073103ull;
  options.yard_variation = 0.1;
  ShovelJob job(options);
  for (int i = 0; i < 5; ++i) {
    const CycleOutcome out = job.RunCycle(i, {}, nullptr);
    EXPECT_EQ(out.record.safety_violations, 0) << "cycle " << i + 1;
    EXPECT_GE(out.record.safety_margin_m, options.safety_distance) << "cycle " << i + 1;
  }
}

}  // namespace
}  // namespace autoshovel::app
