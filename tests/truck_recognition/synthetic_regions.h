// Planar regions built directly from geometry, described the way GroupPlanarRegions describes
// what it grows, for testing the model's constraints and the tree search without scans.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "runtime/perception/truck/planar_regions.h"

namespace autoshovel::perception::truck_sim {

/// A vertical face: `normal` horizontal (toward the sensor), extent ±half_length along z × n,
/// heights [z_min, z_max], wall top `top_z`.
inline PlanarRegion VerticalRegion(const Eigen::Vector3d& normal, const Eigen::Vector3d& centroid,
                                   double half_length, double z_min, double z_max, double top_z,
                                   int num_points = 400) {
  PlanarRegion r;
  r.normal = normal.normalized();
  r.centroid = centroid;
  r.num_points = num_points;
  r.num_scanlines = 20;
  r.axis_u = Eigen::Vector3d::UnitZ().cross(r.normal).normalized();
  r.axis_v = r.normal.cross(r.axis_u);
  r.u_min = -half_length;
  r.u_max = half_length;
  r.v_min = z_min - centroid.z();
  r.v_max = z_max - centroid.z();
  r.z_min = z_min;
  r.z_max = z_max;
  r.top_z = top_z;
  r.bottom_z = z_min;
  return r;
}

/// A level face, normal up, extents ±half_u along `axis_u` (horizontal) and ±half_v across.
inline PlanarRegion FlatRegion(const Eigen::Vector3d& centroid, const Eigen::Vector3d& axis_u,
                               double half_u, double half_v, int num_points = 400) {
  PlanarRegion r;
  r.normal = Eigen::Vector3d::UnitZ();
  r.centroid = centroid;
  r.num_points = num_points;
  r.num_scanlines = 20;
  r.axis_u = axis_u.normalized();
  r.axis_v = r.normal.cross(r.axis_u);
  r.u_min = -half_u;
  r.u_max = half_u;
  r.v_min = -half_v;
  r.v_max = half_v;
  r.z_min = r.z_max = r.top_z = r.bottom_z = centroid.z();
  return r;
}

/// The faces of an ideal 20 t bed (inside 5.8 m × 2.35 m, 1.15 m walls, floor 1.55 m up, 7 cm
/// plates, headboard 0.3 m above the rim), centred on the world origin, heading +x, seen from a
/// scanner at (0, -8, 5): near side, far side, floor, headboard, tailgate, in BedFace order.
struct IdealBed {
  static constexpr double kLength = 5.8;
  static constexpr double kWidth = 2.35;
  static constexpr double kWall = 1.15;
  static constexpr double kFloor = 1.55;
  static constexpr double kThickness = 0.07;
  static constexpr double kRim = kFloor + kWall;

  static std::vector<PlanarRegion> Faces() {
    const double hl = 0.5 * kLength;
    const double hw = 0.5 * kWidth;
    const Eigen::Vector3d toward_sensor = -Eigen::Vector3d::UnitY();
    return {
        VerticalRegion(toward_sensor, {0, -hw - kThickness, kFloor + 0.4}, hl + kThickness,
                       kFloor - 0.25, kRim, kRim),
        VerticalRegion(toward_sensor, {0.2, hw, kRim - 0.3}, hl - 0.4, kRim - 0.6, kRim, kRim),
        FlatRegion({0, 0.6, kFloor}, Eigen::Vector3d::UnitX(), hl - 0.3, 0.5),
        VerticalRegion(-Eigen::Vector3d::UnitX(), {hl, 0.5, kFloor + 0.8}, 0.6, kFloor + 0.3,
                       kRim + 0.3, kRim + 0.3),
        VerticalRegion(Eigen::Vector3d::UnitX(), {-hl, 0.5, kFloor + 0.7}, 0.6, kFloor + 0.3, kRim,
                       kRim),
    };
  }
};

/// Flat ground at z = 0 as the ground estimate of a scene whose region `index` is the ground.
inline GroundEstimate FlatGround(int index = -1) {
  GroundEstimate ground;
  ground.found = true;
  ground.region = index;
  ground.normal = Eigen::Vector3d::UnitZ();
  ground.offset = 0;
  return ground;
}

}  // namespace autoshovel::perception::truck_sim
