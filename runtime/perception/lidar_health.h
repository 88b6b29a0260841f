// LiDAR health: azimuth sectors in which a LiDAR fired downward and heard nothing back (issue 9,
// fault "lidar_dead_sector": a cracked window, mud on part of it, a failed emitter bank).
//
// A ray that leaves the sensor at least `min_depression` below the world's horizon meets the
// yard floor within h / sin(min_depression) (3.75 m / sin 12° = 18 m for the XCMG's top LiDAR),
// at an incidence where the LiDAR equation gives a return with probability ≈ 1 (lidar.h), or
// meets the machine itself or an obstacle nearer still. A sector where many such rays were fired
// and not one came back is therefore blind, not looking at nothing. Sky and far grazing ground
// never count: only downward rays make a sector's expectation. Nor does a downward ray whose
// floor point lies where the map has never seen ground (`ground_known`): past the edge of a
// simulated yard there is nothing to return from, and on a real site the same test keeps a
// quarry's drop-off from reading as a blind sector.
#pragma once

#include <Eigen/Geometry>
#include <functional>
#include <vector>

#include "runtime/sensors/sensor_data.h"

namespace autoshovel::perception {

struct LidarHealthConfig {
  double bin = 5.0 * 3.14159265358979323846 / 180;              ///< azimuth bin width [rad]
  double min_depression = 12.0 * 3.14159265358979323846 / 180;  ///< see above [rad]
  int min_expected_rays = 20;  ///< downward rays a bin needs before silence means blindness
};

/// An azimuth interval [from, to] in the machine's body frame (x forward, y left), radians,
/// from < to; within [−π, π] except that a sector across the rear starts below −π.
struct AzimuthSector {
  double from = 0, to = 0;
};

/// The blind sectors of one frame. `ray_directions_sensor`: every ray the sensor fired for the
/// frame (unit, sensor frame); `cloud`: the returns it got; `R_body_sensor` turns sensor
/// directions into the machine's body frame (azimuths are reported there), `R_world_sensor`
/// into the world (for the downward test). Adjacent blind bins merge into one sector.
/// `ground_known(d_world)`, when given, says whether a downward ray of world direction d_world
/// would meet floor the map knows; rays it refuses make no expectation.
std::vector<AzimuthSector> BlindSectors(
    const std::vector<Eigen::Vector3d>& ray_directions_sensor, const sensors::PointCloud& cloud,
    const Eigen::Matrix3d& R_body_sensor, const Eigen::Matrix3d& R_world_sensor,
    const LidarHealthConfig& config = {},
    const std::function<bool(const Eigen::Vector3d&)>& ground_known = {});

/// Whether `sector` overlaps the cone of half-angle `half_angle` around the body's azimuth
/// `direction` (0: straight ahead, π: behind).
bool SectorFaces(const AzimuthSector& sector, double direction, double half_angle);

}  // namespace autoshovel::perception
