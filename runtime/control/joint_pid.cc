// PID with dead-zone compensation (seed §6.2): u_valve = sign(u)·(d + (1 − d)|u|).
#include "runtime/control/joint_pid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace autoshovel::control {

double CompensateDeadZone(double demand, double dead_zone) {
  if (!(dead_zone >= 0 && dead_zone < 1)) {
    throw std::invalid_argument("CompensateDeadZone: dead zone must be in [0, 1), got " +
                                std::to_string(dead_zone));
  }
  if (!std::isfinite(demand)) {
    throw std::invalid_argument("CompensateDeadZone: demand must be finite");
  }
  const double magnitude = std::min(std::abs(demand), 1.0);
  if (magnitude == 0) return 0.0;
  return std::copysign(dead_zone + (1 - dead_zone) * magnitude, demand);
}

std::string JointPidGains::Invalid() const {
  const double values[] = {kp, ki, kd, output_limit, integral_limit, tolerance};
  for (double v : values) {
    if (!std::isfinite(v) || v < 0) return "joint PID: gains and limits must be finite and >= 0";
  }
  if (output_limit > 1) return "joint PID: output_limit must be <= 1";
  return {};
}

JointPid::JointPid(const JointPidGains& gains, double dead_zone, bool compensate)
    : gains_(gains), dead_zone_(dead_zone), compensate_(compensate) {
  if (const std::string why = gains.Invalid(); !why.empty()) throw std::invalid_argument(why);
  if (!(dead_zone >= 0 && dead_zone < 1)) {
    throw std::invalid_argument("JointPid: dead zone must be in [0, 1), got " +
                                std::to_string(dead_zone));
  }
}

void JointPid::Reset() {
  integral_ = 0;
  last_demand_ = 0;
}

double JointPid::Update(double target, double q, double qd, double dt, double feed_forward) {
  if (!std::isfinite(target) || !std::isfinite(q) || !std::isfinite(qd) || !std::isfinite(dt) ||
      dt <= 0 || !std::isfinite(feed_forward)) {
    ++refused_;
    last_demand_ = 0;
    return 0.0;
  }
  const double error = target - q;
  if (std::abs(error) <= gains_.tolerance) {
    // Holding: the integral is kept (it carries the load) but no feedback demand is issued.
    last_demand_ = std::clamp(feed_forward, -gains_.output_limit, gains_.output_limit);
    return compensate_ ? CompensateDeadZone(last_demand_, dead_zone_) : last_demand_;
  }
  const double unclamped = gains_.kp * error + integral_ - gains_.kd * qd + feed_forward;
  const double demand = std::clamp(unclamped, -gains_.output_limit, gains_.output_limit);
  if (demand == unclamped) {  // integrate only when not saturated (no wind-up)
    integral_ = std::clamp(integral_ + gains_.ki * error * dt, -gains_.integral_limit,
                           gains_.integral_limit);
  }
  last_demand_ = demand;
  return compensate_ ? CompensateDeadZone(demand, dead_zone_) : demand;
}

}  // namespace autoshovel::control
