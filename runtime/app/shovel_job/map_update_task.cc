#include "runtime/app/shovel_job/map_update_task.h"

#include <chrono>
#include <numbers>
#include <utility>

#include "runtime/app/crowd_lookahead.h"
#include "runtime/perception/lidar_health.h"
#include "runtime/perception/semantic_map.h"
#include "runtime/plant/plant.h"
#include "runtime/sensors/raycast.h"

namespace autoshovel::app {

MapUpdateResult MapUpdateTask::Update(
    plant::Plant& plant, sensors::RaycastScene& scene, sensors::Rng& rng,
    std::vector<plant::OrientedBox> extra_boxes, double travel_heading, const FaultSchedule& faults,
    SafetySupervisor& supervisor, perception::LensDirtMonitor& lens_dirt,
    perception::ElevationMap& map, perception::SemanticMap& semantic, const CycleLog& log) {
  const auto w0 = std::chrono::steady_clock::now();
  scene.SetExtraBoxes(std::move(extra_boxes));
  // Frames that arrive: none in a dropout or a blackout; late ones (stamped `lag_s` before
  // now, every second frame) refused by the supervisor's order check, never fused.
  const double now = plant.time();
  const plant::FaultSpec* late = faults.Active(plant::FaultKind::kTimestampsOutOfOrder, now);
  auto stamp_of = [&](const char* sensor) {
    const bool lagging = late != nullptr && late->sensor == sensor && frames_arrived_ % 2 == 1;
    return lagging ? now - late->lag_s : now;
  };
  const bool lidar = faults.Active(plant::FaultKind::kLidarDropout, now) == nullptr &&
                     supervisor.AcceptFrame(SensorStream::kLidar, stamp_of("lidar"), now);
  const bool camera = faults.Active(plant::FaultKind::kCameraBlackout, now) == nullptr &&
                      supervisor.AcceptFrame(SensorStream::kCamera, stamp_of("camera"), now);
  ++frames_arrived_;
  sim::PerceptionFromPlantOptions perceive = config_.perceive;
  perceive.lidar_frames = !lidar ? 0 : calls_ == 0 ? 5 : 1;
  perceive.camera_frame = camera;
  const plant::FaultSpec* blind = faults.Active(plant::FaultKind::kLidarDeadSector, now);
  perceive.dead_lidar = blind != nullptr ? blind->lidar : "";
  perceive.dead_sector = blind != nullptr ? blind->sector_rad : Eigen::Vector2d::Zero();
  const plant::FaultSpec* dirt = faults.Active(plant::FaultKind::kCameraLensDirt, now);
  const model::Camera& camera_model = plant.machine().sensors.camera;
  perceive.lens_dirt_center_px = dirt != nullptr
                                     ? Eigen::Vector2d(dirt->center.x() * camera_model.width_px,
                                                       dirt->center.y() * camera_model.height_px)
                                     : Eigen::Vector2d::Zero();
  perceive.lens_dirt_radius_px = dirt != nullptr ? dirt->radius * camera_model.width_px : 0.0;
  perceive.check_lidar_health = true;
  perceive.lens_dirt = &lens_dirt;
  // The frames as the machine delivers them, then fused (sim::PerceiveFromPlant in two steps,
  // so that a recorder can keep the frames: last_frames()).
  const auto w_sim = std::chrono::steady_clock::now();
  last_frames_ = sim::SimulateSensorFrames(plant, scene, rng, perceive);
  const auto w_fuse = std::chrono::steady_clock::now();
  simulation_seconds_ += std::chrono::duration<double>(w_fuse - w_sim).count();
  const perception::FusionStats seen =
      perception::FuseSensorFrames(plant.machine(), last_frames_,
                                   {.truth_labels = perceive.truth_labels,
                                    .segmenter = perceive.segmenter,
                                    .segmentation_scale = perceive.segmentation_scale,
                                    .lens_dirt = perceive.lens_dirt},
                                   map, semantic);
  fusion_seconds_ +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - w_fuse).count();

  MapUpdateResult result;
  result.camera_dirty_fraction = seen.camera_dirty_fraction;
  result.blind_sector = !seen.blind_sectors.empty();
  for (const auto& [name, sector] : seen.blind_sectors) {
    if (!perception::SectorFaces(sector, travel_heading, config_.blind_sector_cone)) continue;
    result.degraded += (result.degraded.empty() ? "" : ", ") + std::string("LiDAR ") + name +
                       " blind from " + Fixed(sector.from * 180 / std::numbers::pi, 0) + " to " +
                       Fixed(sector.to * 180 / std::numbers::pi, 0) + " deg";
  }
  if (perceive.camera_frame && seen.camera_dirty_fraction > config_.max_masked_fraction) {
    result.degraded += (result.degraded.empty() ? "" : ", ") + std::string("camera view ") +
                       Fixed(100 * seen.camera_dirty_fraction, 0) + " % masked for lens dirt";
  }
  if (seen.camera_dirty_fraction > 0 && !dirt_reported_) {
    log.Say("lens dirt found: " + Fixed(100 * seen.camera_dirty_fraction, 1) +
            " % of the image masked at t = " + Fixed(now - faults.t0(), 2) + " s");
    dirt_reported_ = true;
  }
  // The look-ahead along the path stops for less: a person who stepped in is in the obstacle
  // evidence at 0.5 two frames later (blended at 0.3 a frame), at 0.95 only after nine (1.3 s
  // at 7 Hz, beyond a loader's stopping distance at 1.5 m/s). Only what stands at least
  // `path_obstacle_height` above the ground plane: a low cell's middling obstacle evidence is a
  // shadow or a label's blur on the floor, not a person.
  sure_cells_.clear();
  const Eigen::Vector3d plane = semantic.ground_plane();
  for (const Eigen::Vector2d& c : SureObstacleCells(map.map(), config_.path_obstacle_margin, 0,
                                                    config_.path_obstacle_confidence)) {
    perception::Index i;
    if (!map.map().IndexOf(c, i)) continue;
    const double height =
        map.map().at("elevation", i) - (plane.x() * c.x() + plane.y() * c.y() + plane.z());
    if (height >= config_.path_obstacle_height) sure_cells_.push_back(c);
  }
  ++calls_;
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  return result;
}

}  // namespace autoshovel::app
