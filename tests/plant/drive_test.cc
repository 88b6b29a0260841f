// Drive and steering of the wheel loader: traction limit and slip, brake, steering geometry,
// diesel throttle lag.
#include "runtime/plant/drive.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "runtime/model/plant_constants.h"
#include "runtime/plant/plant.h"
#include "tests/plant/plant_test_support.h"

namespace autoshovel::plant {
namespace {

struct Driver {
  Plant* plant;
  core::ActuatorCommand command;
  void For(double seconds) {
    const double end = plant->time() + seconds;
    while (plant->time() < end - 1e-9) {
      EXPECT_TRUE(plant->SetCommand(command));
      plant->Advance(0.01);
    }
  }
};

// The tyre force never exceeds μN; against a wall of resistance the wheels spin: slip grows
// well past the tyre's peak (0.15) while the machine stands.
TEST(Drive, TractionIsLimitedByMuNAndExcessTorqueSpinsTheWheels) {
  const model::MachineDescription machine = testing::LoadMachine("xcmg_968ev");
  const DriveConstants k;
  const double normal = machine.chassis.operating_mass * model::plant::kGravity;
  DriveState state{0.0, 3.0, 0.0};  // wheels turning, machine held still
  DriveInput input;
  input.command = 1.0;
  const DriveRates rates = EvaluateDrive(machine, k, state, input);
  EXPECT_LE(rates.traction_force, machine.chassis.traction_coefficient * normal * (1 + 1e-12));
  EXPECT_GT(rates.traction_force, 0.95 * machine.chassis.traction_coefficient * normal);
  EXPECT_GT(rates.slip, 1.0);
  // A strong soil force pressing the bucket down raises the normal load and the limit.
  input.soil_force_z = -50e3;
  EXPECT_GT(EvaluateDrive(machine, k, state, input).traction_force, rates.traction_force);

  // Closed loop on a bare floor: the machine accelerates with little slip.
  World world = testing::FlatYard(machine, 20.0, 0.1);
  Plant plant(machine, testing::Functions(machine.name), world, testing::LoaderAt(machine, 0.0));
  Driver run{&plant, {}};
  run.command.valve = {0, 0};
  run.command.drive = 1.0;
  run.For(3.0);
  EXPECT_GT(plant.state().speed, 3.0);  // free: it accelerates
  EXPECT_LT(std::abs(plant.state().wheel_slip), 0.2);
}

TEST(Drive, BrakeStopsTheMachine) {
  const model::MachineDescription machine = testing::LoadMachine("xcmg_968ev");
  World world = testing::FlatYard(machine, 60.0, 0.2);
  Plant plant(machine, testing::Functions(machine.name), world, testing::LoaderAt(machine, -25));
  Driver run{&plant, {}};
  run.command.valve = {0, 0};
  run.command.drive = 0.8;
  run.For(4.0);
  const double v0 = plant.state().speed;
  ASSERT_GT(v0, 3.0);
  run.command.drive = 0.0;
  run.command.brake = 1.0;
  const double x0 = plant.state().hinge_xy.x();
  run.For(4.0);
  EXPECT_LT(std::abs(plant.state().speed), 0.05);
  // Braking at the traction limit: deceleration about μ g, stopping distance about v²/(2 μ g).
  const double mu_g = machine.chassis.traction_coefficient * model::plant::kGravity;
  const double distance = plant.state().hinge_xy.x() - x0;
  EXPECT_GT(distance, 0.7 * v0 * v0 / (2 * mu_g));
  EXPECT_LT(distance, 2.0 * v0 * v0 / (2 * mu_g));
}

// At a constant articulation γ the front axle runs on a circle of radius
// R_f = (l_f cos γ + l_r) / sin γ (articulated-steering kinematics, no lateral slip).
TEST(Drive, ConstantArticulationDrivesTheKnownCircle) {
  const model::MachineDescription machine = testing::LoadMachine("xcmg_968ev");
  World world = testing::FlatYard(machine, 60.0, 0.5);
  MachineState start = testing::LoaderAt(machine, 0.0, -0.2, 0.3);
  const double gamma = 0.5;
  start.articulation = gamma;
  Plant plant(machine, testing::Functions(machine.name), world, start);
  Driver run{&plant, {}};
  run.command.valve = {0, 0};
  run.command.drive = 0.3;
  run.For(1.5);
  run.command.drive = 0.15;
  double max_radius = 0, min_radius = 1e9;
  const double lf = machine.chassis.hinge_to_front_axle, lr = machine.chassis.hinge_to_rear_axle;
  const double expected = (lf * std::cos(gamma) + lr) / std::sin(gamma);
  // Centre of the circle: from the front axle, perpendicular to the front frame, R_f away.
  auto front_axle = [&] {
    const MachineState& s = plant.state();
    return Eigen::Vector2d(s.hinge_xy +
                           lf * Eigen::Vector2d(std::cos(s.heading), std::sin(s.heading)));
  };
  const MachineState& s0 = plant.state();
  const Eigen::Vector2d center =
      front_axle() + expected * Eigen::Vector2d(-std::sin(s0.heading), std::cos(s0.heading));
  for (int i = 0; i < 8; ++i) {
    run.For(1.0);
    const double r = (front_axle() - center).norm();
    max_radius = std::max(max_radius, r), min_radius = std::min(min_radius, r);
  }
  EXPECT_NEAR(max_radius, expected, 0.01 * expected);
  EXPECT_NEAR(min_radius, expected, 0.01 * expected);
  EXPECT_NEAR(plant.state().articulation, gamma, 1e-9);
}

TEST(Drive, DieselThrottleLagsTheCommand) {
  const model::MachineDescription machine = testing::LoadMachine("sdlg_l955he");
  ASSERT_TRUE(machine.diesel_engine.has_value());
  World world = testing::FlatYard(machine, 60.0, 0.5);
  Plant plant(machine, testing::Functions(machine.name), world,
              testing::LoaderAt(machine, -20.0, -0.2, 0.3));
  Driver run{&plant, {}};
  run.command.valve = {0, 0};
  run.command.drive = 1.0;
  const double tau = machine.diesel_engine->throttle_time_constant;
  run.For(tau);
  const double v_tau = plant.state().speed;
  run.For(3 * tau);
  const double v_4tau = plant.state().speed;
  // An electric drive reaches full torque at once; the diesel's speed after τ is far below
  // the speed it gains in the next 3τ at (nearly) full throttle.
  EXPECT_GT(v_tau, 0.0);
  EXPECT_LT(v_tau, 0.25 * v_4tau);
}

}  // namespace
}  // namespace autoshovel::plant
