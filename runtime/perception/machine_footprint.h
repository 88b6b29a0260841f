// The area the machine itself occupies, to drop LiDAR returns from its own body before mapping
// (wheel-loader seed §4.1): two rectangles turning about the articulation hinge, their angle from
// the steering encoder, the front one as long as the bucket tip reaches (Eq. 2 through the
// generated kinematics, computed by the caller from the IMU angles).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "runtime/model/description.h"

namespace autoshovel::perception {

struct MachineFootprint {
  Eigen::Vector2d hinge_xy = Eigen::Vector2d::Zero();  ///< world [m]
  double heading_front = 0;  ///< front frame's x axis from world x [rad] (localisation)
  double articulation = 0;   ///< γ = ψ_front − ψ_rear [rad] (encoder)
  double front_length = 0;   ///< hinge to the farthest point ahead: bucket tip + margin [m]
  double rear_length = 0;    ///< hinge to the counterweight + margin [m]
  double half_width = 0;     ///< half the wider of bucket and body, + margin [m]
  double max_height = 0;     ///< points higher than this are above the machine [m, world z]
  double floor_height = 0;   ///< ground level under the machine [m, world z]

  /// True if a world point lies on the machine.
  bool Contains(const Eigen::Vector3d& p_world) const {
    if (p_world.z() > floor_height + max_height) return false;
    const Eigen::Vector2d d = p_world.head<2>() - hinge_xy;
    auto inside = [&](double heading, double from, double to) {
      const double c = std::cos(heading), s = std::sin(heading);
      const double along = c * d.x() + s * d.y(), across = -s * d.x() + c * d.y();
      return along >= from && along <= to && std::abs(across) <= half_width;
    };
    return inside(heading_front, 0.0, front_length) ||
           inside(heading_front - articulation, -rear_length, 0.0);
  }
};

/// The footprint of a wheel loader from its description, the localisation pose, the encoder's
/// articulation and the tip's horizontal reach from the hinge (Eq. 2 on the IMU angles). The
/// margins cover what the description does not draw: 0.3 m beyond the tip and the sides, the
/// body 2.5 m behind the rear axle (counterweight), 4.5 m of height (cab, raised boom).
inline MachineFootprint LoaderFootprint(const model::MachineDescription& machine,
                                        const Eigen::Vector2d& hinge_xy, double heading_front,
                                        double articulation, double tip_reach) {
  MachineFootprint f;
  f.hinge_xy = hinge_xy;
  f.heading_front = heading_front;
  f.articulation = articulation;
  f.front_length = tip_reach + 0.3;
  f.rear_length = machine.chassis.hinge_to_rear_axle + 2.5;
  f.half_width = std::max(machine.bucket.width, machine.chassis.track_width) / 2 + 0.3;
  f.max_height = 4.5;
  return f;
}

}  // namespace autoshovel::perception
