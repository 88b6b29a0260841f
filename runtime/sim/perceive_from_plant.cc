#include "runtime/sim/perceive_from_plant.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "runtime/perception/machine_footprint.h"
#include "runtime/sensors/camera.h"
#include "runtime/sensors/lidar.h"
#include "runtime/sensors/sensor_pose.h"

namespace autoshovel::sim {

perception::SensorFrames SimulateSensorFrames(const plant::Plant& plant,
                                              const sensors::RaycastScene& scene, sensors::Rng& rng,
                                              const PerceptionFromPlantOptions& options) {
  const model::MachineDescription& machine = plant.machine();
  const plant::MachineState& s = plant.state();
  perception::SensorFrames frames;
  frames.footprint =
      perception::LoaderFootprint(machine, s.hinge_xy, s.heading, s.articulation,
                                  (plant.TipInWorld().head<2>() - s.hinge_xy).norm());
  for (const model::Lidar& lidar : machine.sensors.lidars) {
    const Eigen::Isometry3d T_world_lidar = sensors::SensorInWorld(s, lidar.pose);
    const bool dead = !options.dead_lidar.empty() && lidar.name == options.dead_lidar;
    for (int k = 0; k < options.lidar_frames; ++k) {
      perception::LidarFrame frame;
      frame.lidar = lidar.name;
      frame.T_world_lidar = T_world_lidar;
      frame.stamp = s.time + 0.1 * k;
      const std::vector<sensors::LidarRay> rays = sensors::LidarScanPattern(lidar, frame.stamp);
      frame.cloud =
          sensors::SimulateLidarFrame(lidar, scene, T_world_lidar, frame.stamp, rng, rays);
      if (dead) {
        std::erase_if(frame.cloud.points, [&](const sensors::LidarPoint& p) {
          const double azimuth = std::atan2(p.p_sensor.y(), p.p_sensor.x());
          return azimuth >= options.dead_sector.x() && azimuth <= options.dead_sector.y();
        });
      }
      if (options.check_lidar_health && k + 1 == options.lidar_frames) {
        frame.health_check_rays.reserve(rays.size());
        for (const sensors::LidarRay& ray : rays) frame.health_check_rays.push_back(ray.direction);
        frame.R_cab_lidar = sensors::PoseToIsometry(lidar.pose).linear();
      }
      frames.lidar.push_back(std::move(frame));
    }
  }
  if (!options.camera_frame) return frames;
  frames.T_world_camera = sensors::SensorInWorld(s, machine.sensors.camera.pose);
  sensors::CameraOptions camera_options;
  camera_options.lighting = options.lighting;
  camera_options.lens_dirt_center_px = options.lens_dirt_center_px;
  camera_options.lens_dirt_radius_px = options.lens_dirt_radius_px;
  frames.camera = sensors::SimulateCameraFrame(machine.sensors.camera, scene, frames.T_world_camera,
                                               s.time, camera_options, rng);
  return frames;
}

PerceptionFromPlantStats PerceiveFromPlant(const plant::Plant& plant,
                                           const sensors::RaycastScene& scene, sensors::Rng& rng,
                                           const PerceptionFromPlantOptions& options,
                                           perception::ElevationMap& map,
                                           perception::SemanticMap& semantic) {
  const perception::SensorFrames frames = SimulateSensorFrames(plant, scene, rng, options);
  const perception::FusionOptions fusion{.truth_labels = options.truth_labels,
                                         .segmenter = options.segmenter,
                                         .segmentation_scale = options.segmentation_scale,
                                         .lens_dirt = options.lens_dirt};
  return perception::FuseSensorFrames(plant.machine(), frames, fusion, map, semantic);
}

}  // namespace autoshovel::sim
