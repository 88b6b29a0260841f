// Depth discontinuities of a LiDAR cloud: the points that lie on the silhouette of a nearer
// object against a farther one. Our extension of the consistency score (consistency_score.h,
// "edge term"): where the extrinsic is right, these points project onto the boundaries of the
// image's masks. The cue is the one of Levinson & Thrun ("Automatic Online Calibration of
// Cameras and Lasers", RSS 2013): for each point the range jump to its horizontal neighbours,
// X_i = max(r_left − r_i, r_right − r_i, 0)^γ.
//
// Neighbours are found without a ring index (a PCD need not carry one, and a non-repetitive
// scanner has none): the points are binned into a range image in the LiDAR frame by elevation
// (rows: the scan lines, found as runs of elevations without a gap wider than `row_gap`, at most
// `row_height` tall) and azimuth (columns of `column_width`); a point's left and right
// neighbours are the nearest occupied cells of its row within `max_gap`. Only horizontal
// neighbours are compared: between rows the ground itself jumps in range (the next ring lands
// farther out), which would make every floor point an "edge".
#pragma once

#include <Eigen/Core>
#include <vector>

namespace autoshovel::identification {

struct DepthEdgeOptions {
  double row_gap = 0.05 * 3.14159265358979 / 180;      ///< a wider gap starts a row [rad]
  double row_height = 0.15 * 3.14159265358979 / 180;   ///< a row is at most this tall [rad]
  double column_width = 0.1 * 3.14159265358979 / 180;  ///< azimuth bin [rad]
  double max_gap = 1.0 * 3.14159265358979 / 180;       ///< farthest neighbour looked for [rad]
  double min_jump = 0.3;       ///< smaller range jumps are surface, not an edge [m]
  double min_relative = 0.05;  ///< …and jumps below this share of the range [-]
  double exponent = 0.5;       ///< γ of X_i (Levinson & Thrun) [-]
  double max_jump = 10.0;      ///< jumps are clipped here before γ [m]
};

struct DepthEdges {
  std::vector<float> weight;                ///< X_i ≥ 0 per point (0: not on an edge)
  std::vector<Eigen::Vector3f> silhouette;  ///< where the edge itself lies (half a step out)
};

/// Per point; the LiDAR frame's z axis is the scan's up.
DepthEdges FindDepthEdges(const std::vector<Eigen::Vector3f>& points_lidar,
                          const DepthEdgeOptions& options = {});

/// X_i ≥ 0 per point (0: not on a foreground edge). `up` is the LiDAR frame's z axis.
std::vector<float> DepthEdgeWeights(const std::vector<Eigen::Vector3f>& points_lidar,
                                    const DepthEdgeOptions& options = {});

}  // namespace autoshovel::identification
