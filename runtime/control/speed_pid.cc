// Trapezoidal speed profile and PI with feed-forward (seed §6.2, see speed_pid.h).
#include "runtime/control/speed_pid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace autoshovel::control {

std::string SpeedPidGains::Invalid() const {
  const double values[] = {kff, kp, ki, integral_limit, moving_speed};
  for (double v : values) {
    if (!std::isfinite(v) || v < 0) return "speed PID: gains must be finite and >= 0";
  }
  if (!(max_acceleration > 0) || !(max_deceleration > 0) || !std::isfinite(max_acceleration) ||
      !std::isfinite(max_deceleration)) {
    return "speed PID: acceleration limits must be finite and > 0";
  }
  return {};
}

double ProfileStep(double reference, double target, double max_acceleration,
                   double max_deceleration, double dt) {
  const double delta = target - reference;
  // Speeding up (|v| grows) is limited by a_acc, slowing down by a_dec.
  const bool speeding_up = std::abs(target) > std::abs(reference) && target * reference >= 0;
  const double limit = (speeding_up ? max_acceleration : max_deceleration) * dt;
  return reference + std::clamp(delta, -limit, limit);
}

SpeedPid::SpeedPid(const SpeedPidGains& gains) : gains_(gains) {
  if (const std::string why = gains.Invalid(); !why.empty()) throw std::invalid_argument(why);
}

void SpeedPid::SetTarget(double target_speed) {
  if (std::isfinite(target_speed)) target_ = target_speed;
}

void SpeedPid::Reset(double speed) {
  reference_ = std::isfinite(speed) ? speed : 0.0;
  integral_ = 0;
}

DriveCommand SpeedPid::Update(double speed, double dt) {
  if (!std::isfinite(speed) || !std::isfinite(dt) || dt <= 0) {
    ++refused_;
    return {.drive = 0.0, .brake = 1.0};
  }
  reference_ =
      ProfileStep(reference_, target_, gains_.max_acceleration, gains_.max_deceleration, dt);
  const double error = reference_ - speed;
  const double unclamped = gains_.kff * reference_ + gains_.kp * error + integral_;
  const double u = std::clamp(unclamped, -1.0, 1.0);
  if (u == unclamped) {
    integral_ = std::clamp(integral_ + gains_.ki * error * dt, -gains_.integral_limit,
                           gains_.integral_limit);
  }
  DriveCommand out;
  const bool rolling = std::abs(speed) > gains_.moving_speed;
  if (rolling && u * speed < 0) {
    out.brake = std::min(std::abs(u), 1.0);  // against the travel: brake, keep the gear
  } else if (!rolling && u * reference_ <= 0) {
    // At rest and asked against the reference (or held at zero): brake, never change gear.
    out.brake = reference_ == 0 ? 1.0 : std::min(std::abs(u), 1.0);
  } else {
    out.drive = u;
  }
  return out;
}

}  // namespace autoshovel::control
