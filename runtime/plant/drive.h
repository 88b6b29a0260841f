// Longitudinal drive of a wheel loader: traction motor or diesel engine, lumped wheel, tyre
// force limited by traction, rolling resistance and brake (DESIGN.md, Plant: Drive).
//
//   I_w ω̇ = T_wheel − T_brake − r F_x
//   m v̇   = F_x − F_roll + F_soil,x
//   F_x   = μ N tanh(C_s s),  s = (ω r − v) / sqrt(v² + v_0²)      (saturating tyre curve)
//   F_roll = c_rr N tanh(v / v_roll)
//
// T_wheel: electric, u·T_max limited by the motor power, through the gear ratio; diesel, a
// throttle state with a first-order lag (the fuel rack and turbo), the engine's torque limited
// by its rated power, through the gear ratio, the sign of the command selecting forward or
// reverse. N = (m + m_payload) g − F_soil,z (the soil pressing the bucket down loads the front
// axle). The smooth tyre curve (peak at about 15 % slip) and the regularised signs keep the
// right-hand side differentiable for CVODE's Newton iteration.
#pragma once

#include "runtime/model/description.h"

namespace autoshovel::plant {

/// Estimates for a 20 t class loader that the description does not carry. Documented here so
/// that the plant's behaviour can be traced to a number.
struct DriveConstants {
  double wheel_inertia = 1500;     ///< four wheels plus driveline reflected to the axle [kg·m²]
  double slip_stiffness = 10;      ///< C_s: tanh(C_s s) reaches 0.9 at s ≈ 0.15 [-]
  double slip_speed = 0.3;         ///< v_0 regularising slip at standstill [m/s]
  double rolling_speed = 0.05;     ///< v_roll regularising the rolling-resistance sign [m/s]
  double brake_speed = 0.05;       ///< ω r below which the brake torque fades to zero [m/s]
  double motor_speed_floor = 1.0;  ///< regularises the power limit at standstill [rad/s]
};

struct DriveInput {
  double command = 0;       ///< [-1, 1]
  double brake = 0;         ///< [0, 1]
  double payload = 0;       ///< [kg]
  double soil_force_x = 0;  ///< along the base x axis, on the machine [N]
  double soil_force_z = 0;  ///< vertical, on the machine [N]
};

struct DriveState {
  double speed = 0;        ///< v [m/s]
  double wheel_speed = 0;  ///< ω [rad/s]
  double throttle = 0;     ///< diesel throttle state [0, 1]
};

struct DriveRates {
  double speed_dot = 0, wheel_speed_dot = 0, throttle_dot = 0;
  double wheel_torque = 0;    ///< T_wheel [N·m]
  double traction_force = 0;  ///< F_x [N]
  double normal_load = 0;     ///< N [N]
  double wheel_power = 0;     ///< T_wheel ω [W] (positive when driving)
  double brake_torque = 0;    ///< T_brake [N·m]
  double rolling_force = 0;   ///< F_roll [N]
  double mass = 0;            ///< machine plus payload [kg]
  double slip = 0;            ///< s [-]
};

DriveRates EvaluateDrive(const model::MachineDescription& machine, const DriveConstants& k,
                         const DriveState& state, const DriveInput& input);

}  // namespace autoshovel::plant
