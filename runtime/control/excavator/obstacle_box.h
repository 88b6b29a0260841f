// A vertical box standing on the ground: a truck body, a truck cab, a person (excavator seed §4.4:
// known obstacles such as the truck; §4.5: people). Footprint centred
// at `center` and turned by `yaw` about z; solid from `z_min` up to `z_max`.
#pragma once

#include <Eigen/Core>

namespace autoshovel::control {

struct ObstacleBox {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();        ///< footprint centre [m]
  double yaw = 0;                                          ///< [rad]
  Eigen::Vector2d half_extents = Eigen::Vector2d::Zero();  ///< along, across [m]
  double z_min = 0;                                        ///< [m]
  double z_max = 0;                                        ///< top [m]

  /// Euclidean distance from `p` to the solid box [m]; negative inside (minus the depth).
  double SignedDistance(const Eigen::Vector3d& p) const;
  /// Horizontal distance from (x, y) to the footprint [m], 0 inside.
  double FootprintDistance(const Eigen::Vector2d& xy) const;
  /// The four footprint corners.
  void Corners(Eigen::Vector2d corners[4]) const;
};

/// Throws std::invalid_argument naming `what` when a value is not finite, an extent is not
/// positive or z_max <= z_min.
void Validate(const ObstacleBox& box, const char* what);

}  // namespace autoshovel::control
