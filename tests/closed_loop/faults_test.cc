// Issue 9, item 1: injected faults and what the main job's safety supervisor does about each
// (docs/faults.md). One short cycle per fault on the simulated yard; simulator labels stand in
// for the segmentation network to keep each at a few seconds.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "runtime/app/safety_supervisor.h"
#include "runtime/app/shovel_run.h"
#include "runtime/core/diagnostics.h"
#include "runtime/plant/fault_spec.h"
#include "tests/closed_loop/cycle_runner.h"

namespace autoshovel::app {
namespace {

using plant::FaultKind;
using plant::FaultSpec;

ShovelRunOptions Options(const std::string& bin) {
  ShovelRunOptions o = TestCycleOptions("mixing_station");
  o.bins = {bin};
  return o;
}

CycleOutcome RunOne(const ShovelRunOptions& options) { return RunTestCycle(options); }

// Every faulty cycle: no safety violation, and a stop that began at speed v ends within the
// braking distance v² / 2a of the speed profile (1 m/s²) plus a 20 Hz period's travel.
void ExpectSafe(const ShovelRunOptions& options, const CycleOutcome& out) {
  EXPECT_EQ(out.record.safety_violations, 0);
  EXPECT_GE(out.record.safety_margin_m, options.safety_distance);
  const double v = out.speed_at_stop;
  EXPECT_LE(out.stop_travel_m, v * v / 2.0 + v / 20 + 0.05);
}

FaultSpec Fault(FaultKind kind, double start_s, double duration_s) {
  FaultSpec f;
  f.kind = kind;
  f.start_s = start_s;
  f.duration_s = duration_s;
  f.where = "test";
  return f;
}

// The watchdog: a LiDAR silent for 2 s while driving to the pile holds the machine stopped;
// when frames come back it drives on and the cycle completes.
TEST(Faults, LidarDropoutHoldsTheMachineUntilFramesReturn) {
  ShovelRunOptions o = Options("bin_1");
  o.faults = {Fault(FaultKind::kLidarDropout, 2.0, 2.0)};
  const CycleOutcome out = RunOne(o);
  ExpectSafe(o, out);
  EXPECT_TRUE(out.record.completed) << out.failure;
  EXPECT_EQ(out.safe_stops, 1);
  EXPECT_EQ(out.recoveries, 1);
  EXPECT_GT(out.speed_at_stop, 0.1);  // it was moving when the watchdog stopped it
  EXPECT_GE(out.record.fill_rate, 0.95);
}

TEST(Faults, CameraBlackoutHoldsTheMachineUntilImagesReturn) {
  ShovelRunOptions o = Options("bin_1");
  o.faults = {Fault(FaultKind::kCameraBlackout, 2.0, 3.0)};
  const CycleOutcome out = RunOne(o);
  ExpectSafe(o, out);
  EXPECT_TRUE(out.record.completed) << out.failure;
  EXPECT_EQ(out.safe_stops, 1);
  EXPECT_EQ(out.recoveries, 1);
}

// A jump of the pose estimate (1 m, 10°) while driving: the cycle is abandoned, the machine
// brakes to rest.
TEST(Faults, LocalisationJumpAbandonsTheCycle) {
  ShovelRunOptions o = Options("bin_1");
  FaultSpec jump = Fault(FaultKind::kLocalisationJump, 3.0, INFINITY);
  jump.offset_m = {1.0, 0.0};
  jump.heading_rad = 10 * M_PI / 180;
  o.faults = {jump};
  const CycleOutcome out = RunOne(o);
  ExpectSafe(o, out);
  EXPECT_FALSE(out.record.completed);
  EXPECT_NE(out.failure.find("localisation jumped 1.00 m and 10.0 deg"), std::string::npos)
      << out.failure;
  EXPECT_EQ(out.safe_stops, 1);
  EXPECT_EQ(out.recoveries, 0);
}

// A jammed boom spool: the boom does not answer its valve during the scoop; the cycle is
// abandoned with the machine at rest.
TEST(Faults, StuckBoomValveAbandonsTheCycle) {
  ShovelRunOptions o = Options("bin_1");
  FaultSpec stuck = Fault(FaultKind::kStuckValve, 0.0, INFINITY);
  stuck.joint = "boom";
  o.faults = {stuck};
  const CycleOutcome out = RunOne(o);
  ExpectSafe(o, out);
  EXPECT_FALSE(out.record.completed);
  EXPECT_NE(out.failure.find("boom does not answer its valve"), std::string::npos) << out.failure;
}

// Sand reported as gravel: the machine cannot tell; it scoops with gravel's choices, safely.
TEST(Faults, MistypedMaterialIsScoopedSafely) {
  ShovelRunOptions o = Options("bin_4");
  FaultSpec typo = Fault(FaultKind::kMaterialMistyped, 0.0, INFINITY);
  typo.reported = "big_gravel";
  o.faults = {typo};
  const CycleOutcome out = RunOne(o);
  ExpectSafe(o, out);
  EXPECT_TRUE(out.record.completed) << out.failure;
  EXPECT_EQ(out.record.material, "big_gravel");
  EXPECT_EQ(out.safe_stops, 0);
}

// A person steps onto the path 10 m ahead of the front axle: the machine stops short of them
// (never within the safety distance) and waits; the cycle ends at its time limit.
TEST(Faults, PersonOnThePathStopsTheMachineShortOfThem) {
  ShovelRunOptions o = Options("bin_1");
  FaultSpec person = Fault(FaultKind::kPersonEntersPath, 1.0, INFINITY);
  person.ahead_m = 10.0;
  o.faults = {person};
  o.max_cycle_time = 15.0;
  const CycleOutcome out = RunOne(o);
  ExpectSafe(o, out);
  EXPECT_FALSE(out.record.completed);
  EXPECT_NE(out.failure.find("not complete within 15 s"), std::string::npos) << out.failure;
  EXPECT_GE(out.safe_stops, 1);
  EXPECT_LT(out.record.safety_margin_m, 4.0);  // it did come towards them
}

// --- The supervisor's rules on their own ---

TEST(SafetySupervisor, WatchdogNamesTheSilentSensor) {
  SafetySupervisor s;
  EXPECT_NE(s.StaleSensors(0.0).find("LiDAR silent for the whole cycle"), std::string::npos);
  s.LidarFrame(1.0);
  s.CameraFrame(1.0);
  EXPECT_EQ(s.StaleSensors(1.5), "");
  EXPECT_EQ(s.StaleSensors(1.51), "LiDAR silent for 0.51 s, camera silent for 0.51 s");
  s.CameraFrame(1.5);
  EXPECT_EQ(s.StaleSensors(1.6), "LiDAR silent for 0.60 s");
}

TEST(SafetySupervisor, PoseStepsBeyondTheSpeedAreJumps) {
  SafetySupervisor s;
  EXPECT_EQ(s.CheckPose(0.00, {0, 0}, 0.0, 2.0), "");
  EXPECT_EQ(s.CheckPose(0.01, {0.02, 0}, 0.0, 2.0), "");    // 2 m/s × 10 ms
  EXPECT_EQ(s.CheckPose(0.02, {0.32, 0}, 0.004, 2.0), "");  // + 0.28 m of noise: within 0.3 m
  EXPECT_NE(s.CheckPose(0.03, {1.32, 0}, 0.004, 2.0), "");  // 1 m
  EXPECT_NE(s.CheckPose(0.04, {1.34, 0}, 0.2, 2.0), "");    // 11°
  EXPECT_EQ(s.CheckPose(0.05, {1.36, 0}, 0.2, 2.0), "");    // steady again
}

TEST(SafetySupervisor, AJointThatDoesNotAnswerItsValve) {
  SafetySupervisor s;
  // Open, not moving, away from its limits: 2 s later it is reported.
  EXPECT_EQ(s.CheckJoint(0, "boom", 0.0, 0.8, 0.5, 0.0, -1.0, 1.0), "");
  EXPECT_EQ(s.CheckJoint(0, "boom", 1.9, 0.8, 0.5, 0.0, -1.0, 1.0), "");
  EXPECT_NE(s.CheckJoint(0, "boom", 2.0, 0.8, 0.5, 0.0, -1.0, 1.0).find("boom does not answer"),
            std::string::npos);
  // At its upper limit, commanded up: resting there is right.
  SafetySupervisor t;
  for (double time = 0; time < 5; time += 0.05) {
    EXPECT_EQ(t.CheckJoint(1, "bucket", time, 0.8, 0.98, 0.0, -1.0, 1.0), "");
  }
  // Moving, or a small opening: never.
  for (double time = 0; time < 5; time += 0.05) {
    EXPECT_EQ(t.CheckJoint(0, "boom", time, 0.8, 0.0, 0.1, -1.0, 1.0), "");
    EXPECT_EQ(t.CheckJoint(1, "bucket", time, 0.1, 0.0, 0.0, -1.0, 1.0), "");
  }
  s.Stop("x");
  s.Stop("y");
  s.Resume();
  EXPECT_EQ(s.safe_stops(), 1);
  EXPECT_EQ(s.recoveries(), 1);
}

// --- The faults list of scenario and campaign files ---

std::string Write(const std::string& name, const std::string& text) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << text;
  return path.string();
}

TEST(FaultSpecFile, ReadsEveryKind) {
  const std::string path = Write("faults_ok.yaml", R"(faults:
  - kind: lidar_dropout
    start_s: 2.0
    duration_s: 1.5
    cycles: [0, 2]
  - kind: camera_blackout
  - kind: localisation_jump
    start_s: 3.0
    offset_m: [1.0, -0.5]
    heading_deg: 10
  - kind: stuck_valve
    joint: bucket
  - kind: material_mistyped
    reported: big_gravel
  - kind: person_enters_path
    ahead_m: 7.0
)");
  const std::vector<FaultSpec> f = plant::LoadFaults(path);
  ASSERT_EQ(f.size(), 6u);
  EXPECT_EQ(f[0].kind, FaultKind::kLidarDropout);
  EXPECT_TRUE(f[0].ActiveAt(2, 3.0));
  EXPECT_FALSE(f[0].ActiveAt(1, 3.0));  // not its cycle
  EXPECT_FALSE(f[0].ActiveAt(0, 3.5));  // over
  EXPECT_TRUE(f[1].ActiveAt(7, 1e6));   // every cycle, all the time
  EXPECT_NEAR(f[2].heading_rad, 10 * M_PI / 180, 1e-12);
  EXPECT_EQ(f[2].offset_m, Eigen::Vector2d(1.0, -0.5));
  EXPECT_EQ(f[3].joint, "bucket");
  EXPECT_EQ(f[4].reported, "big_gravel");
  EXPECT_EQ(f[5].ahead_m, 7.0);
  EXPECT_EQ(f[5].where, path + ":15");
}

void ExpectError(const std::string& yaml, const std::string& expected) {
  const std::string path = Write("faults_bad.yaml", yaml);
  try {
    plant::LoadFaults(path);
    ADD_FAILURE() << "accepted: " << yaml;
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos)
        << "got: " << e.what() << "\nexpected: " << expected;
  }
}

TEST(FaultSpecFile, BadEntriesAreLocated) {
  ExpectError("faults:\n  - kind: lidar_drop\n", ":2:");
  ExpectError("faults:\n  - kind: lidar_drop\n", "lidar_dropout");
  ExpectError("faults:\n  - kind: lidar_dropout\n    start_s: -1\n", ":3:");
  ExpectError("faults:\n  - kind: lidar_dropout\n    joint: boom\n", ":3:");  // another kind's
  ExpectError("faults:\n  - kind: stuck_valve\n", "joint");
  ExpectError("faults:\n  - kind: lidar_dropout\n    cycles: [a]\n", "cycle indices");
  ExpectError("faults: []\nextra: 1\n", "extra");
  ExpectError("other: 1\n", "faults");
}

}  // namespace
}  // namespace autoshovel::app
