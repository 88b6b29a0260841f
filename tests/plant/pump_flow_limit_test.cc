// The pump's largest delivery (Hydraulics::pump_max_flow): when the open spools ask for more, the
// cylinders together take what the pump delivers, shared in the proportion they asked for
// (post-compensated flow sharing); a limit above the demand changes nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>

#include "runtime/model/interpreted_model.h"
#include "runtime/plant/plant.h"
#include "tests/plant/plant_test_support.h"

namespace autoshovel::plant {
namespace {

struct Flows {
  double boom = 0, tilt = 0;  // mean oil flow into the extending chambers, 1.0–1.5 s [m³/s]
  std::vector<double> states;
};

// Boom and tilt valves fully open (both cylinders extending) from 0.1 s, the machine braked.
Flows OpenBoth(double pump_max_flow_lpm) {
  model::MachineDescription machine = testing::LoadMachine("xcmg_968ev");
  machine.hydraulics.pump_max_flow = pump_max_flow_lpm / 60000;
  World world = testing::FlatYard(machine, 24.0);
  // Bucket off the floor, mid-range, so that neither cylinder reaches an end.
  const double boom = -0.2, bucket = 0.2;
  Plant plant(machine, testing::Functions("xcmg_968ev"), world,
              testing::LoaderAt(machine, 0.0, boom, bucket));
  const model::InterpretedModel reference(machine);
  core::ActuatorCommand command;
  command.valve.assign(machine.hydraulics.actuators.size(), 0.0);
  command.brake = 1.0;
  Flows flows;
  int samples = 0;
  while (plant.time() < 1.5 - 1e-9) {
    if (plant.time() >= 0.1 - 1e-9) command.valve = {1.0, 1.0};
    EXPECT_TRUE(plant.SetCommand(command));
    plant.Advance(0.01);
    const MachineState& s = plant.state();
    if (plant.time() >= 1.0 - 1e-9) {
      for (int a = 0; a < 2; ++a) {
        const model::Actuator& act = machine.hydraulics.actuators[a];
        const std::vector<double> lever = reference.LeverArms(a, s.q.data());
        const double rate = lever[0] * s.qd[0] + lever[1] * s.qd[1];
        const double cap = act.count * std::numbers::pi / 4 * act.bore * act.bore;
        (a == 0 ? flows.boom : flows.tilt) += cap * rate;
      }
      ++samples;
    }
    flows.states.insert(flows.states.end(), s.q.begin(), s.q.end());
    flows.states.insert(flows.states.end(), s.qd.begin(), s.qd.end());
  }
  flows.boom /= samples;
  flows.tilt /= samples;
  return flows;
}

TEST(PumpFlowLimit, CylindersShareWhatThePumpDelivers) {
  const Flows free = OpenBoth(0.0);
  ASSERT_GT(free.boom, 0.0);
  ASSERT_GT(free.tilt, 0.0);
  const double free_total = free.boom + free.tilt;
  // Both spools fully open pass about their rated flows, 400 + 300 l/min.
  EXPECT_NEAR(free_total * 60000, 700, 70);
  const double limit = 0.5 * free_total;
  const Flows limited = OpenBoth(limit * 60000);
  EXPECT_NEAR(limited.boom + limited.tilt, limit, 0.05 * limit);
  // Each section gets the pump's share of what it asked for. The compensators' dead band (2 bar
  // of the 15 bar margin, scaled with the drop) lets a section's flow sit up to 7 % off, so 8 %:
  // a flow that went to one section first (no sharing) would be off by 50 %.
  EXPECT_NEAR(limited.boom / free.boom, 0.5, 0.08 * 0.5);
  EXPECT_NEAR(limited.tilt / free.tilt, 0.5, 0.08 * 0.5);
}

TEST(PumpFlowLimit, ALimitAboveTheDemandChangesNothing) {
  const Flows free = OpenBoth(0.0);
  const Flows roomy = OpenBoth(2000);
  ASSERT_EQ(free.states.size(), roomy.states.size());
  EXPECT_EQ(
      0, std::memcmp(free.states.data(), roomy.states.data(), free.states.size() * sizeof(double)));
}

}  // namespace
}  // namespace autoshovel::plant

namespace autoshovel::plant {
namespace {

// A valve section's load check valve: a chamber above its supply gets no oil back into the supply
// line through an open spool (the arm would give way), in the interpreted model and in the
// generated code alike; below it, the same spool fills the chamber.
TEST(LoadCheckValve, NoFlowFromAChamberBackIntoTheSupply) {
  const model::MachineDescription machine = testing::LoadMachine("xcmg_968ev");
  const generated::MachineFunctions& f = testing::Functions("xcmg_968ev");
  const model::InterpretedModel reference(machine);
  const int J = f.num_joints;
  std::vector<double> x(f.num_states, 0.0), u(f.num_inputs, 0.0), xdot(f.num_states);
  std::vector<double> xdot_generated(f.num_states);
  x[0] = -0.2, x[1] = 0.2;             // mid-range: no end stop
  x[2 * J] = 1.0;                      // boom spool fully open to extend
  x[4 * J] = 10e5;                     // rod side near tank
  x[4 * J + 1] = x[3 * J + 1] = 30e5;  // tilt held
  u[0] = 1.0;
  u[2 * J] = 0.0;  // no payload
  const double area = machine.hydraulics.actuators[0].count * std::numbers::pi / 4 *
                      std::pow(machine.hydraulics.actuators[0].bore, 2);
  const double volume = machine.hydraulics.actuators[0].dead_volume;  // lower bound of V_A
  const double bulk = machine.hydraulics.bulk_modulus;
  // ṗ_A = β/V_A (Q_A − A ṡ − Q_relief) with ṡ = 0: the chamber's net flow at a given supply,
  // spool fully open. Against a supply 100 bar below the chamber (where the check valve holds
  // for sure) the relief's and the tank path's flows cancel and the supply path's remains.
  const double volume_a = volume + area * (reference.CylinderLength<double>(0, x.data()) -
                                           machine.hydraulics.actuators[0].retracted_length);
  x[2 * J] = 1.0;
  x[3 * J] = 260e5;  // below the 280 bar relief
  auto net_flow = [&](double supply) {
    u[2 * J + 2] = supply;  // the boom section's supply
    u[2 * J + 3] = 50e5;
    reference.PlantRhs(x.data(), u.data(), xdot.data());
    f.plant_rhs(0.0, x.data(), u.data(), xdot_generated.data());
    EXPECT_NEAR(xdot_generated[3 * J], xdot[3 * J], 1e-6 * std::abs(xdot[3 * J]) + 1e-3);
    return xdot[3 * J] * volume_a / bulk;
  };
  const double held = net_flow(x[3 * J] - 100e5);
  const double rated = machine.hydraulics.actuators[0].valve.rated_flow;
  // 10 bar above its supply: nothing flows back (an open path would pass 80 % of rated back, and
  // the difference to 100 bar above would be 1.7 times rated).
  EXPECT_NEAR(net_flow(x[3 * J] - 10e5) - held, 0.0, 1e-4 * rated) << "oil flowed back";
  // 15 bar below (the rated drop): the spool's rated flow in.
  EXPECT_NEAR(net_flow(x[3 * J] + 15e5) - held, rated, 0.05 * rated);
}

}  // namespace
}  // namespace autoshovel::plant
