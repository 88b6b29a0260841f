// Travel speed control, wheel-loader seed §6.2: "an acceleration-oriented PID velocity controller,
// derived from comprehensive throttle-brake acceleration profiling, which maintains constant speed
// regulation during attacking and crowding phases before transitioning to fixed acceleration
// control upon scooping initiation".
//
// Our reading: the reference speed v_ref follows the target through a trapezoidal profile,
//   v_ref ← v_ref + clamp(v_target − v_ref, −a_dec·dt, a_acc·dt),
// (constant acceleration to a constant speed), and a PI loop with feed-forward tracks it:
//   u = k_ff·v_ref + kp·(v_ref − v) + ki·∫(v_ref − v) dt.
// A positive u in the direction of v_ref is the drive command; a u against the direction of
// travel brakes (brake = min(|u|, 1)) instead of reversing the gear while the machine still rolls.
// "Fixed acceleration control" at the scoop is SetTarget(0) with the deceleration limit a_dec.
#pragma once

#include <string>

namespace autoshovel::control {

struct SpeedPidGains {
  double kff = 0.1;               ///< drive per m/s of reference [s/m]
  double kp = 1.0;                ///< [s/m]
  double ki = 0.5;                ///< [1/m]
  double integral_limit = 0.7;    ///< |ki·∫e| bound [-]
  double max_acceleration = 0.7;  ///< a_acc of the profile [m/s²]
  double max_deceleration = 1.0;  ///< a_dec of the profile [m/s²]
  double moving_speed = 0.05;     ///< below this the machine may change gear [m/s]

  std::string Invalid() const;
};

struct DriveCommand {
  double drive = 0;  ///< [−1, 1]
  double brake = 0;  ///< [0, 1]
};

class SpeedPid {
 public:
  /// Throws std::invalid_argument for invalid gains.
  explicit SpeedPid(const SpeedPidGains& gains);

  /// The speed the profile heads for [m/s] (signed: negative reverses).
  void SetTarget(double target_speed);
  /// Restarts the profile from the measured speed `speed` [m/s].
  void Reset(double speed);
  /// One control step of `dt` [s] with the measured forward speed `speed` [m/s]. Non-finite
  /// inputs give a released drive with the brake on, counted.
  DriveCommand Update(double speed, double dt);

  double reference() const { return reference_; }
  double target() const { return target_; }
  long refused_inputs() const { return refused_; }

 private:
  SpeedPidGains gains_;
  double target_ = 0;
  double reference_ = 0;
  double integral_ = 0;
  long refused_ = 0;
};

/// One step of the trapezoidal profile: `reference` moved towards `target` by at most
/// a_acc·dt when |v| grows and a_dec·dt when it shrinks [m/s].
double ProfileStep(double reference, double target, double max_acceleration,
                   double max_deceleration, double dt);

}  // namespace autoshovel::control
