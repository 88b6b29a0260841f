// The semantic elevation map a loader builds from where it stands in the simulated yard: its
// LiDAR frames fused into the elevation map (machine points removed), one camera frame segmented
// (or the simulator's labels) and projected, holes filled, Eq. (10)–(11) fused. One pipeline for
// `autoshovel map`, `autoshovel select` and the closed loop, so they cannot drift apart.
//
// The simulation side (runtime/sim, docs/architecture.md): it links the plant and the simulated
// sensors, which perception itself never depends on.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "runtime/perception/elevation_map.h"
#include "runtime/perception/lens_dirt_monitor.h"
#include "runtime/perception/lidar_health.h"
#include "runtime/perception/semantic_map.h"
#include "runtime/perception/sensor_fusion.h"
#include "runtime/plant/plant.h"
#include "runtime/plant/world.h"
#include "runtime/sensors/raycast.h"
#include "runtime/sensors/rng.h"

namespace autoshovel::sim {

struct PerceptionFromPlantOptions {
  int lidar_frames = 5;      ///< per LiDAR, 0.1 s apart; 0: none arrives (a dropout)
  bool camera_frame = true;  ///< false: no usable camera frame arrives (a blackout)
  plant::Lighting lighting = plant::Lighting::kNormal;
  bool truth_labels = false;        ///< the simulator's per-pixel labels instead of the network
  std::string segmenter;            ///< ONNX network (needed unless truth_labels)
  double segmentation_scale = 1.0;  ///< perception::FusionOptions::segmentation_scale

  // Faults (plant/fault_spec.h) and the health checks that find them.
  std::string dead_lidar;  ///< this LiDAR returns nothing within `dead_sector` ("": none)
  Eigen::Vector2d dead_sector = Eigen::Vector2d::Zero();          ///< sensor-frame azimuths [rad]
  Eigen::Vector2d lens_dirt_center_px = Eigen::Vector2d::Zero();  ///< see CameraOptions
  double lens_dirt_radius_px = 0;                                 ///< 0: a clean lens
  bool check_lidar_health = false;  ///< look for blind sectors in every LiDAR's last frame
  /// When given, judges each camera frame for dirt; pixels it masks give the map no evidence.
  perception::LensDirtMonitor* lens_dirt = nullptr;
};

using PerceptionFromPlantStats = perception::FusionStats;

/// What the machine of `plant` senses in `scene` now, as the frames a driver would deliver
/// (`lidar_frames` per LiDAR 0.1 s apart, then the camera's unless `camera_frame` is false),
/// with the faults of `options` applied.
perception::SensorFrames SimulateSensorFrames(const plant::Plant& plant,
                                              const sensors::RaycastScene& scene, sensors::Rng& rng,
                                              const PerceptionFromPlantOptions& options);

/// SimulateSensorFrames, then perception::FuseSensorFrames into `map` and `semantic` (built on
/// `map`). Throws what the segmenter throws for a bad network file.
PerceptionFromPlantStats PerceiveFromPlant(const plant::Plant& plant,
                                           const sensors::RaycastScene& scene, sensors::Rng& rng,
                                           const PerceptionFromPlantOptions& options,
                                           perception::ElevationMap& map,
                                           perception::SemanticMap& semantic);

}  // namespace autoshovel::sim
