// The ground under a user's own scan (issue 43): a cloud may come in any frame (a Livox's
// scanner frame has z along the range axis, not up), so the floor is found from the data.
//
// RANSAC (PCL's SACSegmentation, SACMODEL_PLANE, fixed seed) takes the largest planes off the
// cloud one after the other; each normal is turned to face the scanner (the sensor sees the
// floor's upper side), or to agree with `up` when the user gives it. The floor is the largest
// of them with (almost) all points on its upper side: a heap covering most of a bin's floor is
// a large plane too, but with the floor and the walls' feet below it. Where no candidate has
// the scene above it (the floor hidden under the material), the one with the most above it is
// taken, and the heights printed show it; `--up` and a scan with some floor in view settle it. The
// plane is refitted by least squares to its inliers within half the threshold, and the floor's
// noise σ is their robust spread (1.4826 · median |distance|). Further planes (bin walls) are taken
// off the rest the same way while they hold at least `min_plane_fraction` of the points and stand
// steeper than `wall_min_tilt` to the floor.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

namespace autoshovel::perception {

struct ScanPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit
  double offset = 0;                                  ///< normal · p = offset on the plane [m]
  int inliers = 0;
  double noise = 0;  ///< σ of the inliers' distances (robust) [m]
};

struct ScanGroundOptions {
  double threshold = 0;  ///< RANSAC inlier distance [m]; 0: 0.5 % of the cloud's extent, 5–50 mm
  std::optional<Eigen::Vector3d> up;  ///< gravity up in the cloud's frame, when known
  double min_plane_fraction = 0.05;   ///< walls: share of the points a plane must hold [-]
  double wall_min_tilt = 1.0;         ///< walls: at least this steep against the floor [rad]
  int max_walls = 6;
  double min_ground_fraction = 0.05;  ///< a floor holding fewer points than this is no floor
  int floor_candidates = 4;           ///< largest planes considered for the floor
  double floor_min_above = 0.95;      ///< the floor has this share of the points above it
};

struct ScanGround {
  bool ok = false;
  std::string failure;  ///< why there is no floor ("" when ok)
  ScanPlane floor;
  std::vector<ScanPlane> walls;
  /// The ground frame: z up along the floor normal, origin on the floor below the inliers'
  /// centroid; p_ground = T_ground_scan · p_scan.
  Eigen::Isometry3d T_ground_scan = Eigen::Isometry3d::Identity();
  double threshold = 0;  ///< the RANSAC distance used [m]
};

ScanGround FindScanGround(const std::vector<Eigen::Vector3d>& points_scan,
                          const Eigen::Vector3d& scanner_origin_scan,
                          const ScanGroundOptions& options = {});

}  // namespace autoshovel::perception
