// Pure pursuit on the simulated loader: it tracks a curvature-limited Dubins path closely.
#include "runtime/control/path_follower.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "runtime/app/plant_machine.h"
#include "runtime/control/speed_pid.h"
#include "runtime/plant/plant.h"
#include "runtime/plant/poses.h"
#include "runtime/plant/world.h"
#include "tests/plant/plant_test_support.h"

namespace autoshovel::control {
namespace {

// An S-bend at 90 % of κmax (as the run plans), 20 m, from standstill with the articulation
// straight: the front axle stays within 0.15 m of the path (the run's planning margin) and
// ends within 0.3 m of the goal, its heading within 8° of the goal's (measured 0.07 m, 0.19 m,
// 5.6°: the steering unwinds at 12°/s, so the frame still turns over the last metres).
TEST(PathFollower, TracksAnSBendOnThePlant) {
  const model::MachineDescription machine = plant::testing::LoadMachine("xcmg_968ev");
  const generated::MachineFunctions& functions = plant::testing::Functions("xcmg_968ev");
  plant::World world = plant::EmptyYard(machine, 60.0);
  plant::MachineState start = plant::testing::LoaderAt(machine, 0.0);
  start.hinge_xy = Eigen::Vector2d(10, 30);
  plant::Plant loader(machine, functions, world, start);
  app::PlantMachine io(loader);
  const planning::LoaderGeometry geometry = planning::LoaderGeometryFrom(machine, functions);
  const double kappa = 0.9 * geometry.MaxCurvature();
  const Eigen::Vector2d axle =
      start.hinge_xy + geometry.hinge_to_front_axle * Eigen::Vector2d::UnitX();
  const planning::DubinsPath path =
      planning::ShortestDubinsPath({axle, 0.0}, {axle + Eigen::Vector2d(18, 6), 0.0}, kappa);
  PathFollower follower(planning::SamplePath(path, 0.1), geometry);
  SpeedPid speed(SpeedPidGains{});
  speed.Reset(0);
  core::ActuatorCommand command;
  command.valve.assign(machine.hydraulics.actuators.size(), 0.0);
  double worst = 0, remaining = INFINITY;
  for (int tick = 0; tick < 6000 && remaining > 0.2; ++tick) {
    const Proprioception s = io.Sense();
    const SteeringCommand steer = follower.Update(s.hinge_xy, s.heading, s.articulation);
    worst = std::max(worst, std::abs(steer.cross_track));
    remaining = steer.remaining;
    speed.SetTarget(steer.speed);
    const DriveCommand drive = speed.Update(s.speed, 0.01);
    command.drive = drive.drive;
    command.brake = drive.brake;
    command.articulation_rate = steer.articulation_rate;
    ASSERT_TRUE(io.Command(command, nullptr));
    io.Advance(0.01);
  }
  const plant::MachineState& s = loader.state();
  const Eigen::Vector2d end_axle =
      s.hinge_xy +
      geometry.hinge_to_front_axle * Eigen::Vector2d(std::cos(s.heading), std::sin(s.heading));
  std::printf(
      "S-bend %s %.1f m: worst cross-track %.3f m, end %.3f m from the goal, heading "
      "%.1f deg\n",
      std::string(planning::ToString(path.word)).c_str(), path.length(), worst,
      (end_axle - (axle + Eigen::Vector2d(18, 6))).norm(), s.heading * 180 / M_PI);
  EXPECT_LE(remaining, 0.2);
  EXPECT_LT(worst, 0.15);
  EXPECT_LT((end_axle - (axle + Eigen::Vector2d(18, 6))).norm(), 0.3);
  EXPECT_LT(std::abs(s.heading), 8 * M_PI / 180);
}

}  // namespace
}  // namespace autoshovel::control
