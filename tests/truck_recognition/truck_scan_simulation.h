// Test support for truck recognition (excavator seed §2, §4.1): a scene of boxes and cone-shaped
// dirt piles on flat ground, a haul truck built from boxes (cab, chassis, wheels, bed floor, side
// walls, headboard, optional tailgate), and a two-axis scanning rangefinder: a mirror sweeping
// the beam round a vertical circle while the head pans about the vertical axis, with Gaussian
// range noise and random dropouts. Test-only; the recogniser never sees the scene, only the
// scanlines.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <random>
#include <string>
#include <vector>

#include "runtime/app/truck_scan/truck_placement.h"
#include "runtime/perception/truck/scanline.h"

namespace autoshovel::perception::truck_sim {

using Rng = std::mt19937_64;

struct SimBox {
  Eigen::Isometry3d T_world_box = Eigen::Isometry3d::Identity();  ///< box centre and axes
  Eigen::Vector3d half_extents = Eigen::Vector3d::Ones();         ///< [m]
};

/// A dirt pile: a cone at the angle of repose standing on the ground.
struct SimCone {
  Eigen::Vector2d p_world_centre = Eigen::Vector2d::Zero();
  double height = 2;       ///< [m]
  double base_radius = 3;  ///< [m]
};

struct SimScene {
  double ground_z = 0;  ///< flat ground
  std::vector<SimBox> boxes;
  std::vector<SimCone> cones;

  /// A box of `size` whose bottom centre stands at `p_world_bottom`, turned by `yaw_rad`.
  void AddBox(const Eigen::Vector3d& p_world_bottom, double yaw_rad, const Eigen::Vector3d& size);
};

/// Distance along the unit ray to the first surface, or +inf within `max_range`.
double CastRay(const SimScene& scene, const Eigen::Vector3d& origin,
               const Eigen::Vector3d& direction, double max_range);

/// Body and chassis of a haul truck [m]: the yard simulation's (runtime/app/truck_scan), so the
/// recogniser's tests and the excavator's scans see the same trucks.
using TruckSpec = app::TruckBody;

/// Representative bodies (rounded, not one manufacturer's data): a 3-axle road tipper of about
/// 15 t payload, a 4-axle tipper of about 20 t and a 38 t articulated hauler without tailgate.
inline TruckSpec Tipper15t() { return app::TruckBodyOf(app::TruckClass::kTipper15t); }
inline TruckSpec Tipper20t() { return app::TruckBodyOf(app::TruckClass::kTipper20t); }
inline TruckSpec Hauler38t() { return app::TruckBodyOf(app::TruckClass::kHauler38t); }

/// What the recogniser should report for a truck placed in a scene.
struct TruckTruth {
  /// Origin at the centre of the opening on the rim plane, x toward the cab, z up.
  Eigen::Isometry3d T_world_bed = Eigen::Isometry3d::Identity();
  double yaw_rad = 0;
  double length = 0;
  double width = 0;
  double wall_height = 0;
  double floor_height = 0;
  double rim_height = 0;
  std::array<Eigen::Vector3d, 4>
      p_world_corners{};  ///< front-left, front-right, rear-right, rear-left
  /// Plan circle that holds the whole truck (for placing clutter clear of it).
  Eigen::Vector2d p_world_footprint_centre = Eigen::Vector2d::Zero();
  double footprint_radius = 0;
};

/// Adds the truck with its bed centre at `p_world_bed_xy`, heading `yaw_rad` (cab direction).
TruckTruth AddTruck(const TruckSpec& spec, const Eigen::Vector2d& p_world_bed_xy, double yaw_rad,
                    SimScene* scene);

struct ScannerSpec {
  Eigen::Vector3d p_world_sensor{0.0, 0.0, 4.8};  ///< mirror centre [m]
  double pan_start_deg = 35;  ///< azimuth of the first scanline (0: world +x, 90: +y)
  double pan_end_deg = 145;
  double pan_step_deg = 0.6;  ///< pan per mirror revolution
  /// The part of the scan circle that can return anything useful: from steeply down to just
  /// above the horizon (the rear half looks into the machine) [deg].
  double elevation_min_deg = -70;
  double elevation_max_deg = 10;
  double elevation_step_deg = 0.45;
  double max_range = 40;            ///< [m]
  double range_noise_sigma = 0.03;  ///< Gaussian range noise [m]
  double dropout_probability = 0.03;
  /// The head keeps panning while the mirror turns, so a scanline is a slightly twisted plane.
  bool pan_during_sweep = true;
};

/// One scanline per pan step, returns in mirror order; misses and dropouts are invalid.
std::vector<Scanline> SimulateScan(const SimScene& scene, const ScannerSpec& scanner, Rng& rng);

}  // namespace autoshovel::perception::truck_sim
