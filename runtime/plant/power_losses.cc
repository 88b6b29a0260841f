#include "runtime/plant/power_losses.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace autoshovel::plant {

namespace {

// Appends "name: must be in [lo, hi], got v" when v is outside (or not finite).
void CheckRange(std::ostringstream& why, const std::string& name, double v, double lo, double hi) {
  if (!(std::isfinite(v) && v >= lo && v <= hi)) {
    why << name << ": must be in [" << lo << ", " << hi << "], got " << v << "; ";
  }
}

void CheckSum(std::ostringstream& why, const std::string& names, double sum) {
  if (!(std::abs(sum - 1.0) <= 1e-9)) why << names << ": must sum to 1, got " << sum << "; ";
}

std::string Prefixed(const std::string& prefix, const std::string& message) {
  if (message.empty()) return message;
  std::string out;
  std::istringstream parts(message);
  std::string part;
  while (std::getline(parts, part, ';')) {
    if (part.find_first_not_of(' ') == std::string::npos) continue;
    out += prefix + part.substr(part.find_first_not_of(' ')) + "; ";
  }
  return out;
}

}  // namespace

std::string ElectricLossSplit::Check() const {
  std::ostringstream why;
  for (const auto& [name, v] : {std::pair{"motor", motor},
                                {"inverter", inverter},
                                {"gearing", gearing},
                                {"motor_copper", motor_copper},
                                {"motor_core", motor_core},
                                {"motor_friction", motor_friction},
                                {"core_hysteresis", core_hysteresis},
                                {"inverter_current", inverter_current},
                                {"inverter_ohmic", inverter_ohmic},
                                {"inverter_fixed", inverter_fixed},
                                {"gearing_mesh", gearing_mesh}}) {
    CheckRange(why, name, v, 0.0, 1.0);
  }
  CheckSum(why, "motor + inverter + gearing", motor + inverter + gearing);
  CheckSum(why, "motor_copper + motor_core + motor_friction",
           motor_copper + motor_core + motor_friction);
  CheckSum(why, "inverter_current + inverter_ohmic + inverter_fixed",
           inverter_current + inverter_ohmic + inverter_fixed);
  CheckRange(why, "smoothing", smoothing, 1e-9, 0.1);
  CheckRange(why, "fixed_loss_torque", fixed_loss_torque, 1e-9, 0.5);
  return why.str();
}

std::string PumpLossSplit::Check() const {
  std::ostringstream why;
  for (const auto& [name, v] : {std::pair{"pump", pump},
                                {"leakage", leakage},
                                {"pressure_friction", pressure_friction},
                                {"constant_friction", constant_friction}}) {
    CheckRange(why, name, v, 0.0, 1.0);
  }
  CheckSum(why, "leakage + pressure_friction + constant_friction",
           leakage + pressure_friction + constant_friction);
  CheckRange(why, "delivery_gate", delivery_gate, 1e-9, 0.5);
  CheckRange(why, "smoothing", smoothing, 1e-9, 0.1);
  return why.str();
}

std::string PowerLossOptions::Check() const {
  std::string why = Prefixed("PowerLossOptions.traction.", traction.Check()) +
                    Prefixed("PowerLossOptions.pump_motor.", pump_motor.Check()) +
                    Prefixed("PowerLossOptions.pump.", pump.Check());
  if (!(std::isfinite(pump_speed) && pump_speed > 0)) {
    why +=
        "PowerLossOptions.pump_speed: must be > 0 rad/s, got " + std::to_string(pump_speed) + "; ";
  }
  return why;
}

ElectricLossMap MakeElectricLossMap(double rated_torque, double rated_speed, double efficiency,
                                    const ElectricLossSplit& split) {
  if (!(std::isfinite(rated_torque) && rated_torque > 0) ||
      !(std::isfinite(rated_speed) && rated_speed > 0) ||
      !(std::isfinite(efficiency) && efficiency > 0 && efficiency <= 1)) {
    std::ostringstream why;
    why << "MakeElectricLossMap: rated torque and speed must be > 0 and the efficiency in (0, 1], "
           "got "
        << rated_torque << " N·m, " << rated_speed << " rad/s, " << efficiency;
    throw std::invalid_argument(why.str());
  }
  if (const std::string why = split.Check(); !why.empty()) {
    throw std::invalid_argument("MakeElectricLossMap: " + why);
  }
  ElectricLossMap map;
  map.rated_torque = rated_torque;
  map.rated_speed = rated_speed;
  map.torque_width = split.smoothing * rated_torque;
  map.speed_width = split.smoothing * rated_speed;
  map.power_width = split.smoothing * rated_torque * rated_speed;
  map.fixed_torque = split.fixed_loss_torque * rated_torque;
  const double rated_loss = rated_torque * rated_speed * (1.0 / efficiency - 1.0);
  // Each term's coefficient: its share of the rated loss over its basis function at the rated
  // point, the basis evaluated through Loss itself (coefficient 1, the others 0), so that the
  // map gives the rated loss exactly.
  const ElectricLossMap zero = map;  // every coefficient 0
  auto calibrate = [&](double ElectricLossMap::*coefficient, double share) {
    ElectricLossMap unit = zero;
    unit.*coefficient = 1.0;
    const double basis = unit.Loss(rated_torque, rated_speed);
    map.*coefficient = share * rated_loss / basis;
  };
  calibrate(&ElectricLossMap::copper,
            split.motor * split.motor_copper + split.inverter * split.inverter_ohmic);
  calibrate(&ElectricLossMap::current, split.inverter * split.inverter_current);
  calibrate(&ElectricLossMap::fixed, split.inverter * split.inverter_fixed);
  calibrate(&ElectricLossMap::friction,
            split.motor * split.motor_friction + split.gearing * (1.0 - split.gearing_mesh));
  calibrate(&ElectricLossMap::hysteresis, split.motor * split.motor_core * split.core_hysteresis);
  calibrate(&ElectricLossMap::eddy, split.motor * split.motor_core * (1.0 - split.core_hysteresis));
  calibrate(&ElectricLossMap::mesh, split.gearing * split.gearing_mesh);
  return map;
}

TravelDriveLosses::TravelDriveLosses(const model::MachineDescription& machine,
                                     const PowerLossOptions& options)
    : credit_regeneration_(options.credit_regeneration) {
  if (const std::string why = options.Check(); !why.empty()) {
    throw std::invalid_argument(why);
  }
  if (machine.electric_motor) {
    const model::ElectricMotor& motor = *machine.electric_motor;
    gear_ratio_ = motor.gear_ratio;
    efficiency_ = motor.efficiency;
    if (options.loss_maps) {
      // The corner point: largest torque at the speed where it meets the power limit.
      map_ = MakeElectricLossMap(motor.max_torque, motor.max_power / motor.max_torque,
                                 motor.efficiency, options.traction);
    }
  } else if (machine.diesel_engine) {
    gear_ratio_ = machine.diesel_engine->gear_ratio;
    efficiency_ = machine.diesel_engine->efficiency;
  }
}

HydraulicLosses::HydraulicLosses(const model::MachineDescription& machine,
                                 const PowerLossOptions& options)
    : maps_(options.loss_maps) {
  if (const std::string why = options.Check(); !why.empty()) {
    throw std::invalid_argument(why);
  }
  const model::Hydraulics& hyd = machine.hydraulics;
  efficiency_ = hyd.pump_efficiency;
  rated_pressure_ = hyd.pump_pressure;
  rated_flow_ = hyd.pump_max_flow;
  if (rated_flow_ <= 0) {
    // No largest delivery given: a load-sensing pump is sized for the largest single function
    // at full speed (the valve with the largest rated flow); simultaneous motions share it.
    // The sum of all rated flows would size a 25 t excavator's pump at 1390 l/min, three times
    // its class's (two pumps of about 200 l/min).
    for (const model::Actuator& act : hyd.actuators) {
      rated_flow_ = std::max(rated_flow_, act.valve.rated_flow);
    }
  }
  if (!maps_) return;
  if (!(rated_pressure_ > 0 && rated_flow_ > 0 && efficiency_ > 0 && efficiency_ <= 1)) {
    std::ostringstream why;
    why << "HydraulicLosses: " << machine.name
        << ": the pump's rated point needs a pressure, a flow > 0 and an efficiency in (0, 1], "
           "got "
        << rated_pressure_ << " Pa, " << rated_flow_ << " m³/s, " << efficiency_;
    throw std::invalid_argument(why.str());
  }
  const PumpLossSplit& split = options.pump;
  const double hydraulic = rated_pressure_ * rated_flow_;
  const double rated_loss = hydraulic * (1.0 / efficiency_ - 1.0);
  const bool electric = machine.electric_motor.has_value();
  const double pump_loss = electric ? split.pump * rated_loss : rated_loss;
  gate_flow_ = split.delivery_gate * rated_flow_;
  pressure_width_ = split.smoothing * rated_pressure_;
  pump_speed_ = options.pump_speed;
  const double gate = Gate(rated_flow_);
  leakage_ = split.leakage * pump_loss / (gate * rated_pressure_ * rated_pressure_);
  pressure_friction_ = split.pressure_friction * pump_loss /
                       (gate * loss_internal::SmoothAbs(rated_pressure_, pressure_width_));
  constant_friction_ = split.constant_friction * pump_loss / gate;
  if (!electric) return;
  // The motor at the pump's rated shaft power, its share of the loss at the gate's value there.
  const double shaft = hydraulic + PumpLoss(rated_pressure_, rated_flow_);
  const double motor_loss = (rated_loss - PumpLoss(rated_pressure_, rated_flow_)) / gate;
  motor_ = MakeElectricLossMap(shaft / pump_speed_, pump_speed_, shaft / (shaft + motor_loss),
                               options.pump_motor);
}

}  // namespace autoshovel::plant
