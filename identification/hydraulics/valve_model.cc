#include "identification/hydraulics/valve_model.h"

#include <algorithm>
#include <cmath>
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
    length_at_low_ = Length(q_low_), length_at_high_ = Length(q_high_);
    lever_at_low_ = Lever(q_low_), lever_at_high_ = Lever(q_high_);
    // q(L) tabulated over the stroke the joint's range spans, with dq/dL = 1/lever: the fit
    // inverts the kinematics at every row of every evaluation, and the generated inverse
    // (Newton from mid-range, a dozen kinematic evaluations) was half of a long fit's time.
    // Cubic Hermite on 4096 intervals of a fraction of a millimetre: its error, of order
    // h^4/384 times the fourth derivative of q(L), is far below 1e-9 rad (tests/hydraulics
    // checks it against the generated inverse).
    constexpr std::size_t kIntervals = 4096;
    table_origin_ = std::min(length_at_low_, length_at_high_);
    table_step_ = std::abs(length_at_high_ - length_at_low_) / kIntervals;
    table_angle_.resize(kIntervals + 1);
    table_slope_.resize(kIntervals + 1);
    const bool increasing = length_at_high_ > length_at_low_;
    for (std::size_t i = 0; i <= kIntervals; ++i) {
      // The end nodes are the range's ends themselves: no round-off outside the inverse's
      // domain.
      double q;
      if (i == 0) {
        q = increasing ? q_low_ : q_high_;
      } else if (i == kIntervals) {
        q = increasing ? q_high_ : q_low_;
      } else {
        q = ExactAngle(table_origin_ + table_step_ * static_cast<double>(i));
      }
      table_angle_[i] = q;
      table_slope_[i] = 1.0 / Lever(q);
    }
  }
}

namespace {

// Scratch configuration per thread: the fit calls these once or twice per log row and
// evaluation, from the solver's threads, and a vector allocated per call showed in profiles.
std::vector<double>& Scratch(const std::vector<double>& like) {
  thread_local std::vector<double> config;
  config.assign(like.begin(), like.end());
  return config;
}

}  // namespace

double ActuatorKinematics::Length(double q) const {
  if (motor_) return q;
  std::vector<double>& config = Scratch(q_rest_);
  config[joint_] = q;
  return functions_.cylinder_length(actuator_, config.data());
}

double ActuatorKinematics::Lever(double q) const {
  if (motor_) return 1.0;
  std::vector<double>& config = Scratch(q_rest_);
  config[joint_] = q;
  return functions_.lever_arm(actuator_, config.data());
}

double ActuatorKinematics::ExactAngle(double length) const {
  std::vector<double>& out = Scratch(q_rest_);
  if (functions_.joint_from_cylinder_length(actuator_, length, q_rest_.data(), out.data()) != 0) {
    throw std::runtime_error("ActuatorKinematics: no joint angle for cylinder length " +
                             std::to_string(length) + " m");
  }
  return out[joint_];
}

double ActuatorKinematics::Angle(double length, double* slope) const {
  if (motor_) {
    if (slope != nullptr) *slope = 1.0;
    return length;
  }
  const double l_low = length_at_low_, l_high = length_at_high_;
  const bool increasing = l_high > l_low;
  // Outside the joint's range the generated inverse refuses: extrapolate along the lever so
  // that the fit sees a smooth (if unphysical) answer while it passes through such values.
  if ((increasing && length <= l_low) || (!increasing && length >= l_low)) {
    if (slope != nullptr) *slope = 1.0 / lever_at_low_;
    return q_low_ + (length - l_low) / lever_at_low_;
  }
  if ((increasing && length >= l_high) || (!increasing && length <= l_high)) {
    if (slope != nullptr) *slope = 1.0 / lever_at_high_;
    return q_high_ + (length - l_high) / lever_at_high_;
  }
  // Cubic Hermite interpolation in the table of the exact inverse (values and slopes).
  const double t = (length - table_origin_) / table_step_;
  const std::size_t last = table_angle_.size() - 2;
  const std::size_t i = std::min(static_cast<std::size_t>(std::max(t, 0.0)), last);
  const double u = t - static_cast<double>(i), h = table_step_;
  const double q0 = table_angle_[i], q1 = table_angle_[i + 1];
  const double s0 = table_slope_[i], s1 = table_slope_[i + 1];
  const double u2 = u * u, u3 = u2 * u;
  if (slope != nullptr) {
    *slope = (6 * u2 - 6 * u) * (q0 - q1) / h + (3 * u2 - 4 * u + 1) * s0 + (3 * u2 - 2 * u) * s1;
  }
  return (2 * u3 - 3 * u2 + 1) * q0 + (u3 - 2 * u2 + u) * h * s0 + (-2 * u3 + 3 * u2) * q1 +
         (u3 - u2) * h * s1;
}

}  // namespace autoshovel::identification
