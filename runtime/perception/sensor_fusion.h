// The semantic elevation map from the frames a machine's sensors deliver (seed §4, Fig. 2): the
// LiDAR frames fused into the elevation map (the machine's own returns removed), the camera
// frame segmented (or its labels taken) and projected, holes filled, Eq. (10)–(11) fused.
//
// Frames in, maps out: the simulator (runtime/sim, SimulateSensorFrames) and a recording or a
// real driver fill the same SensorFrames; nothing here knows the plant.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "runtime/model/description.h"
#include "runtime/perception/elevation_map.h"
#include "runtime/perception/lens_dirt_monitor.h"
#include "runtime/perception/lidar_health.h"
#include "runtime/perception/machine_footprint.h"
#include "runtime/perception/semantic_map.h"
#include "runtime/sensors/sensor_data.h"

namespace autoshovel::perception {

/// One LiDAR frame as it arrived.
struct LidarFrame {
  std::string lidar;  ///< the description's LiDAR name
  Eigen::Isometry3d T_world_lidar = Eigen::Isometry3d::Identity();
  double stamp = 0;  ///< [s]
  sensors::PointCloud cloud;
  /// The sensor's scan pattern (sensor-frame directions) when this frame is to be checked for
  /// blind sectors; empty: not checked. `R_cab_lidar`: the sensor's mounting, for that check.
  std::vector<Eigen::Vector3d> health_check_rays;
  Eigen::Matrix3d R_cab_lidar = Eigen::Matrix3d::Identity();
};

/// What the sensors gave for one map update, in the order they are fused.
struct SensorFrames {
  /// The machine's outline at the update: returns inside it are its own.
  MachineFootprint footprint;
  std::vector<LidarFrame> lidar;
  std::optional<sensors::CameraFrame> camera;  ///< none: no usable frame (a blackout)
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
};

struct FusionOptions {
  bool truth_labels = false;  ///< the camera frame's labels instead of the network
  std::string segmenter;      ///< ONNX network (needed unless truth_labels)
  /// The network runs at this fraction of the image's resolution (Segmenter::Run): 0.75 costs
  /// about 0.57 of the time for 2.4 points of mIoU (docs/performance.md).
  double segmentation_scale = 1.0;
  /// When given, judges each camera frame for dirt; pixels it masks give the map no evidence.
  LensDirtMonitor* lens_dirt = nullptr;
};

struct FusionStats {
  long returns_fused = 0;
  long returns_on_machine = 0;
  long holes_filled = 0;
  bool ground_plane_found = false;  ///< false: too few ground cells; classes not fused
  std::string semantics;            ///< "simulator labels" or "network <file>"
  /// Blind sectors found in the frames that carried health_check_rays, with the LiDAR's name.
  std::vector<std::pair<std::string, AzimuthSector>> blind_sectors;
  double camera_masked_fraction = 0;  ///< of the last image, masked for dirt (or suspect)
  double camera_dirty_fraction = 0;   ///< of the last image, confirmed dirty (lens_dirt_monitor.h)
};

/// Updates `map` and `semantic` (built on `map`) with `frames` of `machine`'s sensors. Throws
/// what the segmenter throws for a bad network file, and std::invalid_argument for a frame of
/// a LiDAR the description does not have.
FusionStats FuseSensorFrames(const model::MachineDescription& machine, const SensorFrames& frames,
                             const FusionOptions& options, ElevationMap& map,
                             SemanticMap& semantic);

}  // namespace autoshovel::perception
