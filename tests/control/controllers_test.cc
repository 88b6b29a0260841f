// Stop detector (seed §6.2), joint PID with dead-zone compensation on the plant, speed profile.
#include <gtest/gtest.h>

#include <cmath>

#include "runtime/control/joint_pid.h"
#include "runtime/control/speed_pid.h"
#include "runtime/control/stop_detector.h"
#include "runtime/plant/plant.h"
#include "runtime/plant/valve_command.h"
#include "tests/control/control_test_support.h"

namespace autoshovel::control {
namespace {

// Seed §6.2: below 0.15 m/s the confidence rises by (0.1 − v)·100 per cycle; at 100 the stop.
TEST(StopDetector, StandingStillConfirmsAfterTenCycles) {
  StopDetector stop;
  for (int i = 1; i <= 9; ++i) {
    EXPECT_FALSE(stop.Update(0.0)) << i;
    EXPECT_DOUBLE_EQ(stop.confidence(), 10.0 * i);
  }
  EXPECT_TRUE(stop.Update(0.0));
  EXPECT_DOUBLE_EQ(stop.confidence(), 100.0);
}

TEST(StopDetector, ExactIncrementsAndResetAbove015) {
  StopDetector stop;
  stop.Update(0.05);  // +5
  stop.Update(0.02);  // +8
  EXPECT_NEAR(stop.confidence(), 13.0, 1e-12);
  stop.Update(0.12);  // (0.1 − 0.12)·100 = −2: decays, as written
  EXPECT_NEAR(stop.confidence(), 11.0, 1e-12);
  stop.Update(0.15);  // not above 0.15: −5
  EXPECT_NEAR(stop.confidence(), 6.0, 1e-12);
  stop.Update(0.1500001);  // above: reset
  EXPECT_DOUBLE_EQ(stop.confidence(), 0.0);
  stop.Update(0.14);  // −4 from 0: held at 0 (our reading)
  EXPECT_DOUBLE_EQ(stop.confidence(), 0.0);
  // 0.09 m/s gives +1 per cycle: 100 cycles to a stop.
  for (int i = 0; i < 99; ++i) EXPECT_FALSE(stop.Update(0.09));
  EXPECT_TRUE(stop.Update(0.09));
  EXPECT_TRUE(stop.Update(-0.01));  // rolling back slowly: |v| = 0.01, still stopped
  EXPECT_FALSE(stop.Update(-0.2));  // |v| above 0.15
}

TEST(StopDetector, NonFiniteSpeedIsNoEvidence) {
  StopDetector stop;
  for (int i = 0; i < 9; ++i) stop.Update(0.0);
  EXPECT_FALSE(stop.Update(std::nan("")));
  EXPECT_DOUBLE_EQ(stop.confidence(), 0.0);
}

TEST(DeadZone, CompensationInvertsTheValveDeadZone) {
  for (double d : {0.0, 0.08, 0.3}) {
    for (double u : {-1.0, -0.5, -0.01, 0.0, 0.01, 0.2, 1.0}) {
      EXPECT_NEAR(plant::ApplyDeadZone(CompensateDeadZone(u, d), d), u, 1e-12) << d << " " << u;
    }
  }
  EXPECT_DOUBLE_EQ(CompensateDeadZone(0.0, 0.08), 0.0);
  EXPECT_NEAR(CompensateDeadZone(1e-6, 0.08), 0.08, 1e-6);
  EXPECT_THROW(CompensateDeadZone(0.1, 1.0), std::invalid_argument);
  EXPECT_THROW(CompensateDeadZone(std::nan(""), 0.1), std::invalid_argument);
}

TEST(JointPid, NonFiniteInputsGiveZero) {
  JointPid pid(JointPidGains{}, 0.08);
  EXPECT_EQ(pid.Update(std::nan(""), 0.0, 0.0, 0.01), 0.0);
  EXPECT_EQ(pid.Update(0.5, INFINITY, 0.0, 0.01), 0.0);
  EXPECT_EQ(pid.refused_inputs(), 2);
  EXPECT_THROW(JointPid(JointPidGains{.kp = -1}, 0.08), std::invalid_argument);
}

// The feed-forward opening adds to the PID's demand before the limit and passes alone within
// the tolerance (where the PID holds), dead-zone compensated like the rest.
TEST(JointPid, FeedForwardAddsToTheDemandAndPassesWithinTheTolerance) {
  const JointPidGains gains{.kp = 2.0, .ki = 0.0};
  JointPid pid(gains, 0.08, /*compensate=*/false);
  EXPECT_DOUBLE_EQ(pid.Update(0.5, 0.5, 0.0, 0.01, -0.3), -0.3);  // at the target
  EXPECT_NEAR(pid.Update(0.6, 0.5, 0.0, 0.01, -0.3), 2.0 * 0.1 - 0.3, 1e-12);
  EXPECT_DOUBLE_EQ(pid.Update(1.5, 0.5, 0.0, 0.01, 0.5), 1.0);  // limited
  JointPid compensated(gains, 0.08);
  EXPECT_NEAR(compensated.Update(0.5, 0.5, 0.0, 0.01, 0.3), CompensateDeadZone(0.3, 0.08), 1e-12);
  EXPECT_EQ(compensated.Update(0.5, 0.5, 0.0, 0.01, NAN), 0.0);
  EXPECT_EQ(compensated.refused_inputs(), 1);
}

struct PidRun {
  double first_motion = NAN;  ///< when the joint had moved 5 mrad [s]
  double settled_error = NAN;
  bool finite = true;
};

// The bucket joint of the loader on a flat yard, stepped by `step` [rad] under the PID.
PidRun RunBucketStep(double step, bool compensate, const JointPidGains& gains, double duration) {
  const model::MachineDescription machine = plant::testing::LoadMachine("xcmg_968ev");
  plant::World world = plant::testing::FlatYard(machine, 12.0);
  // Bucket off the floor so that it swings freely.
  const std::vector<double> q0 = plant::BucketOnFloor(machine, 0.6);
  plant::MachineState start = plant::testing::LoaderAt(machine, 0.0, q0[0] + 0.2, q0[1]);
  plant::Plant loader(machine, plant::testing::Functions(machine.name), world, start);
  const int bucket_valve = machine.ActuatorOfJoint(1);
  JointPid pid(gains, machine.hydraulics.actuators[bucket_valve].valve.dead_zone, compensate);
  JointPid boom(JointPidGains{},
                machine.hydraulics.actuators[machine.ActuatorOfJoint(0)].valve.dead_zone);
  const double q_start = start.q[1], target = q_start + step, boom_target = start.q[0];
  core::ActuatorCommand command;
  command.valve.assign(machine.hydraulics.actuators.size(), 0.0);
  command.brake = 1;
  PidRun run;
  while (loader.time() < duration) {
    const plant::MachineState& s = loader.state();
    if (std::isnan(run.first_motion) && std::abs(s.q[1] - q_start) > 0.005) {
      run.first_motion = s.time;
    }
    command.valve[bucket_valve] = pid.Update(target, s.q[1], s.qd[1], 0.01);
    command.valve[machine.ActuatorOfJoint(0)] = boom.Update(boom_target, s.q[0], s.qd[0], 0.01);
    for (double u : command.valve) run.finite = run.finite && std::isfinite(u);
    EXPECT_TRUE(loader.SetCommand(command));
    loader.Advance(0.01);
  }
  run.settled_error = target - loader.state().q[1];
  return run;
}

TEST(JointPid, ReachesTheTargetOnThePlant) {
  const PidRun run = RunBucketStep(0.4, true, JointPidGains{}, 6.0);
  EXPECT_TRUE(run.finite);
  // Holding band of the PID is 0.01 rad; allow the spool's run-out after it closes.
  EXPECT_LT(std::abs(run.settled_error), 0.03) << run.settled_error;
}

TEST(JointPid, DeadZoneCompensationShortensTheTimeToMotion) {
  // A small step: kp·e = 0.06 is inside the 0.08 dead zone without compensation.
  const JointPidGains gains{.kp = 1.5, .ki = 0.3, .tolerance = 0.005};
  const PidRun with = RunBucketStep(0.04, true, gains, 4.0);
  const PidRun without = RunBucketStep(0.04, false, gains, 4.0);
  ASSERT_FALSE(std::isnan(with.first_motion));
  // Without compensation the integral has to wind through the dead zone first (or never does).
  if (!std::isnan(without.first_motion)) {
    EXPECT_LT(with.first_motion + 0.2, without.first_motion);
  }
  EXPECT_LT(std::abs(with.settled_error), std::abs(without.settled_error));
}

TEST(SpeedProfile, StepsRespectTheAccelerationLimits) {
  const double a_acc = 0.7, a_dec = 1.0, dt = 0.01;
  double v = 0;
  for (int i = 0; i < 500; ++i) {
    const double next = ProfileStep(v, 2.0, a_acc, a_dec, dt);
    EXPECT_LE(next - v, a_acc * dt + 1e-12);
    EXPECT_GE(next - v, 0.0);
    v = next;
  }
  EXPECT_DOUBLE_EQ(v, 2.0);
  for (int i = 0; i < 500; ++i) {
    const double next = ProfileStep(v, -1.0, a_acc, a_dec, dt);
    // Slowing down at a_dec until rest, then speeding up backwards at a_acc.
    const double limit = (std::abs(next) > std::abs(v) ? a_acc : a_dec) * dt;
    EXPECT_LE(std::abs(next - v), limit + 1e-12);
    v = next;
  }
  EXPECT_DOUBLE_EQ(v, -1.0);
}

TEST(SpeedPid, TracksTheProfileOnThePlant) {
  const model::MachineDescription machine = plant::testing::LoadMachine("xcmg_968ev");
  plant::World world = plant::testing::FlatYard(machine, 40.0, 0.1);
  plant::Plant loader(machine, plant::testing::Functions(machine.name), world,
                      plant::testing::LoaderAt(machine, -15.0));
  SpeedPid pid(SpeedPidGains{});
  pid.SetTarget(1.5);
  core::ActuatorCommand command;
  command.valve.assign(machine.hydraulics.actuators.size(), 0.0);
  double max_lag = 0;
  while (loader.time() < 8.0) {
    if (loader.time() > 5.0) pid.SetTarget(0.0);
    const DriveCommand u = pid.Update(loader.state().speed, 0.01);
    ASSERT_TRUE(std::isfinite(u.drive) && std::isfinite(u.brake));
    command.drive = u.drive, command.brake = u.brake;
    ASSERT_TRUE(loader.SetCommand(command));
    loader.Advance(0.01);
    max_lag = std::max(max_lag, std::abs(pid.reference() - loader.state().speed));
    if (std::abs(loader.time() - 4.0) < 0.005) {
      EXPECT_NEAR(loader.state().speed, 1.5, 0.1);
    }
  }
  EXPECT_LT(max_lag, 0.3) << "the PI loop follows the trapezoid";
  EXPECT_NEAR(loader.state().speed, 0.0, 0.1);
}

}  // namespace
}  // namespace autoshovel::control
