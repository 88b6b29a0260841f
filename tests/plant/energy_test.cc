// Energy bookkeeping and determinism of the plant.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "runtime/plant/plant.h"
#include "tests/plant/plant_test_support.h"

namespace autoshovel::plant {
namespace {

// A scripted run: drive, raise the boom, curl, reverse; returns the plant's trace.
struct Trace {
  std::vector<double> time, hydraulic_power, travel_power, hydraulic_energy, travel_energy;
  std::vector<double> state_bytes;  // every state value, for byte comparison
};

Trace Script(const std::string& machine_name, double duration) {
  const model::MachineDescription machine = testing::LoadMachine(machine_name);
  World world = testing::FlatYard(machine, 24.0);
  testing::AddCone(world, {7.0, 0.0}, 3.0, "small_gravel");
  MachineState start;
  if (machine.kind == model::MachineKind::kWheelLoader) {
    start = testing::LoaderAt(machine, -1.0);
  } else {
    start.q.assign(machine.num_joints(), 0.0);
    for (std::size_t j = 0; j < machine.num_links(); ++j) {
      start.q[j] = 0.5 * (machine.links[j].joint_min + machine.links[j].joint_max);
    }
  }
  Plant plant(machine, testing::Functions(machine_name), world, start);
  core::ActuatorCommand command;
  command.valve.assign(machine.hydraulics.actuators.size(), 0.0);
  Trace trace;
  while (plant.time() < duration - 1e-9) {
    const double t = plant.time();
    command.drive = t < 2.5 ? 0.5 : (t < 5.0 ? 0.2 : -0.3);
    for (std::size_t a = 0; a < command.valve.size(); ++a) {
      command.valve[a] = (t > 2.5 && t < 5.5) ? 0.7 - 0.3 * static_cast<double>(a) : 0.0;
    }
    EXPECT_TRUE(plant.SetCommand(command));
    plant.Advance(0.01);
    trace.time.push_back(plant.time());
    trace.hydraulic_power.push_back(plant.HydraulicPower());
    trace.travel_power.push_back(plant.TravelPower());
    trace.hydraulic_energy.push_back(plant.energy().hydraulic);
    trace.travel_energy.push_back(plant.energy().travel);
    const MachineState& s = plant.state();
    for (const auto* v : {&s.q, &s.qd, &s.spool, &s.pressure_a, &s.pressure_b}) {
      trace.state_bytes.insert(trace.state_bytes.end(), v->begin(), v->end());
    }
    trace.state_bytes.insert(trace.state_bytes.end(),
                             {s.hinge_xy.x(), s.hinge_xy.y(), s.heading, s.speed, s.payload_volume,
                              world.terrain.MaterialVolume()});
  }
  return trace;
}

// The energy counters are CVODE states; the power sampled at the ticks, integrated by the
// trapezoid rule, must give the same energy (to the trapezoid's own error), and never decrease,
// except the travel energy of an electric drive, which its motor braking credits back
// (power_losses.h): the script reverses the command while the machine still rolls forward.
TEST(PlantEnergy, NonNegativeAndEqualToTheIntegralOfPower) {
  for (const std::string name : {"xcmg_968ev", "sdlg_l955he"}) {
    const Trace trace = Script(name, 8.0);
    const bool regenerates =
        TravelDriveLosses(testing::LoadMachine(name), PowerLossOptions{}).can_regenerate();
    EXPECT_EQ(regenerates, name == "xcmg_968ev");
    double hydraulic = trace.hydraulic_energy.front(), travel = trace.travel_energy.front();
    double least_travel_power = 0;
    for (std::size_t i = 1; i < trace.time.size(); ++i) {
      const double dt = trace.time[i] - trace.time[i - 1];
      ASSERT_GE(trace.hydraulic_power[i], 0.0);
      least_travel_power = std::min(least_travel_power, trace.travel_power[i]);
      if (!regenerates) {
        ASSERT_GE(trace.travel_power[i], 0.0);
      }
      // Non-decreasing, to the integrator's tolerance on the energy states (relative 1e-4,
      // absolute 1 J: the energies are CVODE states like any other).
      auto tolerance = [](double e) { return 1e-4 * e + 1.0; };
      ASSERT_GE(trace.hydraulic_energy[i],
                trace.hydraulic_energy[i - 1] - tolerance(trace.hydraulic_energy[i - 1]));
      if (!regenerates) {
        ASSERT_GE(trace.travel_energy[i],
                  trace.travel_energy[i - 1] - tolerance(trace.travel_energy[i - 1]));
      }
      hydraulic += 0.5 * dt * (trace.hydraulic_power[i] + trace.hydraulic_power[i - 1]);
      travel += 0.5 * dt * (trace.travel_power[i] + trace.travel_power[i - 1]);
    }
    EXPECT_GT(trace.hydraulic_energy.back(), 10e3) << name;  // the arm did work
    EXPECT_GT(trace.travel_energy.back(), 10e3) << name;
    // The 968EV's motor brakes at up to a third of its torque at walking pace: the battery gets
    // kilowatts back.
    if (regenerates) {
      EXPECT_LT(least_travel_power, -1e3) << name;
    }
    EXPECT_NEAR(hydraulic, trace.hydraulic_energy.back(), 0.02 * trace.hydraulic_energy.back())
        << name;
    EXPECT_NEAR(travel, trace.travel_energy.back(), 0.02 * trace.travel_energy.back()) << name;
  }
}

TEST(PlantDeterminism, SameInputsGiveByteIdenticalStates) {
  const Trace a = Script("xcmg_968ev", 4.0);
  const Trace b = Script("xcmg_968ev", 4.0);
  ASSERT_EQ(a.state_bytes.size(), b.state_bytes.size());
  EXPECT_EQ(0, std::memcmp(a.state_bytes.data(), b.state_bytes.data(),
                           a.state_bytes.size() * sizeof(double)));
}

TEST(PlantExcavator, ArmAndSwingMoveUnderValveCommands) {
  const Trace trace = Script("excavator_25t", 6.0);
  EXPECT_GT(trace.hydraulic_energy.back(), 10e3);
  EXPECT_EQ(trace.travel_energy.back(), 0.0);  // excavators stand still in this plant
}

}  // namespace
}  // namespace autoshovel::plant
