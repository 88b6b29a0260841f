// Whole loading passes (seed §4.4, Fig. 14) with the joint models as the machine: integrated at
// 100 Hz, the script evaluated at 10 Hz, its parameters computed before the pass from the dig
// point, the dump point and a 20 t truck beside the excavator.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>

#include "excavator_test_support.h"

namespace autoshovel::control {
namespace {

using testing::DigEnd;
using testing::Excavator25t;
using testing::kDeg;
using testing::RunPass;
using testing::RunResult;
using testing::StandardGoal;
using testing::Truck20t;

void PrintParameters(const char* name, const ScriptParameters& p) {
  std::printf(
      "[figure] %s parameters [deg]: swing start %.1f dump %.1f dig %.1f | boom clear %.1f dig "
      "%.1f | stick start %.1f spill %.1f dump %.1f dig %.1f | bucket carry %.1f open %.1f dig "
      "%.1f | LHS: boom for swing %.1f, swing for stick %.1f, swing for bucket %.1f, bucket for "
      "sweep %.1f, bucket dumped %.1f, swing return %.1f | pin %.2f m, must clear %.2f m, "
      "predicted pass %.2f s, predicted min clearance %.3f m, return height %.3f m\n",
      name, p.swing_start / kDeg, p.swing_dump / kDeg, p.swing_dig / kDeg, p.boom_clear / kDeg,
      p.boom_dig / kDeg, p.stick_start / kDeg, p.stick_spill / kDeg, p.stick_dump / kDeg,
      p.stick_dig / kDeg, p.bucket_carry / kDeg, p.bucket_open / kDeg, p.bucket_dig / kDeg,
      p.boom_swing_start / kDeg, p.swing_stick_out / kDeg, p.swing_bucket_open / kDeg,
      p.bucket_sweep / kDeg, p.bucket_dumped / kDeg, p.swing_return / kDeg, p.dump_pin_height,
      p.clearance_height, p.predicted_pass_time, p.predicted_min_truck_clearance,
      p.predicted_min_return_height);
}

/// The lowest 3-D distance of the underside to the boxes over a run (at most 0.021 m over).
double RunClearance(const RunResult& run, const std::vector<ObstacleBox>& boxes) {
  return testing::MinUndersideDistance(run.samples, boxes);
}

/// The standard pass (dig 7 m ahead, truck at 90°) with and without the swing/raise overlap,
/// computed and run once for all tests below.
struct StandardPasses {
  testing::Truck truck = Truck20t(90 * kDeg, 6.0);
  ScriptSettings settings, sequential_settings;
  ScriptParameters params, sequential;
  RunResult run, sequential_run;
  double compute_ms = 0;
};

const StandardPasses& Standard() {
  static const StandardPasses* const passes = [] {
    auto* s = new StandardPasses;
    const testing::Excavator& e = Excavator25t();
    const auto t0 = std::chrono::steady_clock::now();
    s->params = ComputeScriptParameters(*e.envelope, e.derivation.models, DigEnd(),
                                        StandardGoal(s->truck), s->settings);
    s->compute_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    s->sequential_settings.overlap_swing_and_raise = false;
    s->sequential = ComputeScriptParameters(*e.envelope, e.derivation.models, DigEnd(),
                                            StandardGoal(s->truck), s->sequential_settings);
    s->run = RunPass(BuildLoadingScript(s->params, s->settings), e.derivation.models, DigEnd(),
                     s->settings);
    s->sequential_run = RunPass(BuildLoadingScript(s->sequential, s->sequential_settings),
                                e.derivation.models, DigEnd(), s->sequential_settings);
    return s;
  }();
  return *passes;
}

TEST(LoadingPass, CompletesDigToDumpToDigAndEveryJointReachesItsCommands) {
  const StandardPasses& s = Standard();
  PrintParameters("standard", s.params);
  std::printf("[figure] parameters computed in %.1f ms\n%s", s.compute_ms,
              BuildLoadingScript(s.params, s.settings).Describe().c_str());
  ASSERT_TRUE(s.run.finished);
  const double eps = s.settings.arrival_tolerance;
  // At the end every joint is at its dig command, at rest.
  const ExcavatorState& end = s.run.samples.back().state;
  const JointVector dig(s.params.boom_dig, s.params.stick_dig, s.params.bucket_dig,
                        s.params.swing_dig);
  EXPECT_LT((end.q - dig).cwiseAbs().maxCoeff(), eps);
  // The tip ends the dig approach height above the dig point.
  const Eigen::Vector3d tip = Excavator25t().kinematics->TipPosition(end.q);
  EXPECT_LT((tip - Eigen::Vector3d(7.0, 0.0, s.settings.dig_approach_height)).norm(), 0.35);
  // Every rule that moves its joint gets the joint to within ε of its command while active.
  const LoadingScript script = BuildLoadingScript(s.params, s.settings);
  for (ExcavatorJoint joint : kAllExcavatorJoints) {
    const int j = JointIndex(joint);
    const std::vector<ScriptRule>& rules = script.script(joint).rules;
    for (std::size_t r = 0; r < rules.size(); ++r) {
      double closest = 1e9;
      bool active = false;
      for (const testing::RunSample& sample : s.run.samples) {
        if (sample.active_rule[j] != static_cast<int>(r)) continue;
        active = true;
        closest = std::min(closest, std::abs(sample.state.q[j] - rules[r].command));
      }
      EXPECT_TRUE(active) << JointName(joint) << " rule " << r + 1;
      EXPECT_LT(closest, eps) << JointName(joint) << " rule " << r + 1 << " (" << rules[r].action
                              << ")";
    }
  }
  // The load is over the dump point when the bucket opens: the pin within 0.3 m horizontally.
  for (const testing::RunSample& sample : s.run.samples) {
    if (sample.active_rule[JointIndex(ExcavatorJoint::kBucket)] == 1) {
      const ArmPlanePins pins = Excavator25t().kinematics->Pins(sample.state.q);
      const Eigen::Vector3d pin = ExcavatorKinematics::BaseFromArmPlane(pins.swing, pins.pins[2]);
      EXPECT_LT((pin.head<2>() - s.truck.body.center).norm(), 0.5);
      break;
    }
  }
  std::printf("[figure] standard pass: %.2f s simulated, %.2f s predicted\n", s.run.finish_time,
              s.params.predicted_pass_time);
  // The prediction the parameters were computed with is the machine's own behaviour.
  EXPECT_NEAR(s.run.finish_time, s.params.predicted_pass_time, 0.2);
}

TEST(LoadingPass, OneRulePerJointIsActiveAndRulesAdvanceInOrderAtTenHertz) {
  const StandardPasses& s = Standard();
  const LoadingScript script = BuildLoadingScript(s.params, s.settings);
  std::array<int, kNumExcavatorJoints> previous{};
  double previous_change = -1;
  for (const testing::RunSample& sample : s.run.samples) {
    for (int j = 0; j < kNumExcavatorJoints; ++j) {
      const int rule = sample.active_rule[j];
      // The active rule is a single index that only moves on, one rule per evaluation.
      ASSERT_GE(rule, previous[j]);
      ASSERT_LE(rule, previous[j] + 1);
      // The command sent is the active rule's.
      EXPECT_EQ(sample.command[j], script.script(kAllExcavatorJoints[j]).rules[rule].command);
      if (rule != previous[j]) {
        // Changes happen on 10 Hz evaluations only: the sample right after one (0.01 s later).
        const double since_tick = std::fmod(sample.time - 0.01 + 1e-9, LoadingScript::kPeriod);
        EXPECT_LT(since_tick, 1e-6) << "rule change at " << sample.time;
        previous_change = sample.time;
      }
      previous[j] = rule;
    }
  }
  EXPECT_GT(previous_change, 0);
  for (ExcavatorJoint joint : kAllExcavatorJoints) {
    EXPECT_EQ(previous[JointIndex(joint)] + 1, static_cast<int>(script.script(joint).rules.size()));
  }
}

TEST(LoadingPass, SwingOverlapsTheRaiseYetTheLinkageClearsTheTruckIn3D) {
  const StandardPasses& s = Standard();
  const int boom = JointIndex(ExcavatorJoint::kBoom), swing = JointIndex(ExcavatorJoint::kSwing);
  // The swing is already moving while the boom is still well short of its clearance angle.
  double boom_when_swinging = -1;
  for (const testing::RunSample& sample : s.run.samples) {
    if (std::abs(sample.state.qd[swing]) > 0.01) {
      boom_when_swinging = sample.state.q[boom];
      break;
    }
  }
  ASSERT_GT(boom_when_swinging, -1);
  EXPECT_LT(boom_when_swinging, s.params.boom_clear - 10 * kDeg);
  const double clearance = RunClearance(s.run, s.truck.boxes());
  std::printf(
      "[figure] standard pass: swing moving at boom %.1f° (clearance angle %.1f°); min "
      "3-D clearance to the truck %.3f m (margin %.2f m)\n",
      boom_when_swinging / kDeg, s.params.boom_clear / kDeg, clearance, s.settings.truck_clearance);
  EXPECT_GE(clearance, s.settings.truck_clearance - 0.01);
  EXPECT_NEAR(clearance, s.params.predicted_min_truck_clearance, 0.04);
}

TEST(LoadingPass, ATruckNearTheDigDelaysTheSwingJustEnough) {
  // The truck 50° from the dig: swinging at once would put the rising bucket into the body's
  // near corner, so the swing-start threshold binds between the dig-end and clearance angles.
  const testing::Excavator& e = Excavator25t();
  const testing::Truck truck = Truck20t(50 * kDeg, 5.8);
  const LoadingGoal goal = StandardGoal(truck);
  const ScriptSettings settings;
  const ScriptParameters p =
      ComputeScriptParameters(*e.envelope, e.derivation.models, DigEnd(), goal, settings);
  PrintParameters("near truck", p);
  EXPECT_GT(p.boom_swing_start, DigEnd().q[0] + 3 * kDeg);
  EXPECT_LT(p.boom_swing_start, p.boom_clear - 5 * kDeg);
  const RunResult run =
      RunPass(BuildLoadingScript(p, settings), e.derivation.models, DigEnd(), settings);
  ASSERT_TRUE(run.finished);
  const double clearance = RunClearance(run, goal.truck);
  EXPECT_GE(clearance, settings.truck_clearance - 0.01);
  // Without the coupling the bucket would not clear: swinging as soon as the boom moves.
  ScriptParameters eager = p;
  eager.boom_swing_start = DigEnd().q[0] + 0.2 * kDeg;
  const RunResult eager_run =
      RunPass(BuildLoadingScript(eager, settings), e.derivation.models, DigEnd(), settings);
  const double eager_clearance = RunClearance(eager_run, goal.truck);
  std::printf(
      "[figure] truck 50° from the dig: swing starts at boom %.1f° (dig end %.1f°, "
      "clearance %.1f°), min clearance %.3f m; swinging at once: %.3f m\n",
      p.boom_swing_start / kDeg, DigEnd().q[0] / kDeg, p.boom_clear / kDeg, clearance,
      eager_clearance);
  EXPECT_LT(eager_clearance, settings.truck_clearance - 0.05);
}

TEST(LoadingPass, WaitingForTheFullRaiseTakesLonger) {
  const StandardPasses& s = Standard();
  ASSERT_TRUE(s.sequential_run.finished);
  const int boom = JointIndex(ExcavatorJoint::kBoom), swing = JointIndex(ExcavatorJoint::kSwing);
  for (const testing::RunSample& sample : s.sequential_run.samples) {
    if (std::abs(sample.state.qd[swing]) > 1e-3) {
      EXPECT_GT(sample.state.q[boom], s.sequential.boom_clear - s.settings.arrival_tolerance);
      break;
    }
  }
  const double clearance = RunClearance(s.sequential_run, s.truck.boxes());
  std::printf(
      "[figure] pass time with swing/raise overlap %.2f s, waiting for the full raise "
      "%.2f s (min clearance %.3f m)\n",
      s.run.finish_time, s.sequential_run.finish_time, clearance);
  EXPECT_GT(s.sequential_run.finish_time, s.run.finish_time + 1.0);
  EXPECT_GE(clearance, s.settings.truck_clearance - 0.01);
}

TEST(LoadingPass, RandomGoalsOnBothSidesCompleteAndClearTheTruck) {
  const testing::Excavator& e = Excavator25t();
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const ScriptSettings settings;
  double worst = 1e9, slowest = 0, fastest = 1e9, max_compute_ms = 0;
  int overlapped = 0;
  constexpr int kTrials = 10;
  for (int trial = 0; trial < kTrials; ++trial) {
    const double side = trial % 2 == 0 ? 1.0 : -1.0;
    const double dig_azimuth = (-15 + 30 * u(rng)) * kDeg;
    const double truck_azimuth = dig_azimuth + side * (65 + 50 * u(rng)) * kDeg;
    const testing::Truck truck = Truck20t(truck_azimuth, 5.6 + 1.2 * u(rng), side);
    LoadingGoal goal;
    const double dig_radius = 6.0 + 2.0 * u(rng);
    goal.p_base_dig =
        Eigen::Vector3d(dig_radius * std::cos(dig_azimuth), dig_radius * std::sin(dig_azimuth), 0);
    // A dump point anywhere in the body at least 0.9 m from its walls, on a 1.5–2.4 m heap.
    const Eigen::Vector2d local((-1.9 + 3.8 * u(rng)), (-0.35 + 0.7 * u(rng)));
    const Eigen::Vector2d dump = truck.body.center + Eigen::Rotation2Dd(truck.body.yaw) * local;
    goal.p_base_dump = Eigen::Vector3d(dump.x(), dump.y(), 1.5 + 0.9 * u(rng));
    goal.truck = truck.boxes();
    goal.ground_height = 0.0;
    const ExcavatorState start = DigEnd(dig_azimuth + side * (-5 + 10 * u(rng)) * kDeg);
    SCOPED_TRACE("trial " + std::to_string(trial));
    const auto t0 = std::chrono::steady_clock::now();
    const ScriptParameters p =
        ComputeScriptParameters(*e.envelope, e.derivation.models, start, goal, settings);
    max_compute_ms = std::max(
        max_compute_ms,
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    EXPECT_EQ(p.direction, side);
    const RunResult run =
        RunPass(BuildLoadingScript(p, settings), e.derivation.models, start, settings);
    ASSERT_TRUE(run.finished);
    const double clearance = RunClearance(run, goal.truck);
    // The prediction the parameters rest on is what the machine does.
    EXPECT_NEAR(clearance, p.predicted_min_truck_clearance, 0.04);
    EXPECT_GE(clearance, settings.truck_clearance - 0.01);
    worst = std::min(worst, clearance);
    slowest = std::max(slowest, run.finish_time);
    fastest = std::min(fastest, run.finish_time);
    if (p.boom_swing_start < p.boom_clear - 5 * kDeg) ++overlapped;
  }
  std::printf(
      "[figure] %d random passes (truck 65–115° either side, 5.6–6.8 m out): pass time "
      "%.2f–%.2f s, min 3-D clearance %.3f m, %d of them swing before the full raise; "
      "parameters in at most %.1f ms\n",
      kTrials, fastest, slowest, worst, overlapped, max_compute_ms);
  EXPECT_GT(overlapped, kTrials / 2);
}

TEST(LoadingPass, UnreachableOrMeaninglessGoalsAreRejectedWithAReason) {
  const testing::Excavator& e = Excavator25t();
  const testing::Truck truck = Truck20t(90 * kDeg, 6.0);
  auto compute = [&](const LoadingGoal& goal) {
    return ComputeScriptParameters(*e.envelope, e.derivation.models, DigEnd(), goal);
  };
  LoadingGoal far = StandardGoal(truck);
  far.p_base_dig = Eigen::Vector3d(15, 0, 0);
  EXPECT_THROW(compute(far), std::invalid_argument);
  LoadingGoal same = StandardGoal(truck);
  same.p_base_dump = Eigen::Vector3d(6, 0.05, 2.0);
  EXPECT_THROW(compute(same), std::invalid_argument);
  LoadingGoal nan = StandardGoal(truck);
  nan.p_base_dump.x() = std::nan("");
  try {
    compute(nan);
    ADD_FAILURE() << "NaN dump point accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("dump"), std::string::npos) << error.what();
  }
  LoadingGoal tall = StandardGoal(truck);
  tall.truck[0].z_max = 9.0;  // no boom angle clears a 9 m wall
  EXPECT_THROW(compute(tall), std::invalid_argument);
  ExcavatorState bad = DigEnd();
  bad.q[0] = std::nan("");
  EXPECT_THROW(ComputeScriptParameters(*e.envelope, e.derivation.models, bad, StandardGoal(truck)),
               std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::control
