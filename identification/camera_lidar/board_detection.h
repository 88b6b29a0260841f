// Step 1 of Algorithm 1 (seed §3.2, Fig. 4 right): hole corners of the board in the image
// (OpenCV) matched index by index with those found in the cloud (board_geometry.h), then PnP for
// the initial extrinsic T0.
//
// Image side: Otsu threshold of the undistorted grey image (the board is brighter than what is
// seen through its holes), contours with their hierarchy (cv::RETR_CCOMP): the board is an outer
// contour with four quadrilateral holes of similar area (cv::approxPolyDP); each hole's four
// vertices are refined with cv::cornerSubPix and ordered as in board_geometry.h.
//
// PnP: every board pose contributes 16 LiDAR-frame corners and their pixels; with several poses
// the 3D points are not coplanar and the pose is well conditioned. cv::solvePnP (iterative,
// DLT or homography start) and cv::solvePnPRefineLM give T_optical_lidar, hence T_lidar_camera.
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace autoshovel::identification {

struct BoardImageDetection {
  bool ok = false;
  std::string failure;
  std::vector<Eigen::Vector2d> corners_px;  ///< 16, detection order [px]
};

/// `image`: undistorted, BGR or grey.
BoardImageDetection DetectBoardInImage(const cv::Mat& image);

struct BoardObservation {
  std::vector<Eigen::Vector3d> corners_lidar;  ///< [m]
  std::vector<Eigen::Vector2d> corners_px;     ///< undistorted image [px]
};

struct BoardCalibration {
  bool ok = false;
  std::string failure;
  Eigen::Isometry3d T_lidar_camera = Eigen::Isometry3d::Identity();
  double reprojection_rms = 0;             ///< [px]
  std::vector<Eigen::Vector2d> residuals;  ///< per corner, detected − projected [px]
  int boards = 0;
};

/// The pose cv::solvePnP returns (Rodrigues vector, translation) as T_optical_lidar.
Eigen::Isometry3d PoseFromPnP(const cv::Mat& rvec, const cv::Mat& tvec);

/// Detected pixels minus their projection through K and T_optical_lidar, appended to
/// `residuals` [px]; returns their RMS.
double ReprojectionResiduals(const std::vector<cv::Point3d>& object,
                             const std::vector<cv::Point2d>& pixels, const Eigen::Matrix3d& K,
                             const Eigen::Isometry3d& T_optical_lidar,
                             std::vector<Eigen::Vector2d>& residuals);

BoardCalibration SolveBoardPnP(const std::vector<BoardObservation>& observations,
                               const Eigen::Matrix3d& K);

}  // namespace autoshovel::identification
