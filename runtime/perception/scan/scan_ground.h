// The ground under a user's own scan (issue 43): a cloud may come in any frame (a Livox's
// scanner frame has z along the range axis, not up), so the floor is found from the data.
//
// RANSAC (PCL's SACSegmentation, SACMODEL_PLANE, fixed seed) takes the largest planes off the
// cloud one after the other; each normal is turned to face the scanner (the sensor sees the
// floor's upper side), or to agree with `up` when the user gives it. The floor is the largest
// of them with (almost) all points on its upper side: a heap covering most of a bin's floor is
// a large plane too, but with the floor and the walls' feet below it. The plane is refitted by
// least squares to its inliers within half the threshold, and the floor's noise σ is their robust
// spread (1.4826 · median |distance|). Further planes (bin walls) are taken off the rest the same
// way while they hold at least `min_plane_fraction` of the points and stand steeper than
// `wall_min_tilt` to the floor.
//
// No floor in view. Where no candidate has the scene above it, there is no floor in the scan:
// typically the top of a heap that fills a bin wall to wall, scanned from above (the real site
// bins are such scans: but for one stray return, every point lies within −0.45…+0.64 m of one
// gently tilted surface). Taking the best-fitting plane as the floor would report the heap's
// bumps above its own mean surface as its volume, so no floor is claimed: `ok` is false, the
// failure says why, and `surface` holds the heap top's mean plane, so that the caller can still
// map the surface's relief and its form (heaped or drawn down). The floor can then be given
// (`floor`: a surveyed plane, or the bin's floor known from its drawings) or measured on a scan
// of the empty place.
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
  /// Walls: share of the points a plane must hold [-]. A bin filled high shows little of its
  /// walls (a 1.5 m wall above 0.9 m of material, seen from above: 2–4 % of the returns each).
  double min_plane_fraction = 0.02;
  double wall_min_tilt = 1.0;  ///< walls: at least this steep against the floor [rad]
  int max_walls = 6;
  double min_ground_fraction = 0.05;  ///< a floor holding fewer points than this is no floor
  int floor_candidates = 8;           ///< largest planes considered for the floor
  /// The floor has this share of the points above it (within 2 thresholds): everything stands
  /// on it but a few stray returns. A slab of a heap's surface has far fewer (the real bin scans'
  /// best slabs: 79 and 94 %), and so had the floor inside the lab box, above the ground the box
  /// stands on (95 %, where the ground has 99.9 %).
  double floor_min_above = 0.99;
  /// The floor given by the user, n·p = d in the cloud's frame (n = xyz, d = w; n need not be
  /// unit length, and is turned to face the scanner): no floor is searched for.
  std::optional<Eigen::Vector4d> floor;
};

struct ScanGround {
  bool ok = false;
  std::string failure;       ///< why there is no floor ("" when ok)
  bool floor_given = false;  ///< the floor is the user's (ScanGroundOptions::floor)
  ScanPlane floor;
  /// No floor in view: the least-squares plane of all points, the mean plane of the surface the
  /// scan shows (noise and inliers those of the largest RANSAC plane); the ground frame is then
  /// on it (heights are relief about it, not heights above a floor).
  std::optional<ScanPlane> surface;
  /// The largest share of the points any floor candidate had above it [-].
  double best_above = 0;
  std::vector<ScanPlane> walls;
  /// The ground frame: z up along the floor normal, origin on the floor below the inliers'
  /// centroid; p_ground = T_ground_scan · p_scan.
  Eigen::Isometry3d T_ground_scan = Eigen::Isometry3d::Identity();
  double threshold = 0;  ///< the RANSAC distance used [m]
};

/// The diagonal of the points' bounding box [m] (0 for none): the scale the floor's RANSAC
/// threshold, the map's cell and the registration's distances are taken from.
double ScanExtent(const std::vector<Eigen::Vector3d>& points);

ScanGround FindScanGround(const std::vector<Eigen::Vector3d>& points_scan,
                          const Eigen::Vector3d& scanner_origin_scan,
                          const ScanGroundOptions& options = {});

}  // namespace autoshovel::perception
