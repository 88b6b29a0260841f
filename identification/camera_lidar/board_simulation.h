// A simulated board session (step 1 of Algorithm 1): the simulator has no calibration board, so
// it is ray cast here. The LiDAR fires its real scan pattern (sensors::LidarScanPattern,
// integrated over `integration_time`) at the board (analytic ray–plane with the holes) and, past
// it or through the holes, at the floor; range noise and intensity follow sensors/lidar.h. The
// camera image renders board (bright), holes and background (a dark wall of the calibration
// hall) through the pinhole with 4 × 4 supersampling (anti-aliased edges, as a real lens
// gives) and 2 DN Gaussian noise.
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <vector>

#include "identification/camera_lidar/board_geometry.h"
#include "runtime/model/description.h"
#include "runtime/sensors/rng.h"
#include "runtime/sensors/sensor_data.h"

namespace autoshovel::identification {

struct SimulatedBoardFrame {
  cv::Mat image;  ///< BGR, camera size
  sensors::PointCloud cloud;
  Eigen::Isometry3d T_base_board = Eigen::Isometry3d::Identity();
};

/// Five board poses (vehicle frame) 3.5–5.5 m in front of the camera, turned by up to ±20°.
std::vector<Eigen::Isometry3d> DefaultBoardPoses(const model::Camera& camera);

/// `T_lidar_camera`: the true extrinsic (camera body in the LiDAR frame).
SimulatedBoardFrame SimulateBoardFrame(const model::Camera& camera, const model::Lidar& lidar,
                                       const Eigen::Isometry3d& T_lidar_camera,
                                       const Eigen::Isometry3d& T_base_board,
                                       const BoardGeometry& board, double integration_time,
                                       sensors::Rng& rng);

}  // namespace autoshovel::identification
