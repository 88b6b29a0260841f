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

// The front LiDAR blind straight ahead for 2 s while driving: held like a silent sensor, then
// on again when the sector returns.
TEST(Faults, LidarBlindAheadHoldsTheMachine) {
  ShovelRunOptions o = Options("bin_1");
  FaultSpec blind = Fault(FaultKind::kLidarDeadSector, 2.0, 2.0);
  blind.lidar = "front_solid_state";
  blind.sector_rad = {-20 * M_PI / 180, 20 * M_PI / 180};
  o.faults = {blind};
  const CycleOutcome out = RunOne(o);
  ExpectSafe(o, out);
  EXPECT_TRUE(out.blind_sector);
  EXPECT_TRUE(out.record.completed) << out.failure;
  EXPECT_EQ(out.safe_stops, 1);
  EXPECT_EQ(out.recoveries, 1);
}

// The top LiDAR blind behind the cab while the machine drives forward: seen, logged, and no
// reason to stop.
TEST(Faults, LidarBlindBehindLetsAForwardDriveGoOn) {
  ShovelRunOptions o = Options("bin_1");
  FaultSpec blind = Fault(FaultKind::kLidarDeadSector, 0.0, INFINITY);
  blind.lidar = "top_16";
  blind.sector_rad = {150 * M_PI / 180, 180 * M_PI / 180};
  o.faults = {blind};
  const CycleOutcome out = RunOne(o);
  ExpectSafe(o, out);
  EXPECT_TRUE(out.blind_sector);
  EXPECT_TRUE(out.record.completed) << out.failure;
  EXPECT_EQ(out.safe_stops, 0);
}

// A small blot of dirt on the lens: found, masked, the cycle goes on. A large one masks more
// than a quarter of the view: held until the lens is clean again.
TEST(Faults, SmallLensDirtIsMaskedAndTheCycleGoesOn) {
  ShovelRunOptions o = Options("bin_1");
  FaultSpec dirt = Fault(FaultKind::kCameraLensDirt, 1.0, INFINITY);  // a clean view first
  dirt.center = {0.5, 0.8};
  dirt.radius = 0.08;
  o.faults = {dirt};
  const CycleOutcome out = RunOne(o);
  ExpectSafe(o, out);
  EXPECT_GT(out.masked_fraction, 0.02);  // the blot covers π·38² px = 1.6 % of the image
  EXPECT_LT(out.masked_fraction, 0.25);
  EXPECT_TRUE(out.record.completed) << out.failure;
  EXPECT_EQ(out.safe_stops, 0);
}

TEST(Faults, LargeLensDirtHoldsTheMachineUntilWiped) {
  ShovelRunOptions o = Options("bin_1");
  FaultSpec dirt = Fault(FaultKind::kCameraLensDirt, 1.0, 4.0);
  dirt.center = {0.5, 0.6};
  dirt.radius = 0.25;
  o.faults = {dirt};
  const CycleOutcome out = RunOne(o);
  ExpectSafe(o, out);
  EXPECT_GT(out.masked_fraction, 0.25);
  EXPECT_TRUE(out.record.completed) << out.failure;
  EXPECT_EQ(out.safe_stops, 1);
  EXPECT_EQ(out.recoveries, 1);
}

// The bucket IMU repeats one reading: the bucket looks as if it did not answer its valve; the
// cycle is abandoned with the machine at rest.
TEST(Faults, StuckBucketImuAbandonsTheCycle) {
  ShovelRunOptions o = Options("bin_1");
  FaultSpec stuck = Fault(FaultKind::kImuStuck, 0.0, INFINITY);
  stuck.joint = "bucket";
  o.faults = {stuck};
  const CycleOutcome out = RunOne(o);
  ExpectSafe(o, out);
  EXPECT_FALSE(out.record.completed);
  EXPECT_NE(out.failure.find("bucket does not answer its valve"), std::string::npos) << out.failure;
}

// The boom IMU's bias walks off. Nothing on board measures the boom twice, so a slow drift
// (0.1°/s, 2° by the end of the cycle) is not seen: the bucket rides a few centimetres off
// and the cycle completes. A fast one (1.5°/s) has the joint PID press the bucket into the
// floor to reach the angle it reads: the boom stops moving with its rod side and the pump at
// the pump's limit, a stall under load (issue 39, docs/faults.md), and the approach ends before
// the pile ("stopped before contact: boom_stall"); before issue 39 the supervisor could not
// tell it from a stuck valve and stopped the machine. (At 1°/s the 1.5 m/s attack reaches the
// pile first and the cycle completes with the bucket riding high, fill 0.905.)
TEST(Faults, SlowBoomImuDriftCompletesAFastOneIsStopped) {
  ShovelRunOptions o = Options("bin_1");
  FaultSpec drift = Fault(FaultKind::kImuBiasDrift, 0.0, INFINITY);
  drift.joint = "boom";
  drift.rate_rad_s = 0.1 * M_PI / 180;
  o.faults = {drift};
  const CycleOutcome slow = RunOne(o);
  ExpectSafe(o, slow);
  EXPECT_TRUE(slow.record.completed) << slow.failure;
  EXPECT_GE(slow.record.fill_rate, 0.9);

  o.faults[0].rate_rad_s = 1.5 * M_PI / 180;
  const CycleOutcome fast = RunOne(o);
  ExpectSafe(o, fast);
  EXPECT_FALSE(fast.record.completed);
  EXPECT_NE(fast.failure.find("stopped before contact: boom_stall"), std::string::npos)
      << fast.failure;
}

// Noise of 0.5° on the articulation encoder and the arm angles (five times the encoder's
// rating): the PIDs and the path follower ride it out.
TEST(Faults, EncoderNoiseIsRiddenOut) {
  ShovelRunOptions o = Options("bin_1");
  FaultSpec noise = Fault(FaultKind::kEncoderNoise, 0.0, INFINITY);
  noise.sigma_rad = 0.5 * M_PI / 180;
  o.faults = {noise};
  const CycleOutcome out = RunOne(o);
  ExpectSafe(o, out);
  EXPECT_TRUE(out.record.completed) << out.failure;
  EXPECT_GE(out.record.fill_rate, 0.9);
}

// Every valve 50 % slower to answer than identified: the cycle completes; the volume trigger,
// which predicts with the identified delay, fires late and the fill may overshoot.
TEST(Faults, HydraulicDelayDriftStillCompletes) {
  ShovelRunOptions o = Options("bin_1");
  FaultSpec slow = Fault(FaultKind::kHydraulicDelayDrift, 0.0, INFINITY);
  slow.factor = 1.5;
  o.faults = {slow};
  const CycleOutcome out = RunOne(o);
  ExpectSafe(o, out);
  EXPECT_TRUE(out.record.completed) << out.failure;
  EXPECT_GE(out.record.fill_rate, 0.9);
}

// Every second LiDAR frame arrives 0.3 s late: refused (never fused at the wrong pose), and
// the frames in order keep the watchdog fed (0.29 s apart < 0.5 s): no stop.
TEST(Faults, LateLidarFramesAreRefusedWithoutAStop) {
  ShovelRunOptions o = Options("bin_1");
  FaultSpec late = Fault(FaultKind::kTimestampsOutOfOrder, 0.0, INFINITY);
  late.sensor = "lidar";
  late.lag_s = 0.3;
  o.faults = {late};
  const CycleOutcome out = RunOne(o);
  ExpectSafe(o, out);
  EXPECT_TRUE(out.record.completed) << out.failure;
  // Half the 7 Hz frames of ≈ 5 s of selecting and driving (the map is not updated while the
  // bucket is in the pile).
  EXPECT_GE(out.refused_frames, 12);
  EXPECT_EQ(out.safe_stops, 0);
}

TEST(Faults, ADeadSectorOfAnUnknownLidarIsRefused) {
  ShovelRunOptions o = Options("bin_1");
  FaultSpec blind = Fault(FaultKind::kLidarDeadSector, 0.0, INFINITY);
  blind.lidar = "roof_lidar";
  blind.where = "faults.yaml:3";
  o.faults = {blind};
  try {
    ShovelJob job(o);
    FAIL() << "accepted a LiDAR the machine does not have";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("faults.yaml:3: lidar_dead_sector"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("top_16, front_solid_state"), std::string::npos)
        << e.what();
  }
}

// --- The supervisor's rules on their own ---

TEST(SafetySupervisor, FramesOutOfOrderOrTooOldAreRefused) {
  SafetySupervisor s;
  EXPECT_TRUE(s.AcceptFrame(SensorStream::kLidar, 1.0, 1.0));
  EXPECT_FALSE(s.AcceptFrame(SensorStream::kLidar, 0.9, 1.1));  // older than the newest used
  EXPECT_FALSE(s.AcceptFrame(SensorStream::kLidar, 1.0, 1.1));  // the same frame again
  EXPECT_TRUE(s.AcceptFrame(SensorStream::kCamera, 0.9, 1.1));  // each sensor has its own order
  EXPECT_FALSE(s.AcceptFrame(SensorStream::kLidar, 1.2, 1.8));  // in order, but 0.6 s old
  EXPECT_FALSE(s.AcceptFrame(SensorStream::kLidar, std::nan(""), 1.8));
  EXPECT_EQ(s.refused_frames(), 4);
  // Refused frames do not feed the watchdog: the LiDAR's newest used frame is still t = 1.0.
  EXPECT_NE(s.StaleSensors(1.8).find("LiDAR silent for 0.80 s"), std::string::npos);
}

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
  // No pressure reading (NaN): a stall cannot be told, so every unanswered joint is a fault.
  auto check = [](SafetySupervisor& supervisor, int joint, const char* name, double time,
                  double valve, double q, double qd) {
    return supervisor
        .CheckJoint(joint, name, time, {.valve = valve, .q = q, .qd = qd},
                    {.q_min = -1.0, .q_max = 1.0, .stall = {}})
        .message;
  };
  SafetySupervisor s;
  // Open, not moving, away from its limits: 2 s later it is reported.
  EXPECT_EQ(check(s, 0, "boom", 0.0, 0.8, 0.5, 0.0), "");
  EXPECT_EQ(check(s, 0, "boom", 1.9, 0.8, 0.5, 0.0), "");
  EXPECT_NE(check(s, 0, "boom", 2.0, 0.8, 0.5, 0.0).find("boom does not answer"),
            std::string::npos);
  // At its upper limit, commanded up: resting there is right.
  SafetySupervisor t;
  for (double time = 0; time < 5; time += 0.05) {
    EXPECT_EQ(check(t, 1, "bucket", time, 0.8, 0.98, 0.0), "");
  }
  // Moving, or a small opening: never.
  for (double time = 0; time < 5; time += 0.05) {
    EXPECT_EQ(check(t, 0, "boom", time, 0.8, 0.0, 0.1), "");
    EXPECT_EQ(check(t, 1, "bucket", time, 0.1, 0.0, 0.0), "");
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

TEST(FaultSpecFile, ReadsTheSensorAndActuatorKinds) {
  const std::string path = Write("faults_sensors.yaml", R"(faults:
  - kind: lidar_dead_sector
    lidar: top_16
    sector_deg: [-10, 20]
  - kind: camera_lens_dirt
    center: [0.5, 0.7]
    radius: 0.15
  - kind: imu_bias_drift
    joint: boom
    rate_deg_s: 0.5
  - kind: imu_stuck
    joint: bucket
  - kind: encoder_noise
    sigma_deg: 1.0
  - kind: hydraulic_delay_drift
    factor: 1.5
  - kind: timestamps_out_of_order
    sensor: camera
    lag_s: 0.3
)");
  const std::vector<FaultSpec> f = plant::LoadFaults(path);
  ASSERT_EQ(f.size(), 7u);
  EXPECT_EQ(f[0].kind, FaultKind::kLidarDeadSector);
  EXPECT_EQ(f[0].lidar, "top_16");
  EXPECT_NEAR(f[0].sector_rad.x(), -10 * M_PI / 180, 1e-12);
  EXPECT_NEAR(f[0].sector_rad.y(), 20 * M_PI / 180, 1e-12);
  EXPECT_EQ(f[1].center, Eigen::Vector2d(0.5, 0.7));
  EXPECT_EQ(f[1].radius, 0.15);
  EXPECT_NEAR(f[2].rate_rad_s, 0.5 * M_PI / 180, 1e-12);
  EXPECT_EQ(f[3].kind, FaultKind::kImuStuck);
  EXPECT_EQ(f[3].joint, "bucket");
  EXPECT_NEAR(f[4].sigma_rad, M_PI / 180, 1e-12);
  EXPECT_EQ(f[5].factor, 1.5);
  EXPECT_EQ(f[6].sensor, "camera");
  EXPECT_EQ(f[6].lag_s, 0.3);
  EXPECT_STREQ(plant::ToString(f[6].kind), "timestamps_out_of_order");
}

TEST(FaultSpecFile, BadEntriesAreLocated) {
  ExpectError("faults:\n  - kind: lidar_dead_sector\n    lidar: a\n    sector_deg: [20, 10]\n",
              ":4:");
  ExpectError("faults:\n  - kind: camera_lens_dirt\n    center: [0.5, 1.5]\n    radius: 0.1\n",
              ":3:");
  ExpectError("faults:\n  - kind: hydraulic_delay_drift\n    factor: 0\n", ":3:");
  ExpectError("faults:\n  - kind: timestamps_out_of_order\n    sensor: radar\n    lag_s: 1\n",
              ":3:");
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
