// The safety supervisor (safety_supervisor.h).
#include "runtime/app/safety_supervisor.h"

#include <cmath>
#include <cstdio>
#include <numbers>

namespace autoshovel::app {

namespace {

std::string Fixed(double x, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, x);
  return text;
}

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

std::string SafetySupervisor::CheckJoint(int joint, const std::string& name, double t, double valve,
                                         double q, double qd, double q_min, double q_max) {
  double& since = unanswered_since_[joint == 0 ? 0 : 1];
  const bool at_limit = (valve > 0 && q > q_max - config_.limit_margin) ||
                        (valve < 0 && q < q_min + config_.limit_margin);
  const bool unanswered =
      std::abs(valve) >= config_.stuck_command && std::abs(qd) < config_.stuck_rate && !at_limit;
  if (!unanswered) {
    since = -1;
    return "";
  }
  if (since < 0) since = t;
  if (t - since < config_.stuck_time) return "";
  return name + " does not answer its valve: commanded " + Fixed(valve, 2) + " for " +
         Fixed(t - since, 1) + " s, moving " + Fixed(qd, 4) + " rad/s";
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
