#include "identification/camera_lidar/board_simulation.h"

#include <cmath>
#include <numbers>

#include "identification/camera_lidar/camera_model.h"
#include "runtime/sensors/lidar.h"
#include "runtime/sensors/sensor_pose.h"

namespace autoshovel::identification {

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kBoardReflectivity = 0.8, kFloorReflectivity = 0.2;
}  // namespace

std::vector<Eigen::Isometry3d> DefaultBoardPoses(const model::Camera& camera) {
  const Eigen::Isometry3d T_base_camera = sensors::PoseToIsometry(camera.pose);
  const Eigen::Vector3d eye = T_base_camera.translation();
  const Eigen::Vector3d forward = T_base_camera.linear().col(0);
  const Eigen::Vector3d left = T_base_camera.linear().col(1);
  // distance [m], lateral [m], yaw, tilt, roll [deg]
  const double plan[5][5] = {{4.0, 0.0, 0, 0, 0},
                             {4.5, -0.9, 20, 5, 8},
                             {5.0, 0.9, -20, -5, -6},
                             {5.5, 0.3, 10, 15, 3},
                             {3.5, -0.4, -10, -10, -10}};
  std::vector<Eigen::Isometry3d> poses;
  for (const auto& p : plan) {
    const Eigen::Vector3d centre = eye + p[0] * forward + p[1] * left;
    Eigen::Vector3d z = (eye - centre).normalized();
    z = Eigen::AngleAxisd(p[2] * kDeg, Eigen::Vector3d::UnitZ()) * z;
    const Eigen::Vector3d side = Eigen::Vector3d::UnitZ().cross(z).normalized();
    z = Eigen::AngleAxisd(p[3] * kDeg, side) * z;
    Eigen::Vector3d y =
        (Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitZ().dot(z) * z).normalized();
    y = Eigen::AngleAxisd(p[4] * kDeg, z) * y;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear().col(0) = y.cross(z);
    T.linear().col(1) = y;
    T.linear().col(2) = z;
    T.translation() = centre;
    poses.push_back(T);
  }
  return poses;
}

SimulatedBoardFrame SimulateBoardFrame(const model::Camera& camera, const model::Lidar& lidar,
                                       const Eigen::Isometry3d& T_lidar_camera,
                                       const Eigen::Isometry3d& T_base_board,
                                       const BoardGeometry& board, double integration_time,
                                       sensors::Rng& rng) {
  SimulatedBoardFrame frame;
  frame.T_base_board = T_base_board;
  const Eigen::Isometry3d T_base_lidar = sensors::PoseToIsometry(lidar.pose);
  std::normal_distribution<double> gauss(0.0, 1.0);

  // LiDAR: the board, else the floor (z = 0 in the vehicle frame).
  const Eigen::Isometry3d T_board_lidar = T_base_board.inverse() * T_base_lidar;
  const int frames = std::max(1, static_cast<int>(std::lround(integration_time * lidar.rate)));
  frame.cloud.sensor = lidar.name;
  for (int f = 0; f < frames; ++f) {
    for (const sensors::LidarRay& ray : sensors::LidarScanPattern(lidar, f / lidar.rate)) {
      const Eigen::Vector3d o_board = T_board_lidar.translation();
      const Eigen::Vector3d d_board = T_board_lidar.linear() * ray.direction;
      double range = -1, reflectivity = 0, cos_incidence = 1;
      if (d_board.z() < -1e-9) {
        const double t = -o_board.z() / d_board.z();
        const Eigen::Vector3d q = o_board + t * d_board;
        if (t > 0 && board.IsMaterial(q.x(), q.y())) {
          range = t;
          reflectivity = kBoardReflectivity;
          cos_incidence = -d_board.z();
        }
      }
      if (range < 0) {
        const Eigen::Vector3d d_base = T_base_lidar.linear() * ray.direction;
        if (d_base.z() < -1e-6) {
          const double t = -T_base_lidar.translation().z() / d_base.z();
          if (t < 60) {
            range = t;
            reflectivity = kFloorReflectivity;
            cos_incidence = -d_base.z();
          }
        }
      }
      if (range < 0) continue;
      const double measured = range + sensors::LidarRangeSigma(lidar, range) * gauss(rng);
      sensors::LidarPoint p;
      p.p_sensor = (measured * ray.direction).cast<float>();
      p.intensity = static_cast<float>(reflectivity * cos_incidence);
      p.ring = ray.ring;
      p.time_offset = static_cast<float>(f / lidar.rate + ray.time_offset);
      frame.cloud.points.push_back(p);
    }
  }

  // Camera: 4 × 4 samples per pixel against the board plane.
  const Eigen::Isometry3d T_board_optical =
      T_board_lidar * OpticalFromLidar(T_lidar_camera).inverse();
  frame.image.create(camera.height_px, camera.width_px, CV_8UC3);
  const Eigen::Vector3d o = T_board_optical.translation();
  for (int v = 0; v < camera.height_px; ++v) {
    for (int u = 0; u < camera.width_px; ++u) {
      double sum = 0;
      for (int a = 0; a < 4; ++a) {
        for (int b = 0; b < 4; ++b) {
          const double uu = u - 0.375 + 0.25 * a, vv = v - 0.375 + 0.25 * b;
          const Eigen::Vector3d d =
              T_board_optical.linear() *
              Eigen::Vector3d((uu - camera.cx) / camera.fx, (vv - camera.cy) / camera.fy, 1.0);
          double value = 55;  // the hall's wall behind the board
          if (d.z() < 0) {
            const double t = -o.z() / d.z();
            const Eigen::Vector3d q = o + t * d;
            if (board.IsMaterial(q.x(), q.y())) value = 205;
          }
          sum += value;
        }
      }
      const double g = std::clamp(sum / 16.0 + 2.0 * gauss(rng), 0.0, 255.0);
      const auto byte = static_cast<std::uint8_t>(std::lround(g));
      frame.image.at<cv::Vec3b>(v, u) = cv::Vec3b(byte, byte, byte);
    }
  }
  return frame;
}

}  // namespace autoshovel::identification
