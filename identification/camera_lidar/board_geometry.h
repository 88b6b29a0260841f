// The calibration board of seed §3.2 / Fig. 4 (step 1 of Algorithm 1): a flat square board with
// four square holes, found by the LiDAR (the holes are gaps in the scan) and by the camera (the
// holes show the darker background).
//
// Board frame: origin at the board's centre, z the normal towards the sensors, y "up" as seen
// from them, x to their right (x = y × z). Corners are listed hole by hole, holes top-left,
// top-right, bottom-right, bottom-left, and the corners of each hole in the same order: the
// order both detectors use, so image and cloud corners correspond index by index.
//
// Cloud side (board_cloud.cc, PCL): RANSAC planes (up to three), the board is the plane facing
// the sensor (normal most aligned with the LiDAR's boresight, which discards the floor); its
// inliers are refined by least squares, the boundary points (outer edge and hole edges) found
// with pcl::BoundaryEstimation, and the board template — the outer square and the four hole
// squares, 20 edges of known size — is fitted to them in the plane (x, y, θ; Nelder–Mead on the
// truncated squared point-to-edge distance). Boundary points lie a half point spacing inside the
// material on every edge, so the offsets cancel between opposite edges and the fitted corners
// are unbiased, unlike corners of lines fitted to each hole on its own. The board must stand
// within ±40° of upright (the 90° symmetry of the board is broken by `up`).
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <string>
#include <vector>

namespace autoshovel::identification {

struct BoardGeometry {
  double side = 1.0;          ///< the board's outer square [m]
  double hole_side = 0.25;    ///< each hole's side [m]
  double hole_offset = 0.25;  ///< hole centres at (±offset, ±offset) in the board frame [m]

  /// The 16 hole corners in the board frame (z = 0), in detection order.
  std::vector<Eigen::Vector3d> HoleCorners() const;
  /// Whether the board frame point (x, y) is board material (inside the board, outside holes).
  bool IsMaterial(double x, double y) const;
  /// Empty when valid, otherwise what is wrong.
  std::string Check() const;
};

struct BoardCloudDetection {
  bool ok = false;
  std::string failure;  ///< why not, when !ok
  Eigen::Isometry3d T_lidar_board = Eigen::Isometry3d::Identity();
  std::vector<Eigen::Vector3d> corners_lidar;  ///< 16, detection order [m]
  int plane_inliers = 0;
  int boundary_points = 0;
  double edge_rms = 0;  ///< RMS distance of boundary points to the fitted edges [m]
};

/// `up_lidar`, `boresight_lidar`: gravity up and the viewing direction of the sensor pair in the
/// LiDAR frame (nominal mounting is accurate enough: they only break symmetries).
BoardCloudDetection DetectBoardInCloud(const std::vector<Eigen::Vector3f>& points_lidar,
                                       const BoardGeometry& board, const Eigen::Vector3d& up_lidar,
                                       const Eigen::Vector3d& boresight_lidar);

}  // namespace autoshovel::identification
