// What the sensors deliver: the structs a real driver fills as well as the simulator (DESIGN:
// "Real drivers fill the same structs"). Perception and control see these and nothing of the
// plant's ground truth. SI units throughout; every `stamp` is seconds on the machine's clock.
//
// Frames (models/README.md, runtime/plant/machine_state.h):
// - World: x east, y north, z up, origin on the yard floor.
// - Cab frame: the loader's rear frame (excavator: upper structure), origin on the ground below
//   the articulation hinge, x forward, y left, z up. Cameras, LiDARs, the cab IMU and the
//   localisation antenna ride on it.
// - LiDAR sensor frame: x forward along the sensor's boresight, y left, z up (the Velodyne and
//   Livox driver convention, REP 103). Its pose in the cab frame is the description's `pose`.
// - Camera: the image is row-major, row 0 at the top; pixel (u, v) is column u, row v. The
//   optical frame (x right, y down, z forward) is described in camera.h.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace autoshovel::sensors {

/// One LiDAR return.
struct LidarPoint {
  Eigen::Vector3f p_sensor = Eigen::Vector3f::Zero();  ///< in the sensor frame [m]
  /// Return strength as a calibrated sensor reports it: the target's Lambertian reflectivity
  /// seen at the beam's incidence, ρ·cos θ in [0, 1], the 1/r² of the LiDAR equation already
  /// compensated (Livox "reflectivity", Ouster "reflectivity" channel; multiply by 255 for the
  /// 8-bit value those drivers publish).
  float intensity = 0;
  std::uint16_t ring = 0;  ///< laser index: spinning, 0 = lowest beam; Livox, the emitter
  float time_offset = 0;   ///< firing time after the cloud's stamp [s]
};

/// One LiDAR frame (a sweep of a spinning head, or one integration window of a solid-state
/// sensor). Rays without a return are absent, as in the Velodyne/Livox ROS drivers' output.
struct PointCloud {
  double stamp = 0;    ///< time of the frame's first firing [s]
  std::string sensor;  ///< the description's LiDAR name
  std::vector<LidarPoint> points;
};

/// One camera image.
struct CameraFrame {
  double stamp = 0;  ///< exposure mid-time [s]
  int width = 0, height = 0;
  /// Per pixel core::SemanticClass values, row-major. Ground truth from the simulator; empty
  /// from a real camera (segmentation predicts them instead).
  std::vector<std::uint8_t> labels;
  /// 8-bit BGR (OpenCV channel order), 3 bytes per pixel, row-major: wraps as a CV_8UC3 Mat
  /// without a copy.
  std::vector<std::uint8_t> bgr;
};

/// One IMU attitude reading (an inclinometer-grade IMU's fused pitch and roll).
struct ImuSample {
  double stamp = 0;  ///< [s]
  std::string name;  ///< the description's IMU name
  /// θ of wheel-loader seed Eq. 1: the sensor's x axis from the horizontal, positive nose up,
  /// mounting offset α and bias included [rad].
  double pitch = 0;
  double roll = 0;  ///< about the sensor's x axis, right side down positive [rad]
};

/// The articulation encoder of a loader's centre hinge.
struct ArticulationSample {
  double stamp = 0;  ///< [s]
  double angle = 0;  ///< γ = ψ_front − ψ_rear [rad], positive: front frame turned left
};

/// Localisation (RTK-GNSS + heading, or a map matcher) of the cab frame in the world.
struct PoseSample {
  double stamp = 0;  ///< [s]
  double x = 0;      ///< cab frame origin, world [m]
  double y = 0;      ///< [m]
  double yaw = 0;    ///< cab x axis from world x, counter-clockwise [rad]
};

}  // namespace autoshovel::sensors
