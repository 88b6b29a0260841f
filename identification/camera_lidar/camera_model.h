// The camera model of the camera–LiDAR calibration and the frames it connects.
//
// Frames. T_lidar_camera is the pose of the camera *body* frame (x forward, y left, z up, the
// description's convention) in the LiDAR frame, so the calibrated camera pose in the vehicle
// frame is T_base_camera = T_base_lidar · T_lidar_camera (the overlay's `sensors.camera.pose`).
// Projection goes through the optical frame (x right, y down, z forward; sensors/camera.h):
//   p_optical = R_body_opticalᵀ · T_lidar_cameraⁱ⁻¹ · p_lidar,
//   λ (u, v, 1)ᵀ = K p_optical                                          (seed Eq. (5))
// with K the pinhole matrix of the *undistorted* image: images and masks are undistorted with
// (K, D) before use, so the score and the overlays never evaluate the distortion polynomial.
//
// Intrinsics files: the ROS camera_info YAML written by camera_calibration / kalibr_bagcreater
// (image_width, image_height, camera_matrix.data[9], distortion_model plumb_bob,
// distortion_coefficients.data[k1 k2 p1 p2 k3]), the format such intrinsics come in.
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "runtime/model/description.h"

namespace autoshovel::identification {

/// Pinhole matrix and OpenCV "plumb_bob" distortion (k1, k2, p1, p2[, k3]).
struct CameraIntrinsics {
  int width = 0, height = 0;                        ///< [px]
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();  ///< [px]
  std::vector<double> D;                            ///< empty or 4, 5, 8 values [-]
};

/// The description's ideal pinhole (no distortion).
CameraIntrinsics IntrinsicsFromDescription(const model::Camera& camera);

/// Reads a ROS camera_info YAML; throws core::InputError `file:line:column: key: message`.
CameraIntrinsics ReadCameraInfoYaml(const std::string& path);
void WriteCameraInfoYaml(const std::string& path, const CameraIntrinsics& intrinsics);

/// The image (or label image: `nearest` keeps label values) undistorted to the pinhole K.
/// Returns the input unchanged when D is empty or all zero.
cv::Mat Undistort(const cv::Mat& image, const CameraIntrinsics& intrinsics, bool nearest);

/// Body (x forward, y left, z up) ← optical (x right, y down, z forward).
Eigen::Matrix3d BodyFromOpticalRotation();
/// T_optical_lidar from T_lidar_camera (camera body frame in the LiDAR frame) and back.
Eigen::Isometry3d OpticalFromLidar(const Eigen::Isometry3d& T_lidar_camera);
Eigen::Isometry3d CameraInLidarFromOptical(const Eigen::Isometry3d& T_optical_lidar);

/// Projects p_lidar; false behind the camera (z_optical < 0.1 m) or outside the image.
bool ProjectPoint(const Eigen::Matrix3d& K, int width, int height,
                  const Eigen::Isometry3d& T_optical_lidar, const Eigen::Vector3d& p_lidar,
                  Eigen::Vector2d& uv, double& depth);

/// `a` ← `a` perturbed: rotation Exp(rotation) applied in the LiDAR frame, translation added.
Eigen::Isometry3d Perturb(const Eigen::Isometry3d& T_lidar_camera, const Eigen::Vector3d& rotation,
                          const Eigen::Vector3d& translation);

/// Rotation angle between a and b [rad] and distance of their origins [m].
struct PoseError {
  double rotation = 0;
  double translation = 0;
};
PoseError ComparePoses(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b);

/// Roll, pitch, yaw of R = Rz(ψ)·Ry(θ)·Rx(φ) (sensor_pose.h convention) [rad].
Eigen::Vector3d RollPitchYaw(const Eigen::Matrix3d& R);

}  // namespace autoshovel::identification
