// Look-ahead obstacle detection (seed §4.5): the script and the joint models predicted 2–3 s ahead,
// the underside of the linkage tested against an elevation map, a stop at the first report.
// The machine is the joint models at 100 Hz (excavator_test_support.h).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>

#include "excavator_test_support.h"
#include "runtime/control/excavator/linkage_clearance.h"

namespace autoshovel::control {
namespace {

using testing::DigEnd;
using testing::Excavator25t;
using testing::FlatMap;
using testing::kDeg;
using testing::RunOptions;
using testing::RunPass;
using testing::RunResult;
using testing::StandardGoal;
using testing::Truck20t;

HeightGrid MapWithTruck(const testing::Truck& truck, double resolution) {
  HeightGrid map = FlatMap(resolution);
  map.RaiseBox(truck.body);
  map.RaiseBox(truck.cab);
  return map;
}

/// Lowest signed distance of the underside to `box` over a run (the look-ahead only sees map
/// cells; this is the box itself), at most 0.021 m over the true one.
// The loading script of the standard pass (dig end to `truck`) with default settings.
LoadingScript StandardScript(const testing::Excavator& e, const testing::Truck& truck) {
  const ScriptSettings settings;
  const ScriptParameters p = ComputeScriptParameters(*e.envelope, e.derivation.models, DigEnd(),
                                                     StandardGoal(truck), settings);
  return BuildLoadingScript(p, settings);
}

double MinDistanceTo(const RunResult& run, const ObstacleBox& box, double stop_below = -1e9) {
  return testing::MinUndersideDistance(run.samples, {box}, stop_below);
}

TEST(ObstacleLookAhead, NoFalseStopOnAFlatMapWithTheTruckBesideThePath) {
  const testing::Excavator& e = Excavator25t();
  const testing::Truck truck = Truck20t(90 * kDeg, 6.0);
  const ScriptSettings settings;
  const ScriptParameters p = ComputeScriptParameters(*e.envelope, e.derivation.models, DigEnd(),
                                                     StandardGoal(truck), settings);
  const ObstacleLookAhead lookahead(*e.envelope);
  for (double resolution : {0.1, 0.3}) {
    const HeightGrid map = MapWithTruck(truck, resolution);
    RunOptions options;
    options.lookahead = &lookahead;
    options.map = &map;
    const auto t0 = std::chrono::steady_clock::now();
    const RunResult run =
        RunPass(BuildLoadingScript(p, settings), e.derivation.models, DigEnd(), settings, options);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_FALSE(run.stopped) << "cells " << resolution << " m: " << run.first_report.reason;
    EXPECT_TRUE(run.finished);
    std::printf(
        "[figure] flat map, %.1f m cells, truck beside the path: no stop in %d "
        "look-aheads over a %.2f s pass (%.2f ms per look-ahead incl. the 100 Hz "
        "machine)\n",
        resolution, run.lookahead_checks, run.finish_time, ms / run.lookahead_checks);
  }
}

/// One geometry of the person trials: swing speed and acceleration factor, where the truck is
/// and on which side its cab, where the dig is.
struct Scenario {
  double factor, truck_azimuth, cab_side, dig_azimuth;
};
constexpr Scenario kScenarios[] = {
    {0.7, 90 * kDeg, 1, 0},    {0.85, -100 * kDeg, -1, 10 * kDeg},
    {1.0, 120 * kDeg, 1, 0},   {1.15, 75 * kDeg, 1, -10 * kDeg},
    {1.3, -130 * kDeg, -1, 0}, {1.0, 90 * kDeg, 1, 0}};  // the standard pass, last

testing::Truck ScenarioTruck(const Scenario& s) {
  return Truck20t(s.truck_azimuth, 6.0, s.cab_side);
}

ExcavatorState ScenarioStart(const Scenario& s) { return DigEnd(s.dig_azimuth); }

/// Parameters and the unobstructed pass for one scenario, computed once.
struct Nominal {
  ExcavatorJointModels models;
  ScriptParameters params;
  RunResult run;
};

const Nominal& NominalFor(int scenario) {
  static std::map<int, Nominal> cache;
  auto it = cache.find(scenario);
  if (it != cache.end()) return it->second;
  const testing::Excavator& e = Excavator25t();
  const Scenario& s = kScenarios[scenario];
  Nominal n;
  n.models = testing::WithSwingFactor(e.derivation.models, s.factor);
  const ScriptSettings settings;
  LoadingGoal goal = StandardGoal(ScenarioTruck(s));
  goal.p_base_dig = 7.0 * Eigen::Vector3d(std::cos(s.dig_azimuth), std::sin(s.dig_azimuth), 0);
  n.params = ComputeScriptParameters(*e.envelope, n.models, ScenarioStart(s), goal, settings);
  n.run = RunPass(BuildLoadingScript(n.params, settings), n.models, ScenarioStart(s), settings);
  return cache.emplace(scenario, std::move(n)).first->second;
}

TEST(ObstacleLookAhead, StopsShortOfAPersonInTheSwingPathInEveryRandomTrial) {
  const testing::Excavator& e = Excavator25t();
  const ScriptSettings settings;
  const ObstacleLookAhead lookahead(*e.envelope);
  std::mt19937 rng(1998);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  constexpr int kTrials = 30;
  double min_margin = 1e9, sum_margin = 0, min_lead = 1e9, max_lead = 0;
  double min_swept = 1e9, max_swept = -1e9;
  int on_the_way_out = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    const int scenario = trial % 5;
    const Scenario& geometry = kScenarios[scenario];
    const Nominal& nominal = NominalFor(scenario);
    const testing::Truck truck = ScenarioTruck(geometry);
    const ExcavatorState start = ScenarioStart(geometry);
    // The person (0.5 m × 0.5 m, 1.8 m tall) stands where the unobstructed pass brings the
    // underside below 1.6 m while the upper structure swings: under the rising bucket on the way
    // out or the lowering one on the way back, beyond the machine's own 3.5 m, clear of the
    // truck and not where the linkage starts.
    ObstacleBox person;
    person.half_extents = Eigen::Vector2d(0.25, 0.25);
    person.z_max = 1.8;
    bool out = false;
    for (int attempt = 0;; ++attempt) {
      ASSERT_LT(attempt, 1000) << "no place for the person";
      const testing::RunSample& sample =
          nominal.run.samples[static_cast<std::size_t>(u(rng) * nominal.run.samples.size())];
      if (std::abs(sample.state.qd[3]) < 0.05) continue;
      const std::vector<EnvelopePoint> points = e.envelope->Underside(sample.state.q);
      const EnvelopePoint* lowest = nullptr;
      for (const EnvelopePoint& p : points) {
        if (p.p.head<2>().norm() > 3.5 && (lowest == nullptr || p.p.z() < lowest->p.z())) {
          lowest = &p;
        }
      }
      if (lowest == nullptr || lowest->p.z() > 1.6) continue;
      person.center =
          lowest->p.head<2>() + Eigen::Vector2d(0.3 * u(rng) - 0.15, 0.3 * u(rng) - 0.15);
      person.yaw = u(rng) * M_PI;
      Eigen::Vector2d corners[4];
      person.Corners(corners);
      bool near_truck = false;
      for (const Eigen::Vector2d& c : corners) {
        near_truck = near_truck || truck.body.FootprintDistance(c) < 0.5 ||
                     truck.cab.FootprintDistance(c) < 0.5;
      }
      if (near_truck) continue;
      const std::vector<EnvelopePoint> at_start = e.envelope->Underside(start.q);
      if (MinClearance(at_start, {person}) < 0.5) continue;
      out = sample.active_rule[3] == 1;
      break;
    }
    on_the_way_out += out ? 1 : 0;
    // Where along the arc: the swing angle from the dig to the person.
    const double swept = std::abs(std::remainder(
        std::atan2(person.center.y(), person.center.x()) - geometry.dig_azimuth, 2 * M_PI));
    min_swept = std::min(min_swept, swept);
    max_swept = std::max(max_swept, swept);
    SCOPED_TRACE("trial " + std::to_string(trial) + ", scenario " + std::to_string(scenario) +
                 ", person at (" + std::to_string(person.center.x()) + ", " +
                 std::to_string(person.center.y()) + ")");
    // The unobstructed pass would hit the person.
    ASSERT_LT(MinDistanceTo(nominal.run, person, -0.05), 0.0);

    HeightGrid map = MapWithTruck(truck, 0.1);
    map.RaiseBox(person);
    RunOptions options;
    options.lookahead = &lookahead;
    options.map = &map;
    const RunResult run = RunPass(BuildLoadingScript(nominal.params, settings), nominal.models,
                                  start, settings, options);
    ASSERT_TRUE(run.stopped);
    ASSERT_TRUE(run.first_report.collision.has_value());
    // What was reported is the person (within a cell of its footprint), not the truck or ground.
    EXPECT_LT(person.FootprintDistance(run.first_report.collision->p_world.head<2>()),
              0.1 * std::sqrt(2.0));
    // The stop, predicted at the first report, comes to rest clear of the map ...
    EXPECT_EQ(run.stop_prediction.verdict, LookAheadVerdict::kClear) << run.stop_prediction.reason;
    // ... and so does the machine: at rest, the underside never reached the person.
    EXPECT_EQ(run.samples.back().state.qd.cwiseAbs().maxCoeff(), 0.0);
    const double margin = MinDistanceTo(run, person);
    EXPECT_GT(margin, 0.0);
    min_margin = std::min(min_margin, margin);
    sum_margin += margin;
    min_lead = std::min(min_lead, run.first_report.collision->time);
    max_lead = std::max(max_lead, run.first_report.collision->time);
  }
  std::printf(
      "[figure] person in the swing path, %d trials (swing speed and acceleration "
      "x0.7–1.3, truck at ±75–130°, person %.0f–%.0f° of swing from the dig, %d on the "
      "way out): stopped short in all, distance at rest min %.3f m mean %.3f m; "
      "collision predicted %.2f–%.2f s ahead at the first report\n",
      kTrials, min_swept / kDeg, max_swept / kDeg, on_the_way_out, min_margin, sum_margin / kTrials,
      min_lead, max_lead);
}

TEST(ObstacleLookAhead, TheHorizonCoversTheSwingsStoppingDistance) {
  // Seed §4.5: how far ahead of the swing one must look depends on the swing's top speed; the
  // seed found 40°–50° by experiment, and 2–3 s of prediction.
  const testing::Excavator& e = Excavator25t();
  const ObstacleLookAhead lookahead(*e.envelope);
  const LookAheadSettings settings;
  for (int scenario : {5, 2}) {  // the standard 90° pass, then the 120° one
    const Nominal& nominal = NominalFor(scenario);
    const JointModelParams& swing = nominal.models[3];
    const testing::RunSample* fastest = &nominal.run.samples.front();
    for (const testing::RunSample& s : nominal.run.samples) {
      if (std::abs(s.state.qd[3]) > std::abs(fastest->state.qd[3])) fastest = &s;
    }
    const double peak = std::abs(fastest->state.qd[3]);
    const double swing_span = std::abs(nominal.params.swing_dump - nominal.params.swing_start);
    const double stop_angle = StoppingDistance(swing, peak);
    const double stop_time = StoppingTime(swing, peak);
    // A look-ahead from the fastest moment predicts at least as long as that stop takes.
    const ExcavatorSimulator machine(nominal.models, fastest->state);
    const LookAheadResult result =
        lookahead.Check(fastest->state, machine, nullptr, 0.0, testing::FlatMap(0.3),
                        Eigen::Isometry3d::Identity());
    std::printf(
        "[figure] %.0f° pass: swing peak %.1f°/s; a stop from it takes %.2f s and %.1f° "
        "(latency %.2f s, braking %.1f°/s²); the look-ahead predicts %.2f s (%.1f s "
        "set), covering %.1f° at that speed\n",
        swing_span / kDeg, peak / kDeg, stop_time, stop_angle / kDeg, swing.latency,
        swing.max_acceleration / kDeg, result.horizon, settings.horizon,
        peak * result.horizon / kDeg);
    EXPECT_GE(result.horizon, stop_time + LoadingScript::kPeriod - 1e-9);
    EXPECT_GE(result.horizon, settings.horizon);
    EXPECT_GT(peak * result.horizon, stop_angle);
    // The stopping angle is of the seed's order (40–50°), not a few degrees or a half turn.
    EXPECT_GT(stop_angle, 30 * kDeg);
    EXPECT_LT(stop_angle, 90 * kDeg);
    if (scenario == 5) {
      EXPECT_LT(result.horizon, settings.horizon + 0.05);  // 2.5 s all but suffice at 90°
    } else {
      EXPECT_GT(result.horizon, settings.horizon + 0.2);  // extended for the faster 120° swing
    }
  }
}

TEST(ObstacleLookAhead, ATooLowBoomIsCaughtBeforeItReachesTheTruck) {
  // A script whose boom stays 15° below the clearance angle would drive the bucket into the
  // truck's side: the truck is in the map, so the look-ahead stops it, short of the truck.
  const testing::Excavator& e = Excavator25t();
  const testing::Truck truck = Truck20t(90 * kDeg, 6.0);
  const ScriptSettings settings;
  ScriptParameters p = ComputeScriptParameters(*e.envelope, e.derivation.models, DigEnd(),
                                               StandardGoal(truck), settings);
  p.boom_clear -= 15 * kDeg;
  p.boom_swing_start = std::min(p.boom_swing_start, p.boom_clear - 3 * kDeg);
  const RunResult unchecked =
      RunPass(BuildLoadingScript(p, settings), e.derivation.models, DigEnd(), settings);
  ASSERT_LT(std::min(MinDistanceTo(unchecked, truck.body), MinDistanceTo(unchecked, truck.cab)),
            0.0);
  const ObstacleLookAhead lookahead(*e.envelope);
  const HeightGrid map = MapWithTruck(truck, 0.1);
  RunOptions options;
  options.lookahead = &lookahead;
  options.map = &map;
  const RunResult run =
      RunPass(BuildLoadingScript(p, settings), e.derivation.models, DigEnd(), settings, options);
  ASSERT_TRUE(run.stopped);
  EXPECT_GT(std::min(MinDistanceTo(run, truck.body), MinDistanceTo(run, truck.cab)), 0.0);
}

TEST(ObstacleLookAhead, UnknownCellsBlockOnlyWhenAskedTo) {
  const testing::Excavator& e = Excavator25t();
  const testing::Truck truck = Truck20t(90 * kDeg, 6.0);
  LoadingScript script = StandardScript(e, truck);
  HeightGrid map = MapWithTruck(truck, 0.1);
  // An unseen patch 4–6 m out at 40°.
  for (int iy = 0; iy < map.ny(); ++iy) {
    for (int ix = 0; ix < map.nx(); ++ix) {
      const Eigen::Vector2d c = map.CellCenter(ix, iy);
      if (c.norm() > 4 && c.norm() < 6 && std::abs(std::atan2(c.y(), c.x()) - 40 * kDeg) < 0.1) {
        map.set_height(ix, iy, std::nan(""));
      }
    }
  }
  const ExcavatorSimulator machine(e.derivation.models, DigEnd());
  LookAheadSettings blocking;
  blocking.unknown_blocks = true;
  const LookAheadResult open =
      ObstacleLookAhead(*e.envelope)
          .Check(DigEnd(), machine, &script, 0.0, map, Eigen::Isometry3d::Identity());
  const LookAheadResult blocked =
      ObstacleLookAhead(*e.envelope, blocking)
          .Check(DigEnd(), machine, &script, 0.0, map, Eigen::Isometry3d::Identity());
  EXPECT_FALSE(open.stop());
  EXPECT_GT(open.unknown_points, 0);
  ASSERT_TRUE(blocked.stop());
  EXPECT_TRUE(std::isnan(blocked.collision->cell_height));
}

TEST(ObstacleLookAhead, ANonFiniteStateStopsAndNeverBecomesACommand) {
  const testing::Excavator& e = Excavator25t();
  const testing::Truck truck = Truck20t(90 * kDeg, 6.0);
  LoadingScript script = StandardScript(e, truck);
  const HeightGrid map = MapWithTruck(truck, 0.1);
  const ExcavatorSimulator machine(e.derivation.models, DigEnd());
  const ObstacleLookAhead lookahead(*e.envelope);
  ExcavatorState bad = DigEnd();
  bad.qd[3] = std::nan("");
  const LookAheadResult result =
      lookahead.Check(bad, machine, &script, 0.0, map, Eigen::Isometry3d::Identity());
  EXPECT_EQ(result.verdict, LookAheadVerdict::kInvalidState);
  EXPECT_TRUE(result.stop());
  EXPECT_NE(result.reason.find("swing"), std::string::npos) << result.reason;
  EXPECT_EQ(lookahead.CheckStop(bad, machine, map, Eigen::Isometry3d::Identity()).verdict,
            LookAheadVerdict::kInvalidState);
  // The script: a NaN position gives a stop with the reason, finite positions, no rule change.
  bad = DigEnd();
  bad.q[1] = std::nan("");
  const ScriptOutput out = script.Step(bad.q);
  EXPECT_TRUE(out.command.stop);
  EXPECT_TRUE(out.command.position.allFinite());
  EXPECT_NE(out.reason.find("stick"), std::string::npos) << out.reason;
  for (ExcavatorJoint joint : kAllExcavatorJoints) EXPECT_EQ(script.active_rule(joint), 0);
}

}  // namespace
}  // namespace autoshovel::control
