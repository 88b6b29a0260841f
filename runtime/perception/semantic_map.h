// The semantic layers of the elevation map (wheel-loader seed §4.3, Fig. 5): per-cell class
// confidences projected from the segmentation's per-pixel probabilities (Eq. 5), the ground
// plane by RANSAC with its fit variance, the height confidence p1 of Eq. (10) and the fused class
// of Eq. (11):
//   Obstacle  if p̂3 > max(p̂1, p̂2);   Pile  else if p1 + p̂1 < p2 + p̂2;   Ground otherwise,
// with p̂1, p̂2, p̂3 the semantic confidences of ground, pile and obstacle (other loaders,
// people, walls, anything else) and p2 = 1 − p1.
//
// Layers added to the map: "ground_confidence", "pile_confidence", "obstacle_confidence"
// (p̂1..p̂3, averaged over the frames that saw the cell), "semantic_frames" (how many),
// "height_ground_confidence" (p1), "class" (a CellClass value, NaN where the height is
// unknown) and "steep_obstacle_confidence" (p̂3 with a machine, person or wall in the footprint
// counted in full only from views that are not grazing: the evidence that an obstacle stands
// in the cell, which the look-aheads use).
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "runtime/model/description.h"
#include "runtime/perception/elevation_map.h"

namespace autoshovel::perception {

enum class CellClass { kGround = 0, kPile = 1, kObstacle = 2 };

/// Per-pixel probabilities of the core::SemanticClass classes: kNumSemanticClasses planes of
/// width × height, row-major (the layout of the segmentation's output).
struct ClassProbabilities {
  int width = 0, height = 0;
  std::vector<float> planes;
};

/// One-hot probabilities from labels (ground truth, or a segmentation's argmax).
ClassProbabilities FromLabels(const std::vector<std::uint8_t>& labels, int width, int height);

struct SemanticMapConfig {
  /// Weight of a new frame's confidences against the cell's running average, at least
  /// 1/frames (a plain mean over the first frames, then an exponential memory) [-].
  double min_frame_weight = 0.3;
  /// A cell is taken as seen by a pixel when its depth is within this of the nearest depth
  /// projected into the same 4 × 4 pixel block (occlusion test) [m] plus 3 % of the depth.
  double occlusion_tolerance = 0.5;
  /// A cell whose image footprint lies within a pixel block of a surface nearer than this
  /// fraction of its depth (less `occlusion_tolerance`) sits beside an occluding contour and
  /// takes no class evidence from that frame [-].
  double contour_depth_ratio = 0.8;
  /// For "steep_obstacle_confidence", a machine, person or wall pixel in a cell's footprint
  /// counts in full only when the cell's surface spans more than this many image rows; seen
  /// flatter, its pixels are averaged like the rest [rows].
  int min_rows_for_hard = 2;
  /// A machine, person or wall pixel counts in full for a cell only when its ray meets the
  /// mapped surface no farther than this behind the cell's depth; farther, it shows what
  /// stands behind the cell (a wall past a pile's crest) and is averaged like the rest [m].
  /// Half a metre: a ray onto an obstacle standing in the cell meets its mapped face within a
  /// cell or two of the cell's centre.
  double behind_tolerance = 0.5;
  /// A pixel's ray meets the mapped surface when it passes this far below it (heights
  /// bilinear between cell centres): a ray skimming a pile's crest is not taken as ending on
  /// it [m].
  double skim_height = 0.15;
  double ground_z0 = 0.3;          ///< z0: cells at or below this height fit the ground [m]
  double ransac_threshold = 0.05;  ///< inlier distance of the plane fit [m]
  int ransac_iterations = 200;
};

class SemanticMap {
 public:
  explicit SemanticMap(ElevationMap& map, const SemanticMapConfig& config = {});

  /// Eq. (5): projects every cell with a height into the image through the camera model and
  /// `T_world_camera` (the camera's body frame: x forward, y left, z up, as in a description)
  /// and averages the confidences of the visible ones. Returns the cells updated.
  long Project(const ClassProbabilities& probabilities, const model::Camera& camera,
               const Eigen::Isometry3d& T_world_camera);

  /// RANSAC ground plane on cells at or below z0, Eq. (10) and Eq. (11) on every cell with a
  /// height. Returns false (layers unchanged) when fewer than 3 ground cells exist.
  bool Fuse();

  /// The fitted ground plane z = a x + b y + c and its fit variance σz² (after Fuse()).
  const Eigen::Vector3d& ground_plane() const { return plane_; }
  double ground_variance() const { return ground_variance_; }

  ElevationMap& elevation() { return map_; }

 private:
  ElevationMap& map_;
  SemanticMapConfig config_;
  Eigen::Vector3d plane_ = Eigen::Vector3d::Zero();
  double ground_variance_ = 0;
};

/// The class a cell would get from the semantic confidences alone (argmax of p̂) and from the
/// height alone (p1 vs p2): the baselines the fusion is measured against.
CellClass SemanticOnlyClass(float ground, float pile, float obstacle);
CellClass HeightOnlyClass(float height_ground_confidence);

}  // namespace autoshovel::perception
