// The safety supervisor (safety_supervisor.h).
#include "runtime/app/safety_supervisor.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "runtime/core/strings.h"

namespace autoshovel::app {

namespace {

using core::Fixed;

}  // namespace

std::string SafetySupervisor::StaleSensors(double t) const {
  std::string stale;
  if (t - last_lidar_ > config_.max_sensor_age) {
    stale = "LiDAR silent for " + (last_lidar_ < -1e8 ? std::string("the whole cycle")
                                                      : Fixed(t - last_lidar_, 2) + " s");
  }
  if (t - last_camera_ > config_.max_sensor_age) {
    stale +=
        (stale.empty() ? "" : ", ") + std::string("camera silent for ") +
        (last_camera_ < -1e8 ? std::string("the whole cycle") : Fixed(t - last_camera_, 2) + " s");
  }
  return stale;
}

bool SafetySupervisor::AcceptFrame(SensorStream stream, double stamp, double now) {
  double& newest = stream == SensorStream::kLidar ? last_lidar_ : last_camera_;
  if (!std::isfinite(stamp) || stamp <= newest || now - stamp > config_.max_sensor_age) {
    ++refused_frames_;
    return false;
  }
  newest = stamp;
  return true;
}

std::string SafetySupervisor::CheckPose(double t, const Eigen::Vector2d& hinge_xy, double heading,
                                        double speed) {
  std::string jump;
  if (have_pose_ && t > last_t_) {
    const double dt = t - last_t_;
    const double moved = (hinge_xy - last_xy_).norm();
    const double turned = std::abs(std::remainder(heading - last_heading_, 2 * std::numbers::pi));
    if (moved > std::abs(speed) * dt + config_.jump_distance || turned > config_.jump_heading) {
      jump = "localisation jumped " + Fixed(moved, 2) + " m and " +
             Fixed(turned * 180 / std::numbers::pi, 1) + " deg in " + Fixed(dt, 3) + " s";
    }
  }
  have_pose_ = true;
  last_t_ = t, last_xy_ = hinge_xy, last_heading_ = heading;
  return jump;
}

StallLimit StallLimitOf(const model::MachineDescription& machine, int actuator) {
  StallLimit limit;
  const auto& actuators = machine.hydraulics.actuators;
  if (actuator < 0 || actuator >= static_cast<int>(actuators.size())) return limit;
  // The compensators' margin: the largest rated drop, as the plant's load sensing takes it.
  double margin = 0;
  for (const model::Actuator& a : actuators) margin = std::max(margin, a.valve.rated_pressure_drop);
  const double relief = actuators[actuator].relief_pressure;
  const double pump = machine.hydraulics.pump_pressure - margin;
  if (pump > 0 && pump < relief) {
    limit.pressure = pump;
    limit.what = "the load-sensing pump's limit";
  } else if (relief > 0) {
    limit.pressure = relief;
    limit.what = "relief";
  }
  return limit;
}

JointReading ReadJoint(const model::MachineDescription& machine, int joint,
                       const control::Proprioception& sensed,
                       const core::ActuatorCommand& command) {
  const int actuator = machine.ActuatorOfJoint(static_cast<std::size_t>(joint));
  JointReading r;
  r.valve = actuator >= 0 && actuator < static_cast<int>(command.valve.size())
                ? command.valve[actuator]
                : 0.0;
  r.q = joint == 0 ? sensed.q_boom : sensed.q_bucket;
  r.qd = joint == 0 ? sensed.qd_boom : sensed.qd_bucket;
  r.working_pressure =
      joint == 0 ? (r.valve >= 0 ? sensed.boom_pressure : sensed.boom_pressure_rod)
                 : (r.valve >= 0 ? sensed.bucket_pressure_cap : sensed.bucket_pressure_rod);
  r.pump_pressure = sensed.pump_pressure;
  return r;
}

JointRange RangeOf(const model::MachineDescription& machine, int joint) {
  const model::Link& link = machine.links.at(static_cast<std::size_t>(joint));
  return {.q_min = link.joint_min,
          .q_max = link.joint_max,
          .stall = StallLimitOf(machine, machine.ActuatorOfJoint(static_cast<std::size_t>(joint)))};
}

JointCheck SafetySupervisor::CheckJoint(int joint, const std::string& name, double t,
                                        const JointReading& r, const JointRange& range) {
  const int k = joint == 0 ? 0 : 1;
  double& since = unanswered_since_[k];
  double& at_limit_since = at_stall_limit_since_[k];
  bool& reported = stall_reported_[k];
  const bool at_limit = (r.valve > 0 && r.q > range.q_max - config_.limit_margin) ||
                        (r.valve < 0 && r.q < range.q_min + config_.limit_margin);
  const bool unanswered = std::abs(r.valve) >= config_.stuck_command &&
                          std::abs(r.qd) < config_.stuck_rate && !at_limit;
  JointCheck check;
  if (!unanswered) {
    since = at_limit_since = -1;
    reported = false;
    return check;
  }
  if (since < 0) since = t;
  // The chamber and the pump both at the limit: the pump is pushing into the chamber.
  const double threshold = (1 - config_.stall_pressure_margin) * range.stall.pressure;
  const bool at_stall_pressure = std::isfinite(r.working_pressure) &&
                                 std::isfinite(r.pump_pressure) && std::isfinite(threshold) &&
                                 r.working_pressure >= threshold && r.pump_pressure >= threshold;
  if (!at_stall_pressure) {
    at_limit_since = -1;
  } else if (at_limit_since < 0) {
    at_limit_since = t;
  }
  const double unanswered_for = t - since;
  if (unanswered_for < config_.stuck_time) return check;
  const std::string commanded =
      "commanded " + Fixed(r.valve, 2) + " for " + Fixed(unanswered_for, 1) + " s";
  if (at_stall_pressure) {
    // A transient (a stone) does not make a stall: the pressure must have held.
    if (t - at_limit_since < config_.stall_confirm_time) return check;
    const std::string stall = name + " stalls under load at " + range.stall.what + " (" +
                              Fixed(r.working_pressure / 1e5, 0) + " bar, limit " +
                              Fixed(range.stall.pressure / 1e5, 0) + " bar): " + commanded;
    if (unanswered_for >= config_.max_stall_time) {
      check.state = JointState::kDoesNotAnswer;
      check.message = stall + ", not ended by the controller";
      return check;
    }
    check.state = JointState::kStallsUnderLoad;
    check.message = stall;
    check.first_report = !reported;
    reported = true;
    return check;
  }
  check.state = JointState::kDoesNotAnswer;
  check.message =
      name + " does not answer its valve: " + commanded + ", moving " + Fixed(r.qd, 4) + " rad/s" +
      (std::isfinite(r.working_pressure)
           ? ", working pressure " + Fixed(r.working_pressure / 1e5, 0) + " bar" +
                 (std::isfinite(r.pump_pressure)
                      ? ", pump " + Fixed(r.pump_pressure / 1e5, 0) + " bar"
                      : "") +
                 (std::isfinite(range.stall.pressure)
                      ? " (stall limit " + Fixed(range.stall.pressure / 1e5, 0) + " bar)"
                      : "")
           : "");
  return check;
}

void SafetySupervisor::Stop(const std::string& reason) {
  if (!stopped_) ++safe_stops_;
  stopped_ = true;
  reason_ = reason;
}

void SafetySupervisor::Resume() {
  if (stopped_) ++recoveries_;
  stopped_ = false;
  reason_.clear();
}

}  // namespace autoshovel::app
