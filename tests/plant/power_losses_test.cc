// The loss maps behind the energy counters (runtime/plant/power_losses.h): the description's
// efficiency at the rated point, less at part load, losses at stall, regeneration, smoothness
// (derivatives through dual numbers against central differences), and the plant booking them.
#include "runtime/plant/power_losses.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

#include "runtime/plant/plant.h"
#include "tests/plant/plant_test_support.h"

namespace autoshovel::plant {
namespace {

// A forward-mode dual number v + d ε: enough arithmetic for the maps' templates.
struct Dual {
  double v = 0, d = 0;
  Dual(double value = 0, double derivative = 0) : v(value), d(derivative) {}  // NOLINT
  friend Dual operator+(const Dual& a, const Dual& b) { return {a.v + b.v, a.d + b.d}; }
  friend Dual operator-(const Dual& a, const Dual& b) { return {a.v - b.v, a.d - b.d}; }
  friend Dual operator-(const Dual& a) { return {-a.v, -a.d}; }
  friend Dual operator*(const Dual& a, const Dual& b) { return {a.v * b.v, a.d * b.v + a.v * b.d}; }
  friend Dual operator/(const Dual& a, const Dual& b) {
    return {a.v / b.v, (a.d * b.v - a.v * b.d) / (b.v * b.v)};
  }
  friend bool operator>(const Dual& a, const Dual& b) { return a.v > b.v; }
  friend Dual sqrt(const Dual& a) {
    const double s = std::sqrt(a.v);
    return {s, a.d / (2 * s)};
  }
};

model::MachineDescription Machine(const std::string& name) { return testing::LoadMachine(name); }

// The Z-bar candidate (not shipped), which gives the pump's largest delivery.
std::string ZbarPath() {
  return std::string(AUTOSHOVEL_SOURCE_DIR) + "/examples/xcmg_968ev_zbar/xcmg_968ev.yaml";
}
model::MachineDescription Zbar() {
  model::LoadOptions options;
  options.models_dir = testing::ModelsDir();
  return model::LoadMachineDescription(ZbarPath(), options);
}

double RatedLoss(const ElectricLossMap& m, double efficiency) {
  return m.rated_torque * m.rated_speed * (1 / efficiency - 1);
}

TEST(PowerLosses, TractionMapGivesTheDescriptionEfficiencyAtTheRatedPoint) {
  const model::MachineDescription machine = Machine("xcmg_968ev");
  const model::ElectricMotor& motor = *machine.electric_motor;
  const TravelDriveLosses drive(machine, PowerLossOptions{});
  ASSERT_NE(drive.map(), nullptr);
  const ElectricLossMap& map = *drive.map();
  EXPECT_DOUBLE_EQ(map.rated_torque, motor.max_torque);
  EXPECT_DOUBLE_EQ(map.rated_torque * map.rated_speed, motor.max_power);
  EXPECT_NEAR(map.Efficiency(map.rated_torque, map.rated_speed), motor.efficiency, 1e-6);
  // The same through the wheel: T_wheel = G T, ω_wheel = ω/G.
  const TravelPowerSplit<double> wheel =
      drive.Evaluate(motor.gear_ratio * map.rated_torque, map.rated_speed / motor.gear_ratio);
  EXPECT_NEAR(motor.max_power / wheel.drawn, motor.efficiency, 1e-6);
  EXPECT_NEAR(wheel.drawn, motor.max_power + wheel.loss, 1e-9 * motor.max_power);
  EXPECT_EQ(wheel.not_recovered, 0.0);
}

TEST(PowerLosses, PumpMapGivesTheDescriptionEfficiencyAtTheRatedPoint) {
  const std::string zbar = ZbarPath();
  for (const std::string& name :
       {std::string("xcmg_968ev"), std::string("sdlg_l955he"), std::string("hyundai_hl740_9s"),
        std::string("excavator_25t"), zbar}) {
    const model::MachineDescription machine = name == zbar ? Zbar() : Machine(name);
    const HydraulicLosses pump(machine, PowerLossOptions{});
    const double p = pump.rated_pressure(), q = pump.rated_flow();
    EXPECT_DOUBLE_EQ(p, machine.hydraulics.pump_pressure) << name;
    EXPECT_NEAR(p * q / pump.Drawn(p, q), machine.hydraulics.pump_efficiency, 1e-6) << name;
    // An electric machine's pump has its own motor; a diesel's pump is driven by the engine.
    EXPECT_EQ(pump.motor() != nullptr, machine.electric_motor.has_value()) << name;
  }
  // The rated flow: the pump's largest delivery where given, else the largest valve's rating.
  EXPECT_NEAR(HydraulicLosses(Machine("xcmg_968ev"), {}).rated_flow() * 60000, 400, 1e-9);
  EXPECT_NEAR(HydraulicLosses(Zbar(), {}).rated_flow() * 60000, 350, 1e-9);
}

TEST(PowerLosses, PartLoadIsLessEfficientThanTheRatedPoint) {
  const model::MachineDescription machine = Machine("xcmg_968ev");
  const ElectricLossMap m = *TravelDriveLosses(machine, {}).map();
  const double eta = machine.electric_motor->efficiency;
  const double tr = m.rated_torque, wr = m.rated_speed;
  EXPECT_LT(m.Efficiency(0.1 * tr, wr), eta - 0.05);  // 10 % torque at the corner speed
  EXPECT_LT(m.Efficiency(tr, 0.1 * wr), eta - 0.05);  // full torque, crawling
  EXPECT_LT(m.Efficiency(0.1 * tr, 0.1 * wr), m.Efficiency(0.1 * tr, wr));
  // Plausible: a traction drive at a tenth of its torque or speed still converts most of it.
  EXPECT_GT(m.Efficiency(0.1 * tr, wr), 0.5);
  EXPECT_GT(m.Efficiency(tr, 0.1 * wr), 0.5);
  // Rising with the load at the corner speed up to half torque, with the speed at full torque.
  for (double f = 0.05; f < 0.5; f += 0.05) {
    EXPECT_LT(m.Efficiency(f * tr, wr), m.Efficiency((f + 0.05) * tr, wr)) << f;
    EXPECT_LT(m.Efficiency(tr, f * wr), m.Efficiency(tr, (f + 0.05) * wr)) << f;
  }

  const HydraulicLosses pump(machine, {});
  const double p = pump.rated_pressure(), q = pump.rated_flow();
  const double eta_pump = machine.hydraulics.pump_efficiency;
  auto efficiency = [&](double pressure, double flow) {
    return pressure * flow / pump.Drawn(pressure, flow);
  };
  EXPECT_LT(efficiency(p, 0.1 * q), eta_pump - 0.05);  // small displacement at full pressure
  EXPECT_LT(efficiency(0.1 * p, q), eta_pump - 0.05);  // full flow at low pressure
  EXPECT_GT(efficiency(p, 0.1 * q), 0.3);
  for (double f = 0.1; f < 0.95; f += 0.1) {
    EXPECT_LT(efficiency(p, f * q), efficiency(p, (f + 0.1) * q)) << f;
  }
  // Nothing is lost while the pump does not deliver; the electric motor is part of the loss.
  EXPECT_EQ(pump.Loss(p, 0.0), 0.0);
  EXPECT_GT(pump.Loss(p, q), pump.PumpLoss(p, q));
}

TEST(PowerLosses, StallWithTorqueCostsCopperAndInverterLosses) {
  const model::MachineDescription machine = Machine("xcmg_968ev");
  const PowerLossOptions options;
  const TravelDriveLosses drive(machine, options);
  const ElectricLossMap& m = *drive.map();
  const double rated_loss = RatedLoss(m, machine.electric_motor->efficiency);
  // At ω = 0 only the torque terms remain, each at its rated value: the motor's copper share and
  // the whole inverter's.
  const ElectricLossSplit& s = options.traction;
  EXPECT_NEAR(m.Loss(m.rated_torque, 0.0), (s.motor * s.motor_copper + s.inverter) * rated_loss,
              1e-9 * rated_loss);
  const TravelPowerSplit<double> stall =
      drive.Evaluate(machine.electric_motor->gear_ratio * 800, 0.0);
  EXPECT_GT(stall.drawn, 0.01 * rated_loss);
  EXPECT_EQ(stall.drawn, stall.loss);
  EXPECT_EQ(m.Loss(0.0, 0.0), 0.0);
  EXPECT_EQ(drive.Evaluate(0.0, 0.0).drawn, 0.0);
}

TEST(PowerLosses, RegenerationCreditsTheBatteryWithWhatTheLossesLeave) {
  const model::MachineDescription machine = Machine("xcmg_968ev");
  const double g = machine.electric_motor->gear_ratio;
  PowerLossOptions options;
  const TravelDriveLosses credit(machine, options);
  options.credit_regeneration = false;
  const TravelDriveLosses dissipate(machine, options);
  const ElectricLossMap& m = *credit.map();
  const double torque = -0.5 * m.rated_torque * g, speed = m.rated_speed / g;
  const double braking = torque * speed;  // < 0
  const TravelPowerSplit<double> a = credit.Evaluate(torque, speed);
  EXPECT_LT(a.drawn, 0.0);                                           // the battery receives…
  EXPECT_NEAR(a.drawn, braking + a.loss, 1e-9 * std::abs(braking));  // …|Tω| less the losses
  EXPECT_GT(a.loss, 0.0);
  EXPECT_EQ(a.not_recovered, 0.0);
  EXPECT_TRUE(credit.can_regenerate());
  const TravelPowerSplit<double> b = dissipate.Evaluate(torque, speed);
  EXPECT_NEAR(b.drawn, 0.0, 1.0);  // within the 1 W regularisation
  EXPECT_DOUBLE_EQ(b.loss, a.loss);
  EXPECT_NEAR(b.drawn, braking + b.loss + b.not_recovered, 1e-9 * std::abs(braking));
  EXPECT_FALSE(dissipate.can_regenerate());
  // Braking at a crawl: the losses exceed what the wheel gives back; the battery pays the rest.
  const TravelPowerSplit<double> crawl = credit.Evaluate(-m.rated_torque * g, 0.01 * speed);
  EXPECT_GT(crawl.drawn, 0.0);
}

TEST(PowerLosses, FlatOptionAndTheDieselKeepTheFlatEfficiencies) {
  PowerLossOptions flat;
  flat.loss_maps = false;
  const model::MachineDescription ev = Machine("xcmg_968ev");
  const TravelDriveLosses ev_flat(ev, flat);
  EXPECT_EQ(ev_flat.map(), nullptr);
  EXPECT_DOUBLE_EQ(ev_flat.Evaluate(2000.0, 3.0).drawn, 6000.0 / ev.electric_motor->efficiency);
  const TravelPowerSplit<double> braking = ev_flat.Evaluate(-2000.0, 3.0);
  EXPECT_EQ(braking.drawn, 0.0);
  EXPECT_DOUBLE_EQ(braking.not_recovered, 6000.0);
  EXPECT_DOUBLE_EQ(HydraulicLosses(ev, flat).Drawn(200e5, 0.002),
                   200e5 * 0.002 / ev.hydraulics.pump_efficiency);
  const model::MachineDescription diesel = Machine("sdlg_l955he");
  const TravelDriveLosses engine(diesel, PowerLossOptions{});
  EXPECT_EQ(engine.map(), nullptr);
  EXPECT_FALSE(engine.can_regenerate());
  EXPECT_DOUBLE_EQ(engine.Evaluate(2000.0, 3.0).drawn, 6000.0 / diesel.diesel_engine->efficiency);
  EXPECT_EQ(engine.Evaluate(-2000.0, 3.0).drawn, 0.0);
}

// d/dx of f at x: the dual number's derivative against a central difference, to 1e-5 of its
// size or 1e-6 of the derivative's typical size `scale` (rated loss over rated x).
void ExpectDerivative(const std::function<Dual(Dual)>& f, double x, double width, double scale,
                      const std::string& what) {
  const double exact = f(Dual(x, 1.0)).d;
  const double h = 1e-4 * (std::abs(x) + width);
  const double central = (f(Dual(x + h)).v - f(Dual(x - h)).v) / (2 * h);
  EXPECT_NEAR(exact, central, 1e-5 * std::abs(exact) + 1e-6 * scale) << what << " at " << x;
}

TEST(PowerLosses, DerivativesMatchCentralDifferences) {
  const model::MachineDescription machine = Machine("xcmg_968ev");
  PowerLossOptions options;
  options.credit_regeneration = false;  // the smooth positive part too
  const TravelDriveLosses drive(machine, options);
  const ElectricLossMap& m = *drive.map();
  const double tr = m.rated_torque, wr = m.rated_speed, g = machine.electric_motor->gear_ratio;
  const double rated_loss = RatedLoss(m, machine.electric_motor->efficiency);
  for (double ft : {-1.0, -0.3, -2e-3, -3e-4, 0.0, 4e-4, 1e-3, 0.05, 0.5, 1.0}) {
    for (double fw : {-0.5, -1e-3, 0.0, 5e-4, 0.02, 0.7, 1.0, 2.5}) {
      const double t = ft * tr, w = fw * wr;
      const std::string at = " T=" + std::to_string(t) + " w=" + std::to_string(w);
      ExpectDerivative([&](Dual x) { return m.Loss(x, Dual(w)); }, t, m.torque_width,
                       rated_loss / tr, "dL/dT" + at);
      ExpectDerivative([&](Dual x) { return m.Loss(Dual(t), x); }, w, m.speed_width,
                       rated_loss / wr, "dL/dw" + at);
      ExpectDerivative([&](Dual x) { return drive.Evaluate(x, Dual(w / g)).drawn; }, t * g,
                       g * m.torque_width, rated_loss / (g * tr), "dP/dT_wheel" + at);
    }
  }
  const HydraulicLosses pump(machine, PowerLossOptions{});
  const double p = pump.rated_pressure(), q = pump.rated_flow();
  for (double fp : {0.0, 5e-4, 0.01, 0.3, 1.0}) {
    for (double fq : {0.0, 1e-3, 0.01, 0.03, 0.5, 1.0}) {
      const std::string at = " p=" + std::to_string(fp * p) + " Q=" + std::to_string(fq * q);
      ExpectDerivative([&](Dual x) { return pump.Loss(x, Dual(fq * q)); }, fp * p, 1e-3 * p,
                       pump.Loss(p, q) / p, "dL/dp" + at);
      ExpectDerivative([&](Dual x) { return pump.Loss(Dual(fp * p), x); }, fq * q, 0.01 * q,
                       pump.Loss(p, q) / q, "dL/dQ" + at);
    }
  }
}

// No kinks: the slopes just either side of zero agree (sqrt(x² + ε²) regularisation), where
// |x| would jump by twice its coefficient.
TEST(PowerLosses, SlopesAreContinuousThroughZero) {
  const model::MachineDescription machine = Machine("xcmg_968ev");
  const ElectricLossMap m = *TravelDriveLosses(machine, {}).map();
  const double rated_loss = RatedLoss(m, machine.electric_motor->efficiency);
  for (double w : {0.0, 0.3 * m.rated_speed}) {
    const double d = 1e-9 * m.rated_torque;
    const double left = m.Loss(Dual(-d, 1.0), Dual(w)).d, right = m.Loss(Dual(d, 1.0), Dual(w)).d;
    EXPECT_NEAR(left, right, 1e-6 * rated_loss / m.rated_torque) << w;
    EXPECT_GT(m.current, 1e-3 * rated_loss / m.rated_torque);  // the |T| term is there
  }
  for (double t : {0.0, 0.3 * m.rated_torque}) {
    const double d = 1e-9 * m.rated_speed;
    const double left = m.Loss(Dual(t), Dual(-d, 1.0)).d, right = m.Loss(Dual(t), Dual(d, 1.0)).d;
    EXPECT_NEAR(left, right, 1e-6 * rated_loss / m.rated_speed) << t;
  }
  const HydraulicLosses pump(machine, {});
  const double p = pump.rated_pressure(), q = pump.rated_flow();
  const double left = pump.Loss(Dual(p), Dual(-1e-12 * q, 1.0)).d;
  const double right = pump.Loss(Dual(p), Dual(1e-12 * q, 1.0)).d;
  EXPECT_NEAR(left, right, 1e-6 * pump.Loss(p, q) / q);
}

TEST(PowerLosses, BadSplitsAreRefusedNamingTheField) {
  const model::MachineDescription machine = Machine("xcmg_968ev");
  PowerLossOptions options;
  options.traction.motor = 0.5;  // 0.5 + 0.2 + 0.4
  options.pump.delivery_gate = -1;
  try {
    TravelDriveLosses drive(machine, options);
    FAIL() << "accepted a split that does not sum to 1";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("PowerLossOptions.traction.motor + inverter + gearing: must sum to 1, "
                        "got 1.1"),
              std::string::npos)
        << what;
    EXPECT_NE(what.find("PowerLossOptions.pump.delivery_gate: must be in"), std::string::npos)
        << what;
  }
  EXPECT_THROW(MakeElectricLossMap(0.0, 100.0, 0.9, ElectricLossSplit{}), std::invalid_argument);
  EXPECT_THROW(MakeElectricLossMap(100.0, 100.0, 1.5, ElectricLossSplit{}), std::invalid_argument);
}

// The plant books the map: the 968EV pushing against its own service brake (the wheel held, the
// motor at half torque) draws the copper and inverter losses, which the flat model booked as
// almost nothing (it only saw the wheel's creep, T ω).
TEST(PlantEnergy, StallAgainstTheBrakeCostsTheMotorsLosses) {
  const model::MachineDescription machine = Machine("xcmg_968ev");
  auto run = [&](bool maps, double* speed, double* power) {
    World world = testing::FlatYard(machine, 24.0);
    PlantOptions options;
    options.losses.loss_maps = maps;
    options.energy_audit = true;
    Plant plant(machine, testing::Functions("xcmg_968ev"), world, testing::LoaderAt(machine, 0.0),
                options);
    core::ActuatorCommand command;
    command.valve.assign(machine.hydraulics.actuators.size(), 0.0);
    command.drive = 0.5;
    command.brake = 1.0;
    while (plant.time() < 2.0 - 1e-9) {
      EXPECT_TRUE(plant.SetCommand(command));
      plant.Advance(0.01);
    }
    *speed = plant.state().speed;
    *power = plant.TravelPower();
    const EnergyAudit& audit = plant.energy_audit();
    EXPECT_NEAR(audit.travel(), plant.energy().travel, 0.01 * plant.energy().travel + 1.0);
    return plant.energy().travel;
  };
  double speed = 0, power = 0, flat_speed = 0, flat_power = 0;
  const double with_map = run(true, &speed, &power);
  const double flat = run(false, &flat_speed, &flat_power);
  EXPECT_LT(std::abs(speed), 0.05);  // held
  // The maps only count: the trajectory is the same, to the rounding of the Newton solves (the
  // energy rows share the linear system).
  EXPECT_NEAR(speed, flat_speed, 1e-9);
  const ElectricLossMap m = *TravelDriveLosses(machine, {}).map();
  const double stall_loss = m.Loss(0.5 * machine.electric_motor->max_torque, 0.0);
  EXPECT_GT(power, 0.95 * stall_loss);
  EXPECT_GT(with_map, 1.5 * stall_loss);  // about 2 s of it
  EXPECT_LT(flat, 0.5 * with_map);
}

}  // namespace
}  // namespace autoshovel::plant
