#include "identification/camera_lidar/camera_model.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "runtime/core/diagnostics.h"
#include "runtime/core/file_output.h"
#include "runtime/core/yaml_reader.h"

namespace autoshovel::identification {

namespace {

core::SourceLocation At(const std::string& file, const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  return {file, mark.line + 1, mark.column + 1};
}

}  // namespace

CameraIntrinsics IntrinsicsFromDescription(const model::Camera& camera) {
  CameraIntrinsics c;
  c.width = camera.width_px;
  c.height = camera.height_px;
  c.K << camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1;
  return c;
}

CameraIntrinsics ReadCameraInfoYaml(const std::string& path) {
  core::DiagnosticSink sink;
  // The project's YAML loader: size limit, syntax errors and duplicate keys, located.
  const YAML::Node root = core::LoadYamlFile(path, sink);
  sink.ThrowIfAny();
  CameraIntrinsics c;
  auto integer = [&](const char* key, int& value) {
    const YAML::Node node = root[key];
    if (!node) {
      sink.Add({path, 1, 1}, key, "missing (a ROS camera_info YAML needs it)");
      return;
    }
    try {
      value = node.as<int>();
      if (value <= 0)
        sink.Add(At(path, node), key, "must be > 0 px, got " + node.as<std::string>());
    } catch (const YAML::Exception&) {
      sink.Add(At(path, node), key, "expected an integer");
    }
  };
  auto numbers = [&](const char* key, std::size_t min_count, std::size_t max_count,
                     std::vector<double>& values) {
    const YAML::Node block = root[key];
    if (!block) {
      if (min_count > 0) sink.Add({path, 1, 1}, key, "missing (a ROS camera_info YAML needs it)");
      return;
    }
    const YAML::Node data = block.IsMap() ? block["data"] : block;
    if (!data || !data.IsSequence()) {
      sink.Add(At(path, block), std::string(key) + ".data", "expected a list of numbers");
      return;
    }
    for (std::size_t i = 0; i < data.size(); ++i) {
      try {
        const double v = data[i].as<double>();
        if (!std::isfinite(v)) throw YAML::Exception(data[i].Mark(), "");
        values.push_back(v);
      } catch (const YAML::Exception&) {
        sink.Add(At(path, data[i]), std::string(key) + ".data[" + std::to_string(i) + "]",
                 "expected a finite number");
      }
    }
    if (data.size() < min_count || data.size() > max_count) {
      sink.Add(At(path, data), std::string(key) + ".data",
               "expected " + std::to_string(min_count) +
                   (min_count == max_count ? "" : " to " + std::to_string(max_count)) +
                   " values, got " + std::to_string(data.size()));
    }
  };
  integer("image_width", c.width);
  integer("image_height", c.height);
  std::vector<double> k;
  numbers("camera_matrix", 9, 9, k);
  numbers("distortion_coefficients", 0, 8, c.D);
  if (const YAML::Node model = root["distortion_model"]) {
    const std::string name = model.as<std::string>("");
    if (name != "plumb_bob" && name != "rational_polynomial") {
      sink.Add(At(path, model), "distortion_model",
               "expected plumb_bob or rational_polynomial, got '" + name + "'");
    }
  }
  sink.ThrowIfAny();
  c.K << k[0], k[1], k[2], k[3], k[4], k[5], k[6], k[7], k[8];
  if (c.K(0, 0) <= 0 || c.K(1, 1) <= 0 || c.K(2, 2) != 1.0) {
    sink.Add(At(path, root["camera_matrix"]), "camera_matrix.data",
             "expected [fx 0 cx; 0 fy cy; 0 0 1] with fx, fy > 0");
  }
  sink.ThrowIfAny();
  return c;
}

void WriteCameraInfoYaml(const std::string& path, const CameraIntrinsics& c) {
  std::ostringstream out;  // then one checked atomic write (core/file_output.h)
  out.precision(10);
  out << "# ROS camera_info: pinhole K and plumb_bob distortion D\n"
      << "image_width: " << c.width << "\nimage_height: " << c.height << "\ncamera_name: camera\n"
      << "camera_matrix:\n  rows: 3\n  cols: 3\n  data: [";
  for (int i = 0; i < 9; ++i) out << (i ? ", " : "") << c.K(i / 3, i % 3);
  out << "]\ndistortion_model: plumb_bob\ndistortion_coefficients:\n  rows: 1\n  cols: "
      << c.D.size() << "\n  data: [";
  for (std::size_t i = 0; i < c.D.size(); ++i) out << (i ? ", " : "") << c.D[i];
  out << "]\n";
  core::WriteFileAtomically(path, out.str());
}

cv::Mat Undistort(const cv::Mat& image, const CameraIntrinsics& c, bool nearest) {
  bool any = false;
  for (const double d : c.D) any = any || d != 0.0;
  if (!any) return image;
  cv::Mat K(3, 3, CV_64F), D(1, static_cast<int>(c.D.size()), CV_64F), map1, map2, out;
  for (int i = 0; i < 9; ++i) K.at<double>(i / 3, i % 3) = c.K(i / 3, i % 3);
  for (std::size_t i = 0; i < c.D.size(); ++i) D.at<double>(0, static_cast<int>(i)) = c.D[i];
  cv::initUndistortRectifyMap(K, D, cv::Mat(), K, image.size(), CV_32FC1, map1, map2);
  cv::remap(image, out, map1, map2, nearest ? cv::INTER_NEAREST : cv::INTER_LINEAR,
            cv::BORDER_CONSTANT, cv::Scalar::all(0));
  return out;
}

Eigen::Matrix3d BodyFromOpticalRotation() {
  Eigen::Matrix3d R;
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  return R;
}

Eigen::Isometry3d OpticalFromLidar(const Eigen::Isometry3d& T_lidar_camera) {
  Eigen::Isometry3d T_camera_optical = Eigen::Isometry3d::Identity();
  T_camera_optical.linear() = BodyFromOpticalRotation();
  return (T_lidar_camera * T_camera_optical).inverse();
}

Eigen::Isometry3d CameraInLidarFromOptical(const Eigen::Isometry3d& T_optical_lidar) {
  Eigen::Isometry3d T_optical_camera = Eigen::Isometry3d::Identity();
  T_optical_camera.linear() = BodyFromOpticalRotation().transpose();
  return T_optical_lidar.inverse() * T_optical_camera;
}

bool ProjectPoint(const Eigen::Matrix3d& K, int width, int height,
                  const Eigen::Isometry3d& T_optical_lidar, const Eigen::Vector3d& p_lidar,
                  Eigen::Vector2d& uv, double& depth) {
  const Eigen::Vector3d p = T_optical_lidar * p_lidar;
  depth = p.z();
  if (depth < 0.1) return false;
  uv = Eigen::Vector2d(K(0, 0) * p.x() / depth + K(0, 2), K(1, 1) * p.y() / depth + K(1, 2));
  return uv.x() >= -0.5 && uv.y() >= -0.5 && uv.x() < width - 0.5 && uv.y() < height - 0.5;
}

Eigen::Isometry3d Perturb(const Eigen::Isometry3d& T, const Eigen::Vector3d& rotation,
                          const Eigen::Vector3d& translation) {
  Eigen::Isometry3d out = T;
  const double angle = rotation.norm();
  if (angle > 0) out.linear() = Eigen::AngleAxisd(angle, rotation / angle) * T.linear();
  out.translation() += translation;
  return out;
}

PoseError ComparePoses(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  PoseError e;
  e.rotation = Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
  e.translation = (a.translation() - b.translation()).norm();
  return e;
}

Eigen::Vector3d RollPitchYaw(const Eigen::Matrix3d& R) {
  // R = Rz(ψ) Ry(θ) Rx(φ): R(2,0) = −sin θ.
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double roll = std::atan2(R(2, 1), R(2, 2));
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  return {roll, pitch, yaw};
}

}  // namespace autoshovel::identification
