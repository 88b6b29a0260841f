// A user's own scans into the elevation map, and the volumes a site engineer reads off it
// (issue 43): clouds in any frame → the floor found from the data (scan_ground.h) → the Kalman
// elevation map of Eq. (8) in the floor's frame (elevation_map.h, with the sensor-noise model
// σp² = α_d d²) → heaps (connected cells standing above the floor) → per heap the volume above
// the floor and its standard deviation.
//
// Uncertainty of a heap's volume V = A Σ h_i (A the cell area):
//   σ_V² = A² Σ σ_i²  +  (A_heap σ_floor)²,
// the first term the cells' own Kalman variances (independent; a filled cell counts with the
// variance of the heap's measured heights, its relief), the second the floor plane's height
// uncertainty σ_floor = noise / √inliers, which shifts every cell of the heap together. The
// skirt of a heap lower than `min_heap_height` is not counted (a bias of at most that height
// times the skirt's area).
// Cells no return ever reached are not hidden: Eq. (9) fills holes from their nearest measured
// neighbour, and a heap reports the volume on filled cells apart (`filled_volume`), so a heap
// seen from one side only shows how much of it is guessed.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "runtime/perception/elevation_map.h"
#include "runtime/perception/scan/scan_ground.h"
#include "runtime/sensors/sensor_data.h"

namespace autoshovel::perception {

/// One cloud and where it was taken: `T_first_scan` maps its points into the first cloud's frame
/// (identity for the first cloud, or a user's --pose).
struct ScanCloud {
  std::string name;
  sensors::PointCloud cloud;
  Eigen::Isometry3d T_first_scan = Eigen::Isometry3d::Identity();
};

struct ScanMapOptions {
  double cell = 0;             ///< cell edge [m]; 0: the extent over 250, at least 5 mm
  double alpha_d = 4e-6;       ///< σp² = α_d d²: 2 cm at 10 m, a survey LiDAR's range noise [-]
  double min_heap_height = 0;  ///< [m]; 0: 4 σ of the floor, at least 1 cm
  int min_heap_cells = 20;     ///< smaller components are clutter [-]
  double max_fill_cells = 5;   ///< Eq. (9) fills holes this many cells from data [-]
  ScanGroundOptions ground;
};

struct Heap {
  int cells = 0, filled_cells = 0;
  double area = 0;           ///< [m²]
  double volume = 0;         ///< above the floor, measured and filled cells [m³]
  double volume_sigma = 0;   ///< [m³]
  double filled_volume = 0;  ///< the part on filled cells [m³]
  double peak = 0;           ///< [m]
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();  ///< ground frame [m]
};

struct ScanMap {
  bool ok = false;
  std::string failure;
  ScanGround ground;
  ElevationMap map;         ///< in the ground frame; layers elevation, variance, filled, heap
  std::vector<Heap> heaps;  ///< largest first; layer "heap" holds 1 + the heap's index
  long points = 0, points_used = 0, cells_observed = 0, cells_filled = 0;
  long points_at_origin = 0;               ///< 0 0 0 "no return" points dropped
  double height_low = 0, height_high = 0;  ///< 1st and 99th percentile above the floor [m]
  double seconds_floor = 0, seconds_map = 0, seconds_heaps = 0;  ///< where the time went
  double min_heap_height = 0;
};

/// `reference`: scans of the same place empty (the same frame as the first cloud, or placed by
/// their own T_first_scan): the floor is found on them, and heights are measured above them —
/// the heap is what the scans hold and the reference does not, on cells both know.
ScanMap BuildScanMap(const std::vector<ScanCloud>& clouds, const ScanMapOptions& options = {},
                     const std::vector<ScanCloud>* reference = nullptr);

}  // namespace autoshovel::perception
