#include "identification/camera_lidar/yard_simulation.h"

#include <cmath>
#include <numbers>

#include "runtime/plant/scenario.h"
#include "runtime/sensors/camera.h"
#include "runtime/sensors/lidar.h"
#include "runtime/sensors/raycast.h"
#include "runtime/sensors/sensor_pose.h"

namespace autoshovel::identification {

namespace {

// Per pixel: 0 sky, 1 floor, 2 pile, 3 + i box i of the scene (a wall, a fence, a part of a
// parked loader), cast through the same pixel centres as the camera's labels.
cv::Mat InstanceImage(const model::Camera& camera, const sensors::RaycastScene& scene,
                      const Eigen::Isometry3d& T_world_body) {
  const Eigen::Isometry3d T_world_optical = sensors::OpticalInWorld(T_world_body);
  cv::Mat instances(camera.height_px, camera.width_px, CV_32S);
  for (int v = 0; v < camera.height_px; ++v) {
    for (int u = 0; u < camera.width_px; ++u) {
      const Eigen::Vector3d d = T_world_optical.linear() * sensors::PixelRay(camera, u, v);
      const sensors::RayHit hit = scene.Cast(T_world_optical.translation(), d, 400.0);
      int id = 0;
      if (hit.hit && hit.box >= 0) {
        id = 3 + hit.box;
      } else if (hit.hit) {
        id = hit.semantic_class == core::SemanticClass::kPile ? 2 : 1;
      }
      instances.at<int>(v, u) = id;
    }
  }
  return instances;
}

}  // namespace

std::vector<YardFrame> SimulateYardFrames(const model::MachineDescription& machine,
                                          const model::Lidar& lidar,
                                          const Eigen::Isometry3d& T_lidar_camera,
                                          const std::string& models_dir,
                                          const YardSimulationOptions& options) {
  const plant::Scenario scenario =
      plant::LoadScenario(plant::ResolveScenario(options.scenario, models_dir));
  sensors::RaycastScene scene(scenario.world);
  sensors::Rng rng(options.seed);
  std::vector<Eigen::Vector3d> poses = options.machine_poses;
  if (poses.empty()) {
    constexpr double kDeg = std::numbers::pi / 180.0;
    poses = {{35.45, 43.0, 90 * kDeg},   // bin_3: the parked loader at 6.6 m
             {53.0, 44.0, 90 * kDeg},    // bin_5: fence and debris
             {15.0, 24.0, 180 * kDeg},   // bin_7: the parked loader beside the heap
             {16.0, 34.0, 180 * kDeg},   // bin_8: fence and debris
             {22.0, 45.0, 100 * kDeg}};  // the end of a north wall at 4 m
  }
  std::vector<YardFrame> frames;
  for (const Eigen::Vector3d& pose : poses) {
    plant::MachineState state;
    state.hinge_xy = pose.head<2>();
    state.heading = pose.z();
    state.q.assign(machine.num_joints(), 0.0);
    const Eigen::Isometry3d T_world_lidar = sensors::SensorInWorld(state, lidar.pose);
    YardFrame frame;
    frame.cloud.sensor = lidar.name;
    for (int k = 0; k < options.lidar_frames; ++k) {
      const sensors::PointCloud part =
          sensors::SimulateLidarFrame(lidar, scene, T_world_lidar, k / lidar.rate, rng);
      frame.cloud.points.insert(frame.cloud.points.end(), part.points.begin(), part.points.end());
    }
    sensors::CameraOptions camera_options;
    camera_options.lighting = scenario.lighting;
    const sensors::CameraFrame image = sensors::SimulateCameraFrame(
        machine.sensors.camera, scene, T_world_lidar * T_lidar_camera, 0.0, camera_options, rng);
    frame.image =
        cv::Mat(image.height, image.width, CV_8UC3, const_cast<std::uint8_t*>(image.bgr.data()))
            .clone();
    frame.labels =
        cv::Mat(image.height, image.width, CV_8U, const_cast<std::uint8_t*>(image.labels.data()))
            .clone();
    frame.instances = InstanceImage(machine.sensors.camera, scene, T_world_lidar * T_lidar_camera);
    frame.masks = MasksFromLabels(options.instance_masks ? frame.instances : frame.labels);
    frames.push_back(std::move(frame));
  }
  return frames;
}

}  // namespace autoshovel::identification
