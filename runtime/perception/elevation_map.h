// The elevation map of the yard (wheel-loader seed §4.1, Fig. 6): per cell a height and its
// variance, fused from LiDAR frames with the localisation pose by the Kalman update of Eq. (8),
//   h⁺ = (σp² h⁻ + σm² p_z)/(σm² + σp²),   σm²⁺ = σm² σp²/(σm² + σp²),   σp² = α_d d²,
// with returns on the machine itself removed (machine_footprint.h), rays that pass below a cell's
// lower confidence bound h − σ clearing it (dynamic obstacles), and holes filled from their
// nearest observed neighbour (Eq. 9), the filled cells flagged.
//
// Changes made on purpose must show at once. A Kalman filter that has seen a cell a hundred
// times is certain of it and would take a hundred frames to follow a bucket that just removed
// half a metre. So each frame's measurement of a cell is first tested against the cell: if the
// Mahalanobis distance |p_z − h| / sqrt(σm² + σp² + σr²) exceeds `change_gate` (σr, the cell's
// sub-cell roughness, keeps a surface sloping inside a cell from looking like a change), the
// cell is re-initialised from the new measurement instead of fused. A dug cell therefore drops
// to the new surface in the first frame that sees it.
//
// Layers: "elevation" [m], "variance" [m²], "filled" (1 where Eq. 9 supplied the height),
// "observed" (number of frames that measured the cell), "stamp" (last measurement time [s]).
#pragma once

#include <Eigen/Geometry>
#include <string>

#include "runtime/perception/grid_map.h"
#include "runtime/perception/machine_footprint.h"
#include "runtime/sensors/sensor_data.h"

namespace autoshovel::perception {

struct ElevationMapConfig {
  double resolution = 0.30;            ///< ε, cell edge [m] (seed Table 1)
  Eigen::Vector2d length{60.0, 60.0};  ///< map size [m]: a 60 m × 60 m yard
  double alpha_d = 0.05;               ///< α_d of σp² = α_d d² [1/m²·m²] (seed Table 1)
  double max_ray_length = 60.0;        ///< returns farther than this are ignored [m]
  double min_ray_length = 0.5;         ///< and nearer than this (sensor housing) [m]
  double initial_variance = 1e4;       ///< σm² of a cell never measured [m²]
  double roughness = 0.05;             ///< σr: sub-cell height spread allowed by the gate [m]
  double change_gate = 4.0;            ///< Mahalanobis distance that re-initialises a cell
  /// Variance added per second to every measured cell, so that the map keeps listening.
  double process_noise = 1e-4;  ///< [m²/s]
  /// Every n-th return also clears the cells its ray crosses (1: every ray). Rays are dense;
  /// a stride keeps clearing within the throughput budget.
  int clearing_stride = 4;
  double clearing_margin = 0.05;   ///< the ray must pass this far below h − σ [m]
  double max_fill_distance = 3.0;  ///< Eq. (9) fills holes up to this far from data [m]
  double max_pose_age = 0.2;       ///< a frame whose pose is older than this is refused [s]
};

/// What one frame did to the map.
struct MapUpdateStats {
  bool applied = false;
  std::string refused;     ///< why the frame changed nothing ("" when applied)
  long points = 0;         ///< returns in the frame
  long non_finite = 0;     ///< NaN/inf coordinates, dropped
  long on_machine = 0;     ///< inside the machine footprint, dropped
  long out_of_range = 0;   ///< outside [min, max] ray length or the map
  long fused = 0;          ///< returns used
  long cells_fused = 0;    ///< cells updated by Eq. (8)
  long cells_reset = 0;    ///< cells re-initialised by the change gate
  long cells_cleared = 0;  ///< cells cleared by rays passing below them
};

class ElevationMap {
 public:
  explicit ElevationMap(const ElevationMapConfig& config = {},
                        const Eigen::Vector2d& center = Eigen::Vector2d::Zero());

  /// Fuses one LiDAR frame. `T_world_sensor` is the localisation pose of the sensor at
  /// `pose_stamp`; a frame more than `max_pose_age` younger than its pose, an empty frame or
  /// a non-finite pose leaves the map unchanged (stats.refused says which). `footprint`, when
  /// given, removes returns on the machine.
  MapUpdateStats Update(const sensors::PointCloud& cloud, const Eigen::Isometry3d& T_world_sensor,
                        double pose_stamp, const MachineFootprint* footprint = nullptr);

  /// Eq. (9): every unobserved cell within `max_fill_distance` of an observed one takes the
  /// height of its nearest observed cell (and the values of the layers registered with
  /// FillAlso, e.g. the semantic confidences) and is flagged "filled". Returns the cells filled.
  long FillHoles();
  /// Layers that hole filling copies from the nearest observed cell along with the height.
  void FillAlso(const std::string& layer) { fill_also_.push_back(layer); }

  /// Keeps the machine near the middle of the map (cells that leave are forgotten).
  void FollowTo(const Eigen::Vector2d& center_xy) { map_.Move(center_xy); }

  const GridMap& map() const { return map_; }
  GridMap& map() { return map_; }
  const ElevationMapConfig& config() const { return config_; }

  /// Height at a world point (its cell), NaN when unknown.
  float HeightAt(const Eigen::Vector2d& xy) const;

 private:
  ElevationMapConfig config_;
  GridMap map_;
  double last_stamp_ = -1e300;
  // Per-frame scratch, sized to the map: the frame's own fused estimate per cell.
  Eigen::MatrixXf frame_height_, frame_variance_;
  std::vector<int> touched_;
  std::vector<std::string> fill_also_;
};

}  // namespace autoshovel::perception
