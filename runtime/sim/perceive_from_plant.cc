#include "runtime/sim/perceive_from_plant.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "runtime/perception/machine_footprint.h"
#include "runtime/perception/segmentation.h"
#include "runtime/sensors/camera.h"
#include "runtime/sensors/lidar.h"
#include "runtime/sensors/sensor_pose.h"

namespace autoshovel::sim {

using namespace perception;  // the pipeline is perception's, run on the simulator's frames

namespace {

// Loading a network also checks it with one forward pass (≈ 50 ms); the closed loop perceives
// at 7 Hz, so each thread keeps the last network it loaded.
const Segmenter& CachedSegmenter(const std::string& onnx_path) {
  thread_local std::unique_ptr<Segmenter> cached;
  if (cached == nullptr || cached->model_path() != onnx_path) {
    cached = std::make_unique<Segmenter>(onnx_path);
  }
  return *cached;
}

}  // namespace

PerceptionFromPlantStats PerceiveFromPlant(const plant::Plant& plant,
                                           const sensors::RaycastScene& scene, sensors::Rng& rng,
                                           const PerceptionFromPlantOptions& options,
                                           perception::ElevationMap& map,
                                           perception::SemanticMap& semantic) {
  const model::MachineDescription& machine = plant.machine();
  const plant::MachineState& s = plant.state();
  PerceptionFromPlantStats stats;
  const MachineFootprint footprint =
      LoaderFootprint(machine, s.hinge_xy, s.heading, s.articulation,
                      (plant.TipInWorld().head<2>() - s.hinge_xy).norm());
  for (const model::Lidar& lidar : machine.sensors.lidars) {
    const Eigen::Isometry3d T_world_lidar = sensors::SensorInWorld(s, lidar.pose);
    const bool dead = !options.dead_lidar.empty() && lidar.name == options.dead_lidar;
    for (int k = 0; k < options.lidar_frames; ++k) {
      const double t = s.time + 0.1 * k;
      sensors::PointCloud cloud = sensors::SimulateLidarFrame(lidar, scene, T_world_lidar, t, rng);
      if (dead) {
        std::erase_if(cloud.points, [&](const sensors::LidarPoint& p) {
          const double azimuth = std::atan2(p.p_sensor.y(), p.p_sensor.x());
          return azimuth >= options.dead_sector.x() && azimuth <= options.dead_sector.y();
        });
      }
      if (options.check_lidar_health && k + 1 == options.lidar_frames) {
        std::vector<Eigen::Vector3d> rays;
        for (const sensors::LidarRay& ray : sensors::LidarScanPattern(lidar, t)) {
          rays.push_back(ray.direction);
        }
        const Eigen::Isometry3d T_cab_lidar = sensors::PoseToIsometry(lidar.pose);
        // Floor the map has seen: where the ray meets the ground plane fitted so far (z = 0
        // before the first fit), on a cell with a height.
        const Eigen::Vector3d origin = T_world_lidar.translation();
        const Eigen::Vector3d plane = semantic.ground_plane();
        const double floor_z = plane.x() * origin.x() + plane.y() * origin.y() + plane.z();
        auto ground_known = [&](const Eigen::Vector3d& d) {
          const double along = (floor_z - origin.z()) / d.z();
          return along > 0 && !std::isnan(map.HeightAt((origin + along * d).head<2>()));
        };
        for (const AzimuthSector& sector : BlindSectors(rays, cloud, T_cab_lidar.linear(),
                                                        T_world_lidar.linear(), {}, ground_known)) {
          stats.blind_sectors.emplace_back(lidar.name, sector);
        }
      }
      const MapUpdateStats update = map.Update(cloud, T_world_lidar, t, &footprint);
      stats.returns_fused += update.fused;
      stats.returns_on_machine += update.on_machine;
    }
  }
  if (!options.camera_frame) {
    stats.holes_filled = map.FillHoles();
    stats.ground_plane_found = semantic.Fuse();
    return stats;
  }
  const Eigen::Isometry3d T_world_camera = sensors::SensorInWorld(s, machine.sensors.camera.pose);
  sensors::CameraOptions camera_options;
  camera_options.lighting = options.lighting;
  camera_options.lens_dirt_center_px = options.lens_dirt_center_px;
  camera_options.lens_dirt_radius_px = options.lens_dirt_radius_px;
  const sensors::CameraFrame image = sensors::SimulateCameraFrame(
      machine.sensors.camera, scene, T_world_camera, s.time, camera_options, rng);

  ClassProbabilities probabilities;
  if (options.truth_labels) {
    probabilities = FromLabels(image.labels, image.width, image.height);
    stats.semantics = "simulator labels";
  } else {
    SegmentationResult result = CachedSegmenter(options.segmenter).Run(image);
    probabilities.width = result.width;
    probabilities.height = result.height;
    probabilities.planes = std::move(result.probabilities);
    stats.semantics = "network " + options.segmenter;
  }
  if (options.lens_dirt != nullptr) {
    // The machine's own pixels by the segmentation: they stand still in the image, not dirt.
    std::vector<std::uint8_t> own(static_cast<std::size_t>(image.width) * image.height, 0);
    const std::size_t plane = static_cast<std::size_t>(probabilities.width) * probabilities.height;
    const std::size_t own_plane = static_cast<std::size_t>(core::SemanticClass::kOwnLoader);
    if (plane > 0 && probabilities.planes.size() >= (own_plane + 1) * plane) {
      for (int v = 0; v < image.height; ++v) {
        for (int u = 0; u < image.width; ++u) {
          const int pu = std::min(probabilities.width - 1, u * probabilities.width / image.width);
          const int pv =
              std::min(probabilities.height - 1, v * probabilities.height / image.height);
          own[static_cast<std::size_t>(v) * image.width + u] =
              probabilities.planes[own_plane * plane +
                                   static_cast<std::size_t>(pv) * probabilities.width + pu] > 0.5f;
        }
      }
    }
    options.lens_dirt->Observe(image, T_world_camera, own);
    stats.camera_masked_fraction = options.lens_dirt->masked_fraction();
    stats.camera_dirty_fraction = options.lens_dirt->dirty_fraction();
  }
  if (options.lens_dirt != nullptr && stats.camera_masked_fraction > 0) {
    // Masked pixels give no evidence (SemanticMap::Project skips NaN probabilities).
    const std::size_t plane = static_cast<std::size_t>(probabilities.width) * probabilities.height;
    const double su = static_cast<double>(image.width) / probabilities.width;
    const double sv = static_cast<double>(image.height) / probabilities.height;
    for (int v = 0; v < probabilities.height; ++v) {
      for (int u = 0; u < probabilities.width; ++u) {
        if (!options.lens_dirt->Masked(static_cast<int>(u * su), static_cast<int>(v * sv))) {
          continue;
        }
        for (int c = 0; c < core::kNumSemanticClasses; ++c) {
          probabilities.planes[c * plane + static_cast<std::size_t>(v) * probabilities.width + u] =
              std::numeric_limits<float>::quiet_NaN();
        }
      }
    }
  }
  semantic.Project(probabilities, machine.sensors.camera, T_world_camera);
  stats.holes_filled = map.FillHoles();
  stats.ground_plane_found = semantic.Fuse();
  return stats;
}

}  // namespace autoshovel::sim
