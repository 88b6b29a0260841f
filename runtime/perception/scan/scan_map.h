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
// seen from one side only shows how much of it is guessed. The floor under a heap is not seen
// either: `floor_bias` is how far the volume moves if the floor there stands off the fitted
// plane by the floor's own RMS scatter (area × σ_floor,rms), a systematic bound reported beside
// the 1-σ figure, not added to it.
//
// Form. A heap is heaped (a cone or ridge: its middle stands above its edges) or drawn down (a
// crater where material was taken from below or from the middle: its edges stand above its
// middle), or level. The heights are fitted with a quadric z = c + g·x + xᵀ Q x over the heap's
// measured cells (x from their centroid); the form's height is the quadric's centre minus its
// mean over the cells, −tr(Q Σ) with Σ the cells' position covariance: > 0 heaped, < 0 drawn
// down, and level when smaller than a tenth of the heights' 5–95 % spread or three times the
// floor's noise. A scan without a floor gets the same reading of its surface.
//
// A reference scan taken from another pose is registered onto the scan first when the caller
// asks (scan_registration.h; `register_reference`).
//
// Walls. With the floor, the walls found (scan_ground.h) bound the heaps: cells on or behind a
// wall's inner face are marked in layer "wall" and belong to no heap. The face's plane is taken
// as unbounded, which suits one bin per scan (cells hidden behind a wall and filled by Eq. 9 from
// its top are left out with it); a divider between two bins in one scan would hide the second.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "runtime/perception/elevation_map.h"
#include "runtime/perception/scan/scan_ground.h"
#include "runtime/perception/scan/scan_registration.h"
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
  /// A return with no more than this many others in the 3 × 3 × 3 voxels (edge: 2 default
  /// cells) around it is a stray echo, dropped [-].
  int min_neighbours = 1;
  ScanGroundOptions ground;
  /// Register the reference onto the scan. Off by default: a scan cropped to the heap alone (the
  /// lab box's "balls only" scans) shares nothing with the empty one but the floor under the
  /// heap, and registration would lift the empty floor onto the heap. On for an empty scan taken
  /// from another set-up; the scans must share unchanged structure (walls, floor around the
  /// heap, surroundings).
  bool register_reference = false;
  ScanRegistrationOptions registration;
  /// A registered reference with fewer of its points on the scan than this is refused [-].
  double min_reference_overlap = 0.3;
};

/// Heaped, drawn down or level (see the header).
struct SurfaceForm {
  double height = 0;           ///< quadric centre minus its mean over the cells [m]; > 0 heaped
  double spread = 0;           ///< 5–95 % spread of the heights [m]
  std::string name = "level";  ///< "heaped", "drawn down" or "level"
};

struct Heap {
  int cells = 0, filled_cells = 0;
  double area = 0;           ///< [m²]
  double volume = 0;         ///< above the floor, measured and filled cells [m³]
  double volume_sigma = 0;   ///< [m³]
  double filled_volume = 0;  ///< the part on filled cells [m³]
  double floor_bias = 0;     ///< area × the floor's RMS scatter [m³] (systematic bound)
  double peak = 0;           ///< [m]
  SurfaceForm form;
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();  ///< ground frame [m]
};

struct ScanMap {
  bool ok = false;  ///< a map was built (with or without a floor)
  std::string failure;
  /// A floor under the map (or a reference scan): heights are above it and heaps have volumes.
  /// Without one (no floor in view, ground.failure says why) the map holds the surface's relief
  /// about its mean plane, `surface_form` reads its form, and there are no heaps.
  bool floor_found = false;
  SurfaceForm surface_form;
  ScanGround ground;
  std::optional<ScanRegistration> registration;  ///< of the reference, when registered
  ElevationMap map;         ///< in the ground frame; layers elevation, variance, filled, wall, heap
  std::vector<Heap> heaps;  ///< largest first; layer "heap" holds 1 + the heap's index
  long points = 0, points_used = 0, cells_observed = 0, cells_filled = 0;  ///< points: read
  long points_at_origin = 0;               ///< 0 0 0 "no return" points dropped
  long points_isolated = 0;                ///< stray returns dropped (min_neighbours)
  double height_low = 0, height_high = 0;  ///< 1st and 99th percentile above the floor [m]
  double seconds_floor = 0, seconds_map = 0, seconds_heaps = 0;  ///< where the time went
  double min_heap_height = 0;
};

/// `reference`: scans of the same place empty, placed roughly by their own T_first_scan and then
/// registered onto the scans (ScanMapOptions::register_reference): the floor is found on them,
/// and heights are measured above them — the heap is what the scans hold and the reference does
/// not, on cells both know.
ScanMap BuildScanMap(const std::vector<ScanCloud>& clouds, const ScanMapOptions& options = {},
                     const std::vector<ScanCloud>* reference = nullptr);

}  // namespace autoshovel::perception
