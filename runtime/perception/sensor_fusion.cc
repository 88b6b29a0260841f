#include "runtime/perception/sensor_fusion.h"

#include <algorithm>
#include <limits>
#include <memory>
#include <stdexcept>

#include "runtime/perception/segmentation.h"

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

const model::Lidar& LidarNamed(const model::MachineDescription& machine, const std::string& name) {
  if (const model::Lidar* lidar = machine.FindLidar(name)) return *lidar;
  throw std::invalid_argument("FuseSensorFrames: machine '" + machine.name + "' has no LiDAR '" +
                              name + "'");
}

// The LiDAR frames, in order; a frame carrying its scan pattern is first checked for blind
// sectors against the floor the map has seen so far.
void FuseLidarFrames(const model::MachineDescription& machine, const SensorFrames& frames,
                     ElevationMap& map, const SemanticMap& semantic, FusionStats& stats) {
  for (const LidarFrame& frame : frames.lidar) {
    const model::Lidar& lidar = LidarNamed(machine, frame.lidar);
    if (!frame.health_check_rays.empty()) {
      // Floor the map has seen: where the ray meets the ground plane fitted so far (z = 0
      // before the first fit), on a cell with a height.
      const Eigen::Vector3d origin = frame.T_world_lidar.translation();
      const Eigen::Vector3d plane = semantic.ground_plane();
      const double floor_z = plane.x() * origin.x() + plane.y() * origin.y() + plane.z();
      auto ground_known = [&](const Eigen::Vector3d& d) {
        const double along = (floor_z - origin.z()) / d.z();
        return along > 0 && !std::isnan(map.HeightAt((origin + along * d).head<2>()));
      };
      for (const AzimuthSector& sector :
           BlindSectors(frame.health_check_rays, frame.cloud, frame.R_cab_lidar,
                        frame.T_world_lidar.linear(), {}, ground_known)) {
        stats.blind_sectors.emplace_back(lidar.name, sector);
      }
    }
    const MapUpdateStats update =
        map.Update(frame.cloud, frame.T_world_lidar, frame.stamp, &frames.footprint);
    stats.returns_fused += update.fused;
    stats.returns_on_machine += update.on_machine;
  }
}

// The lens dirt monitor's view of the frame; pixels it masks give no evidence (SemanticMap::
// Project skips NaN probabilities).
void MaskLensDirt(const sensors::CameraFrame& image, const Eigen::Isometry3d& T_world_camera,
                  LensDirtMonitor& lens_dirt, ClassProbabilities& probabilities,
                  FusionStats& stats) {
  // The machine's own pixels by the segmentation: they stand still in the image, not dirt.
  std::vector<std::uint8_t> own(static_cast<std::size_t>(image.width) * image.height, 0);
  const std::size_t plane = static_cast<std::size_t>(probabilities.width) * probabilities.height;
  const std::size_t own_plane = static_cast<std::size_t>(core::SemanticClass::kOwnLoader);
  if (plane > 0 && probabilities.planes.size() >= (own_plane + 1) * plane) {
    for (int v = 0; v < image.height; ++v) {
      for (int u = 0; u < image.width; ++u) {
        const int pu = std::min(probabilities.width - 1, u * probabilities.width / image.width);
        const int pv = std::min(probabilities.height - 1, v * probabilities.height / image.height);
        own[static_cast<std::size_t>(v) * image.width + u] =
            probabilities.planes[own_plane * plane +
                                 static_cast<std::size_t>(pv) * probabilities.width + pu] > 0.5f;
      }
    }
  }
  lens_dirt.Observe(image, T_world_camera, own);
  stats.camera_masked_fraction = lens_dirt.masked_fraction();
  stats.camera_dirty_fraction = lens_dirt.dirty_fraction();
  if (stats.camera_masked_fraction <= 0) return;
  const double su = static_cast<double>(image.width) / probabilities.width;
  const double sv = static_cast<double>(image.height) / probabilities.height;
  for (int v = 0; v < probabilities.height; ++v) {
    for (int u = 0; u < probabilities.width; ++u) {
      if (!lens_dirt.Masked(static_cast<int>(u * su), static_cast<int>(v * sv))) continue;
      for (int c = 0; c < core::kNumSemanticClasses; ++c) {
        probabilities.planes[c * plane + static_cast<std::size_t>(v) * probabilities.width + u] =
            std::numeric_limits<float>::quiet_NaN();
      }
    }
  }
}

}  // namespace

FusionStats FuseSensorFrames(const model::MachineDescription& machine, const SensorFrames& frames,
                             const FusionOptions& options, ElevationMap& map,
                             SemanticMap& semantic) {
  FusionStats stats;
  FuseLidarFrames(machine, frames, map, semantic, stats);
  if (!frames.camera) {
    stats.holes_filled = map.FillHoles();
    stats.ground_plane_found = semantic.Fuse();
    return stats;
  }
  const sensors::CameraFrame& image = *frames.camera;
  ClassProbabilities probabilities;
  if (options.truth_labels) {
    probabilities = FromLabels(image.labels, image.width, image.height);
    stats.semantics = "simulator labels";
  } else {
    SegmentationResult result =
        CachedSegmenter(options.segmenter).Run(image, options.segmentation_scale);
    probabilities.width = result.width;
    probabilities.height = result.height;
    probabilities.planes = std::move(result.probabilities);
    stats.semantics = "network " + options.segmenter;
  }
  if (options.lens_dirt != nullptr) {
    MaskLensDirt(image, frames.T_world_camera, *options.lens_dirt, probabilities, stats);
  }
  semantic.Project(probabilities, machine.sensors.camera, frames.T_world_camera);
  stats.holes_filled = map.FillHoles();
  stats.ground_plane_found = semantic.Fuse();
  return stats;
}

}  // namespace autoshovel::perception
