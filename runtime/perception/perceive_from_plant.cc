#include "runtime/perception/perceive_from_plant.h"

#include <memory>

#include "runtime/perception/machine_footprint.h"
#include "runtime/perception/segmentation.h"
#include "runtime/sensors/camera.h"
#include "runtime/sensors/lidar.h"
#include "runtime/sensors/sensor_pose.h"

namespace autoshovel::perception {

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
                                           ElevationMap& map, SemanticMap& semantic) {
  const model::MachineDescription& machine = plant.machine();
  const plant::MachineState& s = plant.state();
  PerceptionFromPlantStats stats;
  const MachineFootprint footprint =
      LoaderFootprint(machine, s.hinge_xy, s.heading, s.articulation,
                      (plant.TipInWorld().head<2>() - s.hinge_xy).norm());
  for (const model::Lidar& lidar : machine.sensors.lidars) {
    const Eigen::Isometry3d T_world_lidar = sensors::SensorInWorld(s, lidar.pose);
    for (int k = 0; k < options.lidar_frames; ++k) {
      const double t = s.time + 0.1 * k;
      const MapUpdateStats update =
          map.Update(sensors::SimulateLidarFrame(lidar, scene, T_world_lidar, t, rng),
                     T_world_lidar, t, &footprint);
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
  semantic.Project(probabilities, machine.sensors.camera, T_world_camera);
  stats.holes_filled = map.FillHoles();
  stats.ground_plane_found = semantic.Fuse();
  return stats;
}

}  // namespace autoshovel::perception
