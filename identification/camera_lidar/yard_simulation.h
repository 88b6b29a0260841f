// Simulated frames for step 2 of Algorithm 1: the forward camera and LiDAR of a machine parked
// at a few places in a scenario's yard (runtime/plant scenario, sensors ray casting). The LiDAR
// cloud integrates `lidar_frames` consecutive frames of the scan pattern with the machine
// standing still (a Livox rosette needs a few to cover its field of view). The camera is placed
// by the *true* extrinsic given (so a drift can be simulated: the board was calibrated with one
// extrinsic, the yard frames are seen with another). Masks: connected components of a per-pixel
// instance image (each box of the scene — a wall, a fence, a parked loader's part —, the floor,
// the piles, the sky apart), a SAM stand-in with exact boundaries; the simulator's classes
// alone would merge the walls of neighbouring bins into one mask that no cloud segmentation
// reproduces, which biases F_S. The own machine's bodies are not simulated (no plant is run).
//
// Default poses: translation is seen only through parallax, f·Δt/Z ≈ 1 px for 2 cm at 5 m with
// this camera (f = 260 px), so the five default poses put bin walls' ends, a parked loader,
// fences and debris at 4–8 m (the three earlier poses saw the bins at 10–20 m, where x moved ρ
// by < 0.5 % over ±10 cm).
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
  cv::Mat image;      ///< BGR
  cv::Mat labels;     ///< CV_8U simulator classes
  cv::Mat instances;  ///< CV_32S: 0 sky, 1 floor, 2 pile, 3 + i box i of the scene
  sensors::PointCloud cloud;
  MaskSet masks;
};

struct YardSimulationOptions {
  std::string scenario = "mixing_station";
  int lidar_frames = 3;
  /// Machine poses (hinge x [m], y [m], heading [rad]) in the world; empty: five poses near the
  /// mixing station's bins (see above).
  std::vector<Eigen::Vector3d> machine_poses;
  unsigned long long seed = 1;
  /// Masks from `instances` (each box, the floor, each pile apart) rather than from `labels`.
  bool instance_masks = true;
};

std::vector<YardFrame> SimulateYardFrames(const model::MachineDescription& machine,
                                          const model::Lidar& lidar,
                                          const Eigen::Isometry3d& T_lidar_camera,
                                          const std::string& models_dir,
                                          const YardSimulationOptions& options = {});

}  // namespace autoshovel::identification
