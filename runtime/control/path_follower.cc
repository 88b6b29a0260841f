// Pure pursuit for the articulated loader's front axle (path_follower.h).
#include "runtime/control/path_follower.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace autoshovel::control {

std::string PathFollowerOptions::Invalid() const {
  const double positive[] = {lookahead,    articulation_gain, max_articulation_rate,
                             cruise_speed, final_speed,       deceleration,
                             lag_span,     min_speed_factor};
  for (double v : positive) {
    if (!(v > 0) || !std::isfinite(v)) return "path follower: every option must be > 0";
  }
  if (final_speed > cruise_speed) return "path follower: final_speed exceeds cruise_speed";
  if (min_speed_factor > 1) return "path follower: min_speed_factor exceeds 1";
  return {};
}

PathFollower::PathFollower(std::vector<planning::PathSample> path,
                           const planning::LoaderGeometry& loader,
                           const PathFollowerOptions& options)
    : path_(std::move(path)), loader_(loader), options_(options) {
  if (const std::string why = options.Invalid(); !why.empty()) throw std::invalid_argument(why);
  if (path_.size() < 2) throw std::invalid_argument("path follower: the path has < 2 samples");
}

Eigen::Vector2d PathFollower::PointAt(double s) const {
  if (s >= path_.back().s) {
    const planning::PathSample& end = path_.back();
    return end.xy + (s - end.s) * Eigen::Vector2d(std::cos(end.heading), std::sin(end.heading));
  }
  const auto next =
      std::upper_bound(path_.begin(), path_.end(), s,
                       [](double v, const planning::PathSample& p) { return v < p.s; });
  if (next == path_.begin()) return path_.front().xy;
  const planning::PathSample& a = *(next - 1);
  const planning::PathSample& b = *next;
  const double t = (s - a.s) / std::max(b.s - a.s, 1e-9);
  return a.xy + t * (b.xy - a.xy);
}

SteeringCommand PathFollower::Update(const Eigen::Vector2d& hinge_xy, double heading,
                                     double articulation) {
  const Eigen::Vector2d forward(std::cos(heading), std::sin(heading));
  const Eigen::Vector2d axle = hinge_xy + loader_.hinge_to_front_axle * forward;
  // Nearest sample, searched forward from the last one (a window of a few metres): the path may
  // come back near itself, progress may not jump there.
  double best = (path_[nearest_].xy - axle).squaredNorm();
  for (std::size_t i = nearest_ + 1; i < path_.size(); ++i) {
    if (path_[i].s - path_[nearest_].s > 2 * options_.lookahead) break;
    const double d = (path_[i].xy - axle).squaredNorm();
    if (d < best) best = d, nearest_ = i;
  }
  const planning::PathSample& near = path_[nearest_];
  // Progress past the last sample: project onto the straight continuation.
  double s_axle = near.s;
  if (nearest_ + 1 == path_.size()) {
    s_axle += std::max(
        0.0, (axle - near.xy).dot(Eigen::Vector2d(std::cos(near.heading), std::sin(near.heading))));
  }
  SteeringCommand out;
  const Eigen::Vector2d normal(-std::sin(near.heading), std::cos(near.heading));
  out.cross_track = (axle - near.xy).dot(normal);
  out.remaining = path_.back().s - s_axle;

  const Eigen::Vector2d target = PointAt(s_axle + options_.lookahead);
  const Eigen::Vector2d chord = target - axle;
  const double alpha =
      std::atan2(forward.x() * chord.y() - forward.y() * chord.x(), forward.dot(chord));
  const double max_curvature = loader_.MaxCurvature();
  const double curvature = std::clamp(2.0 * std::sin(alpha) / std::max(chord.norm(), 1e-3),
                                      -max_curvature, max_curvature);
  const double gamma = loader_.ArticulationFor(curvature);
  out.articulation_rate =
      std::clamp(options_.articulation_gain * (gamma - articulation),
                 -options_.max_articulation_rate, options_.max_articulation_rate);
  // v² = v_f² + 2 a d: cruise, then slow to the final speed by the path's end.
  const double d = std::max(out.remaining, 0.0);
  const double lag_factor = std::clamp(1.0 - std::abs(gamma - articulation) / options_.lag_span,
                                       options_.min_speed_factor, 1.0);
  out.speed = lag_factor * std::min(options_.cruise_speed,
                                    std::sqrt(options_.final_speed * options_.final_speed +
                                              2 * options_.deceleration * d));
  return out;
}

}  // namespace autoshovel::control
