#include "identification/camera_lidar/yard_simulation.h"

#include <cmath>
#include <numbers>

#include "runtime/plant/scenario.h"
#include "runtime/sensors/camera.h"
#include "runtime/sensors/lidar.h"
#include "runtime/sensors/raycast.h"
#include "runtime/sensors/sensor_pose.h"

namespace autoshovel::identification {

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
    poses = {{35.0, 40.0, 90 * kDeg}, {27.0, 41.5, 105 * kDeg}, {44.0, 40.5, 75 * kDeg}};
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
    frame.masks = MasksFromLabels(frame.labels);
    frames.push_back(std::move(frame));
  }
  return frames;
}

}  // namespace autoshovel::identification
