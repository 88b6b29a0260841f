#include "runtime/plant/drive.h"

#include <algorithm>
#include <cmath>

#include "runtime/model/plant_constants.h"

namespace autoshovel::plant {

namespace {

// Torque available from a source limited by T_max and by power P: a smooth min(T_max, P/|ω|).
double AvailableTorque(double max_torque, double max_power, double speed, double speed_floor) {
  const double w = std::sqrt(speed * speed + speed_floor * speed_floor);
  return max_torque * max_power / std::sqrt(std::pow(max_torque * w, 2) + max_power * max_power);
}

}  // namespace

DriveRates EvaluateDrive(const model::MachineDescription& machine, const DriveConstants& k,
                         const DriveState& state, const DriveInput& input) {
  const model::Chassis& chassis = machine.chassis;
  const double g = model::plant::kGravity;
  const double r = chassis.wheel_radius;
  const double mass = chassis.operating_mass + input.payload;
  DriveRates out;
  out.normal_load = std::max(mass * g - input.soil_force_z, 0.1 * mass * g);

  if (machine.electric_motor) {
    const model::ElectricMotor& motor = *machine.electric_motor;
    const double motor_speed = state.wheel_speed * motor.gear_ratio;
    out.wheel_torque =
        input.command * motor.gear_ratio *
        AvailableTorque(motor.max_torque, motor.max_power, motor_speed, k.motor_speed_floor);
  } else if (machine.diesel_engine) {
    const model::DieselEngine& engine = *machine.diesel_engine;
    const double engine_speed = std::max(std::abs(state.wheel_speed) * engine.gear_ratio, 0.0);
    const double gear = input.command >= 0 ? 1.0 : -1.0;
    out.wheel_torque =
        gear * state.throttle * engine.gear_ratio *
        AvailableTorque(engine.max_torque, engine.rated_power, engine_speed, k.motor_speed_floor);
    out.throttle_dot = (std::abs(input.command) - state.throttle) / engine.throttle_time_constant;
  }

  const double v = state.speed;
  out.slip = (state.wheel_speed * r - v) / std::sqrt(v * v + k.slip_speed * k.slip_speed);
  out.traction_force =
      chassis.traction_coefficient * out.normal_load * std::tanh(k.slip_stiffness * out.slip);
  // Service brakes can hold the full traction: T_brake,max = μ N r.
  const double brake_torque = input.brake * chassis.traction_coefficient * out.normal_load * r *
                              std::tanh(state.wheel_speed * r / k.brake_speed);
  const double rolling =
      chassis.rolling_resistance * out.normal_load * std::tanh(v / k.rolling_speed);
  out.wheel_speed_dot =
      (out.wheel_torque - brake_torque - r * out.traction_force) / k.wheel_inertia;
  out.speed_dot = (out.traction_force - rolling + input.soil_force_x) / mass;
  out.wheel_power = out.wheel_torque * state.wheel_speed;
  out.brake_torque = brake_torque;
  out.rolling_force = rolling;
  out.mass = mass;
  return out;
}

}  // namespace autoshovel::plant
