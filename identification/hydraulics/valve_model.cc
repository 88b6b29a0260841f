#include "identification/hydraulics/valve_model.h"

#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace autoshovel::identification {

ActuatorKinematics::ActuatorKinematics(const model::MachineDescription& machine,
                                       const generated::MachineFunctions& functions, int actuator)
    : functions_(functions), actuator_(actuator) {
  if (actuator < 0 || actuator >= functions.num_actuators ||
      actuator >= static_cast<int>(machine.hydraulics.actuators.size())) {
    throw std::invalid_argument("ActuatorKinematics: actuator " + std::to_string(actuator) +
                                " out of range, machine '" + machine.name + "' has " +
                                std::to_string(functions.num_actuators));
  }
  const model::Actuator& act = machine.hydraulics.actuators[actuator];
  joint_ = functions.actuator_joint[actuator];
  motor_ = act.kind == model::ActuatorKind::kMotor;
  q_low_ = functions.joint_min[joint_];
  q_high_ = functions.joint_max[joint_];
  // The other joints at mid-range; the swing at zero.
  q_rest_.assign(functions.num_joints, 0.0);
  for (int j = 0; j < functions.num_links; ++j) {
    q_rest_[j] = 0.5 * (functions.joint_min[j] + functions.joint_max[j]);
  }
  if (motor_) {
    area_extend_ = area_retract_ = act.displacement;
    length_min_ = -std::numeric_limits<double>::infinity();
    length_max_ = std::numeric_limits<double>::infinity();
  } else {
    const double c = act.count * std::numbers::pi / 4.0;
    area_extend_ = c * act.bore * act.bore;
    area_retract_ = c * (act.bore * act.bore - act.rod * act.rod);
    length_min_ = act.retracted_length;
    length_max_ = act.retracted_length + act.stroke;
  }
}

double ActuatorKinematics::Length(double q) const {
  if (motor_) return q;
  std::vector<double> config = q_rest_;
  config[joint_] = q;
  return functions_.cylinder_length(actuator_, config.data());
}

double ActuatorKinematics::Lever(double q) const {
  if (motor_) return 1.0;
  std::vector<double> config = q_rest_;
  config[joint_] = q;
  return functions_.lever_arm(actuator_, config.data());
}

double ActuatorKinematics::Angle(double length) const {
  if (motor_) return length;
  const double l_low = Length(q_low_), l_high = Length(q_high_);
  const bool increasing = l_high > l_low;
  // Outside the joint's range the generated inverse refuses: extrapolate along the lever so
  // that the fit sees a smooth (if unphysical) answer while it passes through such values.
  if ((increasing && length <= l_low) || (!increasing && length >= l_low)) {
    return q_low_ + (length - l_low) / Lever(q_low_);
  }
  if ((increasing && length >= l_high) || (!increasing && length <= l_high)) {
    return q_high_ + (length - l_high) / Lever(q_high_);
  }
  std::vector<double> out(q_rest_.size());
  if (functions_.joint_from_cylinder_length(actuator_, length, q_rest_.data(), out.data()) != 0) {
    throw std::runtime_error("ActuatorKinematics: no joint angle for cylinder length " +
                             std::to_string(length) + " m");
  }
  return out[joint_];
}

}  // namespace autoshovel::identification
