// Joint position control of the loader arm, wheel-loader seed §6.2: "a PID-based position
// controller with solenoid valve dead-zone compensation governs the boom and bucket articulation".
//
// u = kp·e + ki·∫e dt + kd·ė   with e = q_target − q [rad], ė = −q̇ (derivative on measurement),
// limited to [−u_max, u_max]; within `tolerance` of the target the output is zero (holding, so the
// transport delay of the valve does not turn the last few millirad into a limit cycle). The duty
// sent to the valve is then pre-compensated for the valve's dead zone d (model::Valve::dead_zone,
// the machine applies opening = (|u| − d)/(1 − d) beyond d, valve_command.h):
//   u_valve = sign(u)·(d + (1 − d)·|u|)  for u ≠ 0, and 0 for u = 0,
// the exact inverse, so a nonzero demand always opens the spool in proportion to it.
#pragma once

#include <cmath>
#include <string>

namespace autoshovel::control {

/// Maps a spool-opening demand in [−1, 1] to the valve duty that yields it past a dead zone
/// `dead_zone` ∈ [0, 1). Zero stays zero. Throws std::invalid_argument for a dead zone outside
/// [0, 1) or a non-finite demand.
double CompensateDeadZone(double demand, double dead_zone);

struct JointPidGains {
  double kp = 3.0;              ///< [1/rad]
  double ki = 0.3;              ///< [1/(rad·s)]
  double kd = 0.0;              ///< [s/rad]
  double output_limit = 1;      ///< u_max, fraction of full opening [-]
  double integral_limit = 0.3;  ///< |ki·∫e| bound (anti wind-up) [-]
  double tolerance = 0.01;      ///< |e| within which the output is zero [rad]

  /// Empty when usable, else what is wrong.
  std::string Invalid() const;
};

class JointPid {
 public:
  /// `dead_zone` of the joint's valve [-]; `compensate` false sends the PID output as it is
  /// (the uncompensated reference the tests compare against). Throws std::invalid_argument for
  /// invalid gains or dead zone.
  JointPid(const JointPidGains& gains, double dead_zone, bool compensate = true);

  /// One control step of `dt` [s] towards `target` [rad] from the measured position `q` [rad]
  /// and rate `qd` [rad/s]; returns the valve duty in [−1, 1]. `feed_forward` [-] is a spool
  /// opening added to the PID demand before the output limit (a moving target's rate, see
  /// arm_feed_forward.h); it is issued within the tolerance too, where the PID part is zero.
  /// Non-finite inputs give 0 and are counted (never a NaN command).
  double Update(double target, double q, double qd, double dt, double feed_forward = 0);
  void Reset();

  /// The PID output before dead-zone compensation at the last step [-].
  double last_demand() const { return last_demand_; }
  bool AtTarget(double target, double q) const { return std::abs(target - q) <= gains_.tolerance; }
  long refused_inputs() const { return refused_; }

 private:
  JointPidGains gains_;
  double dead_zone_;
  bool compensate_;
  double integral_ = 0;  ///< ki·∫e dt [-]
  double last_demand_ = 0;
  long refused_ = 0;
};

}  // namespace autoshovel::control
