// Pictures of the calibration (seed Fig. 12 and Fig. 11): LiDAR points projected into the image,
// coloured by depth (OpenCV's "jet": near red … far blue), before and after, side by side; and
// the score surface as 1-D slices per parameter.
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "identification/camera_lidar/auto_calibration.h"

namespace autoshovel::identification {

/// The image with `points_lidar` projected through K (undistorted image) and T_lidar_camera.
cv::Mat RenderProjection(const cv::Mat& image, const std::vector<Eigen::Vector3f>& points_lidar,
                         const Eigen::Matrix3d& K, const Eigen::Isometry3d& T_lidar_camera,
                         double max_depth = 30.0);

/// The image darkened, the mask boundaries (distance < 1 px) white and the depth-edge points
/// (ScoreFrame::edge_weight > 0) projected through T, coloured by depth: how the edge term sees
/// the frame.
cv::Mat RenderEdges(const cv::Mat& image, const ScoreFrame& frame,
                    const Eigen::Isometry3d& T_lidar_camera, double max_depth = 30.0);

/// Before | after, titled; written to `path` (PNG). Throws std::runtime_error when it cannot.
void WriteBeforeAfterPng(const std::string& path, const cv::Mat& image,
                         const std::vector<Eigen::Vector3f>& points_lidar, const Eigen::Matrix3d& K,
                         const Eigen::Isometry3d& before, const Eigen::Isometry3d& after);

/// Six panels of ρ against each parameter's offset; plus, when given, the board PnP residual
/// vectors (×20) as a seventh panel.
void WriteScoreSurfacePng(const std::string& path, const std::vector<ScoreSlice>& slices,
                          const std::vector<Eigen::Vector2d>& board_residuals_px = {});

}  // namespace autoshovel::identification
