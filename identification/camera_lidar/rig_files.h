// Files of a standalone camera–LiDAR rig (no machine description): the intrinsics and the
// extrinsic as the public calibration tools exchange them.
//
// Extrinsic convention of these files: T_optical_lidar, the 4×4 rigid transform that takes a
// point from the LiDAR frame into the camera's OpenCV optical frame (x right, y down, z forward),
// p_optical = R p_lidar + t. Internally the calibration works with T_lidar_camera, the camera
// *body* pose in the LiDAR frame (camera_model.h); OpticalFromLidar and CameraInLidarFromOptical
// convert between the two.
//
// Formats read:
// - CalibAnything's `calib.txt`: lines `K: k11 … k33` (9 values, row-major), `D: k1 k2 p1 p2
//   [k3]`, `T: r11 r12 r13 t1 r21 … t3` (the first 3 or all 4 rows of T_optical_lidar, row-major).
//   Lines may come in any order; `#` starts a comment; K and D are needed for intrinsics, T for
//   an extrinsic.
// - An extrinsic matrix file: 12 or 16 numbers (3×4 or 4×4, row-major, any whitespace, `#`
//   comments), or a calib.txt whose `T:` line is read.
// Every refusal is a core::InputError `file:line:column: message`; files over 1 MiB are refused
// before they are read.
//
// Perturbations follow the published CalibAnything protocol: a start is T_optical_lidar ·
// ΔT(roll, pitch, yaw, x, y, z) with ΔT = [Rz(yaw) Ry(pitch) Rx(roll) | (x, y, z)], i.e. the
// offset is applied to the LiDAR points first; the error of an estimate is T_ref · T_est⁻¹, read
// as a rotation angle and a translation length.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

namespace autoshovel::identification {

struct RigCalibrationFile {
  std::optional<Eigen::Matrix3d> K;                  ///< [px]
  std::vector<double> D;                             ///< k1 k2 p1 p2 [k3]
  std::optional<Eigen::Isometry3d> T_optical_lidar;  ///< the `T:` line
};

/// Parses calib.txt text (`source` names the file in messages). Throws core::InputError.
RigCalibrationFile ParseCalibTxt(const std::string& text, const std::string& source);
RigCalibrationFile ReadCalibTxt(const std::string& path);

/// Parses an extrinsic: 12/16 plain numbers or a calib.txt with a `T:` line. The rotation must be
/// orthonormal within 1e-3 (a file with a scaled or sheared matrix is refused, not repaired).
Eigen::Isometry3d ParseExtrinsic(const std::string& text, const std::string& source);
Eigen::Isometry3d ReadExtrinsic(const std::string& path);

/// The 4×4 matrix as text, one row per line, with a `#` comment header.
std::string ExtrinsicText(const Eigen::Isometry3d& T_optical_lidar, const std::string& comment);

/// 2D–3D correspondences for the board step (`--correspondences`): a pixel of the raw image
/// and the same point in the LiDAR frame.
struct Correspondence {
  Eigen::Vector2d uv;       ///< [px], raw (distorted) image
  Eigen::Vector3d p_lidar;  ///< [m]
};

/// Lines `u v x y z` (whitespace or commas, `#` comments). Throws core::InputError naming the
/// line; fewer than 4 correspondences is refused (PnP needs 4).
std::vector<Correspondence> ParseCorrespondences(const std::string& text,
                                                 const std::string& source);
/// Two files: lines `u v` and lines `x y z`, the k-th line of one matching the k-th of the other.
std::vector<Correspondence> ParseCorrespondencePair(const std::string& image_text,
                                                    const std::string& image_source,
                                                    const std::string& lidar_text,
                                                    const std::string& lidar_source);
/// `FILE` or `IMAGE_FILE,LIDAR_FILE`.
std::vector<Correspondence> ReadCorrespondences(const std::string& spec);

/// The error of the protocol above: T_ref · T_est⁻¹ as a rotation angle [rad] and the length of
/// its translation [m] (both T_optical_lidar).
struct ProtocolError {
  double rotation = 0, translation = 0;
};
ProtocolError CompareExtrinsics(const Eigen::Isometry3d& T_ref_optical_lidar,
                                const Eigen::Isometry3d& T_est_optical_lidar);

/// ΔT of the protocol above; angles [rad], translation [m].
Eigen::Isometry3d ProtocolDelta(const Eigen::Vector3d& roll_pitch_yaw, const Eigen::Vector3d& xyz);

}  // namespace autoshovel::identification
