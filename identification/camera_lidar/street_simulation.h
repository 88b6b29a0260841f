// A synthetic scene with the traits of real calibration recordings (the CalibAnything street
// scenes), for tests of step 2 of Algorithm 1 beyond our simulated yard: a sloped ground with no
// dominant horizontal floor, clutter on it, cars, poles and a building front; no sky class (the
// camera's rays that hit nothing belong to no mask); a 32-line spinning LiDAR whose lines are
// sparse near the ground; an intensity that varies by material, with noise; a camera frame
// whose masks are the objects' exact silhouettes (a SAM stand-in: SAM's masks follow object
// outlines within a few pixels), ground included.
//
// Ray casting against boxes, vertical cylinders and a plane, in closed form: no scenario, no
// machine, no plant. Deterministic from the seed.
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "identification/camera_lidar/camera_model.h"
#include "identification/camera_lidar/mask_io.h"
#include "runtime/sensors/sensor_data.h"

namespace autoshovel::identification {

struct StreetSceneOptions {
  unsigned long long seed = 1;
  int width = 960, height = 600;     ///< camera image [px]
  double focal = 1100;               ///< [px]
  double ground_slope = 0.05;        ///< rise per metre along x (the road climbs ahead) [-]
  double ground_cross_slope = 0.02;  ///< along y [-]
  double lidar_height = 1.9;         ///< above the ground at the LiDAR [m]
  double range_noise = 0.02;         ///< σ [m]
  double intensity_noise = 0.04;     ///< σ [-]
  int lines = 32;                    ///< LiDAR scan lines from −16° to +15°, denser at 0
  double azimuth_step_deg = 0.2;
};

struct StreetFrame {
  CameraIntrinsics intrinsics;       ///< pinhole, no distortion
  Eigen::Isometry3d T_lidar_camera;  ///< the truth the frame was made with
  sensors::PointCloud cloud;         ///< the LiDAR's front half (±90°)
  MaskSet masks;                     ///< one per object seen, the ground among them
  cv::Mat image;                     ///< BGR, each object's colour with its shading
};

/// A camera 5 cm ahead, 10 cm left and 40 cm below the LiDAR, looking along its x axis, turned
/// 0.7° left and tilted 2° down: the mount `--simulate` and the tests use.
Eigen::Isometry3d StreetSceneMount();

/// `T_lidar_camera`: the camera body pose in the LiDAR frame (camera_model.h).
StreetFrame SimulateStreetFrame(const Eigen::Isometry3d& T_lidar_camera,
                                const StreetSceneOptions& options = {});

}  // namespace autoshovel::identification
