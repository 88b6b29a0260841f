#include "runtime/control/excavator/joint_servo.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "runtime/control/joint_pid.h"

namespace autoshovel::control {

void Validate(const JointServoSettings& settings) {
  auto require = [](bool ok, const char* field) {
    if (!ok) throw std::invalid_argument(std::string("JointServoSettings.") + field + " invalid");
  };
  require(std::isfinite(settings.velocity_gain) && settings.velocity_gain >= 0, "velocity_gain");
  require(std::isfinite(settings.hold_tolerance) && settings.hold_tolerance >= 0, "hold_tolerance");
  require(std::isfinite(settings.hold_velocity) && settings.hold_velocity >= 0, "hold_velocity");
}

ExcavatorJointServo::ExcavatorJointServo(const model::MachineDescription& machine,
                                         const generated::MachineFunctions& functions,
                                         const ExcavatorJointModels& models,
                                         const JointServoSettings& settings)
    : functions_(functions), models_(models), settings_(settings) {
  Validate(settings_);
  Validate(models_);
  if (machine.kind != model::MachineKind::kExcavator || !machine.swing ||
      machine.num_joints() != kNumExcavatorJoints || functions.num_joints != kNumExcavatorJoints ||
      functions.lever_arm == nullptr) {
    throw std::invalid_argument("ExcavatorJointServo: " + machine.name +
                                " is not an excavator with boom, stick, bucket and swing");
  }
  num_actuators_ = static_cast<int>(machine.hydraulics.actuators.size());
  for (int j = 0; j < kNumExcavatorJoints; ++j) {
    const int a = machine.ActuatorOfJoint(static_cast<std::size_t>(j));
    if (a < 0) {
      throw std::invalid_argument("ExcavatorJointServo: no actuator drives joint " +
                                  std::string(JointName(kAllExcavatorJoints[j])) + " of " +
                                  machine.name);
    }
    const model::Actuator& act = machine.hydraulics.actuators[a];
    actuator_[j] = a;
    dead_zone_[j] = act.valve.dead_zone;
    is_motor_[j] = act.kind == model::ActuatorKind::kMotor;
    rated_flow_[j] = act.valve.rated_flow;
    cap_area_[j] = act.count * std::numbers::pi / 4.0 * act.bore * act.bore;
    annulus_area_[j] =
        act.count * std::numbers::pi / 4.0 * (act.bore * act.bore - act.rod * act.rod);
  }
}

std::vector<double> ExcavatorJointServo::Update(const ExcavatorCommand& command,
                                                const ExcavatorState& measured) {
  std::vector<double> duty(num_actuators_, 0.0);
  rate_demand_.setZero();
  if (command.stop || FirstNonFinite(measured.q) >= 0 || FirstNonFinite(measured.qd) >= 0 ||
      FirstNonFinite(command.position) >= 0) {
    return duty;
  }
  for (int j = 0; j < kNumExcavatorJoints; ++j) {
    const JointModelParams& m = models_[j];
    const double target = std::clamp(command.position[j], m.position_min, m.position_max);
    const double e = target - measured.q[j];
    const double qd = measured.qd[j];
    if (std::abs(e) <= settings_.hold_tolerance && std::abs(qd) <= settings_.hold_velocity) {
      continue;  // locked by the oil
    }
    // The joint model's servo rate (joint_model.h), its braking branch shortened by the valve's
    // dead time: the model applies its law to the joint without delay, but here the valve answers
    // L later, and a joint braking only then overshoots by v·L (0.3 rad for the swing at 1 rad/s).
    // v·L + v²/(2a) = |e| gives the fastest rate that still stops at the target.
    const double a = m.max_acceleration, L = m.latency;
    const double v_brake = a * (std::sqrt(L * L + 2.0 * std::abs(e) / a) - L);
    double v = std::copysign(std::min(std::abs(e) / m.time_constant, v_brake), e);
    v = std::clamp(v, -m.max_velocity_down, m.max_velocity_up);
    rate_demand_[j] = v;
    double v_max = v >= 0 ? m.max_velocity_up : m.max_velocity_down;
    double sign = 1.0;
    if (!is_motor_[j]) {
      const double lever = functions_.lever_arm(actuator_[j], measured.q.data());
      if (!std::isfinite(lever) || std::abs(lever) < 1e-6) continue;
      sign = lever > 0 ? 1.0 : -1.0;
      // Extending feeds the cap side; extending raises the angle when dL/dq > 0.
      const bool extend = (v >= 0) == (lever > 0);
      v_max = rated_flow_[j] / ((extend ? cap_area_[j] : annulus_area_[j]) * std::abs(lever));
    }
    double u = (v + settings_.velocity_gain * (v - qd)) / v_max;
    u = std::clamp(u, -1.0, 1.0);
    // Braking closes the valve, never reverses it while the joint still moves the other way: a
    // reversed spool would open the braking side to tank (no braking at all on the swing's
    // inertia), a closed one holds it to the relief pressure, which is the braking the models
    // assume.
    if (u * qd < 0 && std::abs(qd) > settings_.hold_velocity) u = 0;
    // The same when the joint, at the rate it has now, needs all the distance left to stop:
    // v* above is the rate to aim for, but a joint still faster than that (the swing, whose
    // inertia it cannot shed quickly) has to start braking now, not once it has slowed to v*.
    const double closing = qd * (e > 0 ? 1.0 : -1.0);
    if (closing > 0 && closing * L + closing * closing / (2.0 * a) >= std::abs(e)) u = 0;
    duty[actuator_[j]] = CompensateDeadZone(sign * u, dead_zone_[j]);
  }
  return duty;
}

}  // namespace autoshovel::control
