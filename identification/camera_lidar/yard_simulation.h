// Simulated frames for step 2 of Algorithm 1: the forward camera and LiDAR of a machine parked
// at a few places in a scenario's yard (runtime/plant scenario, sensors ray casting). The LiDAR
// cloud integrates `lidar_frames` consecutive frames of the scan pattern with the machine
// standing still (a Livox rosette needs a few to cover its field of view). The camera is placed
// by the *true* extrinsic given (so a drift can be simulated: the board was calibrated with one
// extrinsic, the yard frames are seen with another). Masks: connected components of the
// simulator's per-pixel classes (MasksFromLabels), a SAM stand-in with exact boundaries. The
// own machine's bodies are not simulated (no plant is run).
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "identification/camera_lidar/mask_io.h"
#include "runtime/model/description.h"
#include "runtime/sensors/sensor_data.h"

namespace autoshovel::identification {

struct YardFrame {
  cv::Mat image;   ///< BGR
  cv::Mat labels;  ///< CV_8U simulator classes
  sensors::PointCloud cloud;
  MaskSet masks;
};

struct YardSimulationOptions {
  std::string scenario = "mixing_station";
  int lidar_frames = 3;
  /// Machine poses (hinge x [m], y [m], heading [rad]) in the world; empty: three poses facing the
  /// scenario's north bins.
  std::vector<Eigen::Vector3d> machine_poses;
  unsigned long long seed = 1;
};

std::vector<YardFrame> SimulateYardFrames(const model::MachineDescription& machine,
                                          const model::Lidar& lidar,
                                          const Eigen::Isometry3d& T_lidar_camera,
                                          const std::string& models_dir,
                                          const YardSimulationOptions& options = {});

}  // namespace autoshovel::identification
