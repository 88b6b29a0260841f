// Steering an articulated wheel loader along a planned path (the Dubins path of the front axle
// that shovel point selection returns, planning/dubins_path.h).
//
// Pure pursuit on the front axle: the curvature that joins the axle to the point `lookahead`
// metres further along the path, κ = 2 sin α / L_d (α: the angle between the front frame's
// heading and the chord), turned into the articulation that holds that curvature
// (LoaderGeometry::ArticulationFor, the planner's own steering model) and reached by a
// proportional articulation-rate command. Pure pursuit is chosen because it needs nothing but
// the pose and the path, tolerates the articulation lag (the lookahead smooths the curvature
// steps at the Dubins path's joints) and is the usual tracker for slow articulated machines.
// Beyond its end the path continues straight along the final heading, so the bucket keeps the
// entry heading into the pile while the scoop cycle crowds.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "runtime/planning/dubins_path.h"
#include "runtime/planning/shovel_point_selection.h"

namespace autoshovel::control {

struct PathFollowerOptions {
  double lookahead = 1.5;              ///< L_d [m]
  double articulation_gain = 2.0;      ///< rate command per articulation error [1/s]
  double max_articulation_rate = 0.4;  ///< [rad/s]
  double cruise_speed = 2.0;           ///< [m/s]
  double final_speed = 1.0;            ///< at the path's end (the attack speed) [m/s]
  double deceleration = 0.5;           ///< to slow from cruise to final before the end [m/s²]
  /// The machine slows while its articulation lags the one the path needs (a loader's steering
  /// turns at 10–15 °/s, so a curvature step takes seconds): the speed target is scaled by
  /// 1 − |γ_needed − γ| / `lag_span`, not below `min_speed_factor`.
  double lag_span = 0.4;          ///< [rad]
  double min_speed_factor = 0.2;  ///< [-]

  std::string Invalid() const;
};

struct SteeringCommand {
  double articulation_rate = 0;  ///< [rad/s]
  double speed = 0;              ///< target for the speed PID [m/s]
  double remaining = 0;          ///< path length left ahead of the front axle [m]
  double cross_track = 0;        ///< front axle to the path, left positive [m]
};

class PathFollower {
 public:
  /// `path`: front-axle samples (planning::SamplePath), at least two. Throws
  /// std::invalid_argument for bad options or a path of fewer than two samples.
  PathFollower(std::vector<planning::PathSample> path, const planning::LoaderGeometry& loader,
               const PathFollowerOptions& options = {});

  /// `hinge_xy`, `heading` (front frame), `articulation` γ: the machine now.
  SteeringCommand Update(const Eigen::Vector2d& hinge_xy, double heading, double articulation);

  const std::vector<planning::PathSample>& path() const { return path_; }

 private:
  /// The path point `s` metres from its start, straight on beyond its end.
  Eigen::Vector2d PointAt(double s) const;

  std::vector<planning::PathSample> path_;
  planning::LoaderGeometry loader_;
  PathFollowerOptions options_;
  std::size_t nearest_ = 0;  ///< progress along the path only moves forward
};

}  // namespace autoshovel::control
