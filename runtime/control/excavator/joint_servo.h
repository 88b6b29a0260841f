// The excavator's low-level joint controllers (excavator seed §4.4: "a desired joint position
// sent to that joint's low-level controller"): desired joint positions in, valve duties out.
//
// Each joint follows the rate law of its closed-loop joint model (joint_model.h),
//   v* = sign(e) · min(|e| / τ, v_b(|e|)),  e = q_desired − q,  clamped to [−v_down, v_up],
// so that the machine moves as the script parameters and the look-ahead predict it. The model's
// braking branch is sqrt(2 a |e|); the servo's, v_b = a (sqrt(L² + 2|e|/a) − L), also brakes for
// the valve's dead time L (v_b L + v_b²/(2a) = |e|): the model's joint answers at once, the
// machine's valve L later, and without it the swing overshoots the truck by about v·L. The valves
// are pressure compensated (the plant, and load-sensing machines), so a spool opening passes a
// flow, hence a joint rate, in proportion to it whatever the load: the duty is the rate asked
// for over the joint's full rate at the measured pose, plus a velocity-error term that makes up
// for what the model leaves out (gravity near relief, the swing's inertia),
//   u = v*/v_max(q) + k_v (v* − q̇)/v_max(q),  clamped to [−1, 1],
// v_max(q) = rated flow / (fed area · |dL/dq(q)|): the cylinder's lever changes several-fold over
// the workspace (the stick's from the carry pose to a dig at full reach), and a gain fixed at one
// pose would make the loop around the valve's dead time ring at another.
// set to zero while the joint still moves against it (braking by closing the valve, see the
// code), then pre-compensated for the valve's dead zone (joint_pid.h, CompensateDeadZone) and
// signed by the cylinder's lever dL/dq at the measured pose (a positive duty extends a cylinder,
// which raises the joint angle when dL/dq > 0). Within `hold_tolerance` of the target and slow, the
// valve is closed: the cylinder or motor is then locked by the oil, as an operator's released
// lever locks it.
//
// A stop (§4.5) closes every valve at once: the closed-centre spools block the ports and the
// load brakes the joint up to the relief pressure, which is the braking the joint models assume
// (joint_model.cc: a = relief Δp · area · lever / inertia).
#pragma once

#include <array>
#include <vector>

#include "generated/machine_functions.h"
#include "runtime/control/excavator/excavator_joints.h"
#include "runtime/control/excavator/joint_model.h"
#include "runtime/model/description.h"

namespace autoshovel::control {

struct JointServoSettings {
  double velocity_gain = 0.5;     ///< k_v [-]
  double hold_tolerance = 0.004;  ///< |e| below which a slow joint's valve is closed [rad]
  double hold_velocity = 0.02;    ///< "slow" for the hold [rad/s]
};

/// Throws std::invalid_argument naming the field.
void Validate(const JointServoSettings& settings);

class ExcavatorJointServo {
 public:
  /// Finds each joint's actuator in the description (one per joint). Throws std::invalid_argument
  /// when the machine is not an excavator with one actuator per joint, or a setting is invalid.
  ExcavatorJointServo(const model::MachineDescription& machine,
                      const generated::MachineFunctions& functions,
                      const ExcavatorJointModels& models, const JointServoSettings& settings = {});

  /// Valve duties in description order for `command` at the measured state. A stop, or a
  /// measured state with a non-finite entry, closes every valve (NaN never reaches a valve).
  std::vector<double> Update(const ExcavatorCommand& command, const ExcavatorState& measured);

  /// The rate the last Update asked of each joint [rad/s].
  const JointVector& rate_demand() const { return rate_demand_; }
  int actuator(ExcavatorJoint joint) const { return actuator_[JointIndex(joint)]; }
  const ExcavatorJointModels& models() const { return models_; }

 private:
  const generated::MachineFunctions& functions_;
  ExcavatorJointModels models_;
  JointServoSettings settings_;
  std::array<int, kNumExcavatorJoints> actuator_{};
  std::array<double, kNumExcavatorJoints> dead_zone_{};
  std::array<bool, kNumExcavatorJoints> is_motor_{};
  std::array<double, kNumExcavatorJoints> rated_flow_{};    ///< [m³/s]
  std::array<double, kNumExcavatorJoints> cap_area_{};      ///< all cylinders of the joint [m²]
  std::array<double, kNumExcavatorJoints> annulus_area_{};  ///< [m²]
  int num_actuators_ = 0;
  JointVector rate_demand_ = JointVector::Zero();
};

}  // namespace autoshovel::control
