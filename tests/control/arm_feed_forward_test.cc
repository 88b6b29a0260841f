// The attitude-holding feed-forward against the plant: its valve model predicts the joint rates
// the hydraulic plant gives, and the tilt opening it computes keeps the bucket's attitude while
// the boom rises (what the exit lift needs, arm_feed_forward.h).
#include "runtime/control/arm_feed_forward.h"

#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <stdexcept>

#include "runtime/control/joint_pid.h"
#include "tests/control/control_test_support.h"

namespace autoshovel::control {
namespace {

constexpr const char* kMachine = "xcmg_968ev";
constexpr double kTick = 0.01;

struct Motion {
  double boom = 0;               ///< boom travel [rad]
  double attitude = 0;           ///< change of q_boom + q_bucket [rad]
  double boom_rate = 0;          ///< mean over the interval [rad/s]
  std::vector<double> q_middle;  ///< joint angles halfway through [rad]
};

// Opens the boom valve by `boom_opening` and the tilt valve by `bucket_opening` (spool openings,
// dead zone compensated as the scoop cycle sends them) with the bucket in the air and empty;
// measures over `seconds` once both valves have answered.
Motion OpenLoopLift(double boom_opening, double bucket_opening, double seconds) {
  const model::MachineDescription machine = plant::testing::LoadMachine(kMachine);
  plant::World world = plant::testing::FlatYard(machine, 20.0);
  // Boom low, bucket racked back a little: the exit lift's start.
  const plant::MachineState start = plant::testing::LoaderAt(machine, 0.0, -0.40, 0.70);
  plant::Plant loader(machine, plant::testing::Functions(kMachine), world, start);
  const double boom_dead = machine.hydraulics.actuators[machine.ActuatorOfJoint(0)].valve.dead_zone;
  const double tilt_dead = machine.hydraulics.actuators[machine.ActuatorOfJoint(1)].valve.dead_zone;
  core::ActuatorCommand command;
  command.valve.assign(machine.hydraulics.actuators.size(), 0.0);
  command.brake = 1;
  command.valve[machine.ActuatorOfJoint(0)] = CompensateDeadZone(boom_opening, boom_dead);
  command.valve[machine.ActuatorOfJoint(1)] = CompensateDeadZone(bucket_opening, tilt_dead);
  EXPECT_TRUE(loader.SetCommand(command));
  // Transport delay and spool lag (0.58 s), then the flow settles.
  const double settle = 1.0;
  for (double t = 0; t < settle; t += kTick) loader.Advance(kTick);
  const std::vector<double> q0 = loader.state().q;
  for (double t = 0; t < seconds; t += kTick) loader.Advance(kTick);
  const std::vector<double> q1 = loader.state().q;
  Motion m;
  m.boom = q1[0] - q0[0];
  m.attitude = (q1[0] + q1[1]) - (q0[0] + q0[1]);
  m.boom_rate = m.boom / seconds;
  m.q_middle = {0.5 * (q0[0] + q1[0]), 0.5 * (q0[1] + q1[1])};
  return m;
}

// The valve model (load-sensing: x·Q_rated into the cap side) gives the boom rate the plant
// gives within 15 % (the compensator's dead band and the empty bucket's inertia are not in it).
TEST(AttitudeHoldFeedForward, PredictsThePlantsBoomRate) {
  const model::MachineDescription machine = plant::testing::LoadMachine(kMachine);
  const AttitudeHoldFeedForward feed_forward(machine, plant::testing::Functions(kMachine));
  for (double opening : {0.4, 0.8}) {
    const Motion m = OpenLoopLift(opening, 0.0, 1.0);
    const double predicted = feed_forward.JointRate(0, opening, m.q_middle);
    std::printf("[feed-forward] boom opening %.1f: plant %.3f rad/s, model %.3f rad/s\n", opening,
                m.boom_rate, predicted);
    EXPECT_GT(m.boom_rate, 0.05);
    EXPECT_NEAR(predicted, m.boom_rate, 0.15 * m.boom_rate) << opening;
  }
}

// With the tilt valve opened as the feed-forward says, the bucket's attitude moves by under a
// fifth of the boom's travel; with the tilt valve shut it moves with the boom one for one (the
// tilt cylinder rides on the boom). That residue is what the scoop cycle's PID trims.
TEST(AttitudeHoldFeedForward, KeepsTheAttitudeWhileTheBoomRises) {
  const model::MachineDescription machine = plant::testing::LoadMachine(kMachine);
  const AttitudeHoldFeedForward feed_forward(machine, plant::testing::Functions(kMachine));
  const double boom_opening = 0.8;
  const double bucket_opening = feed_forward.BucketDemand(boom_opening, {-0.30, 0.60});
  EXPECT_LT(bucket_opening, 0);  // the tilt turns the bucket forward as the boom rises
  const Motion held = OpenLoopLift(boom_opening, bucket_opening, 1.0);
  const Motion free = OpenLoopLift(boom_opening, 0.0, 1.0);
  std::printf("[feed-forward] boom +%.3f rad: attitude %+.3f rad held, %+.3f rad tilt shut\n",
              held.boom, held.attitude, free.attitude);
  ASSERT_GT(held.boom, 0.1);
  EXPECT_NEAR(free.attitude, free.boom, 0.05 * free.boom);
  EXPECT_LT(std::abs(held.attitude), 0.2 * held.boom);
}

TEST(AttitudeHoldFeedForward, OpeningOfDutyInvertsTheDeadZoneCompensation) {
  const model::MachineDescription machine = plant::testing::LoadMachine(kMachine);
  const AttitudeHoldFeedForward feed_forward(machine, plant::testing::Functions(kMachine));
  const double dead = machine.hydraulics.actuators[machine.ActuatorOfJoint(1)].valve.dead_zone;
  for (double opening : {-1.0, -0.3, 0.0, 0.05, 0.6, 1.0}) {
    EXPECT_NEAR(feed_forward.OpeningOfDuty(1, CompensateDeadZone(opening, dead)), opening, 1e-12);
  }
  EXPECT_EQ(feed_forward.OpeningOfDuty(1, 0.5 * dead), 0.0);  // inside the dead zone
  EXPECT_EQ(feed_forward.OpeningOfDuty(1, NAN), 0.0);
  EXPECT_EQ(feed_forward.BucketDemand(NAN, {0.0, 0.5}), 0.0);
  EXPECT_EQ(feed_forward.JointRate(0, 0.0, {0.0, 0.5}), 0.0);
  // The travel of a run of openings is their rates' sum times the step.
  const std::deque<double> openings = {0.5, -0.25, 1.0};
  double sum = 0;
  for (double x : openings) sum += feed_forward.JointRate(1, x, {0.0, 0.5}) * 0.01;
  EXPECT_NEAR(feed_forward.JointTravel(1, openings, {0.0, 0.5}, 0.01), sum, 1e-12);
  // Same valves on both joints of this machine: no lag between them.
  EXPECT_EQ(feed_forward.boom_lag(), 0.0);
}

TEST(AttitudeHoldFeedForward, RefusesAnArmItCannotDrive) {
  const model::MachineDescription excavator = plant::testing::LoadMachine("excavator_25t");
  EXPECT_THROW(AttitudeHoldFeedForward(excavator, plant::testing::Functions("excavator_25t")),
               std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::control
