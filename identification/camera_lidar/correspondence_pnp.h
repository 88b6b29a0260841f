// The board step from given 2D–3D correspondences (`calibrate camera-lidar --correspondences`):
// a user who picked corners by hand, or whose board detector is another tool, gets the same
// start for step 2 as the board calibration gives.
//
// The pixels are of the raw image: they are undistorted with (K, D) first (cv::undistortPoints
// back to pixels of the pinhole K), so the result is in the frame every other step uses. Then
// cv::solvePnPRansac (EPnP hypotheses, inliers within `ransac_threshold_px`, 99.9 %
// confidence) rejects mismatched pairs, and cv::solvePnPRefineLM polishes the pose on the
// inliers. With exactly 4 or 5 pairs RANSAC has nothing to reject and plain iterative PnP is used.
#pragma once

#include <string>
#include <vector>

#include "identification/camera_lidar/board_detection.h"
#include "identification/camera_lidar/camera_model.h"
#include "identification/camera_lidar/rig_files.h"

namespace autoshovel::identification {

struct CorrespondencePnPOptions {
  double ransac_threshold_px = 4.0;  ///< inlier reprojection error [px]
  int ransac_iterations = 1000;
};

struct CorrespondencePnP {
  BoardCalibration calibration;  ///< T_lidar_camera, reprojection RMS over the inliers, residuals
  int inliers = 0, total = 0;
};

CorrespondencePnP SolveCorrespondencePnP(const std::vector<Correspondence>& pairs,
                                         const CameraIntrinsics& intrinsics,
                                         const CorrespondencePnPOptions& options = {});

}  // namespace autoshovel::identification
