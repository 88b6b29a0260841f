// The main job's 7 Hz map update (seed Fig. 2, "semantic elevation map"): the frames that
// arrive from the simulated sensors are fused into the elevation and semantic maps; what the
// supervisor must know of degraded sensors and the sure obstacle cells the path look-ahead
// stops for come out.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "runtime/app/safety_supervisor.h"
#include "runtime/app/shovel_job/cycle_log.h"
#include "runtime/app/shovel_job/fault_schedule.h"
#include "runtime/perception/sensor_fusion.h"
#include "runtime/plant/world.h"
#include "runtime/sensors/rng.h"
#include "runtime/sim/perceive_from_plant.h"

namespace autoshovel::sensors {
class RaycastScene;
}

namespace autoshovel::plant {
class Plant;
}

namespace autoshovel::app {

struct MapUpdateConfig {
  sim::PerceptionFromPlantOptions perceive;  ///< lighting, labels, segmenter
  double blind_sector_cone = 0;              ///< SupervisorConfig::blind_sector_cone [rad]
  double max_masked_fraction = 1;            ///< SupervisorConfig::max_masked_fraction [-]
  double path_obstacle_margin = 0;
  double path_obstacle_confidence = 0.95;
  double path_obstacle_height = 0;  ///< [m] above the ground plane
};

/// What the sensors and the maps gave this update, for the supervisor and the look-ahead.
struct MapUpdateResult {
  /// Degraded sensors: a blind sector facing the way the machine goes, a view masked for dirt
  /// ("" when none).
  std::string degraded;
  double camera_dirty_fraction = 0;  ///< of the image, confirmed dirty [-]
  bool blind_sector = false;         ///< some LiDAR is blind in some sector
};

class MapUpdateTask {
 public:
  explicit MapUpdateTask(const MapUpdateConfig& config) : config_(config) {}

  /// One update at the plant's time. `extra_boxes`: boxes the sensors see besides the world's
  /// (the machine's own bodies, people a fault put in the yard). `travel_heading`: 0 driving
  /// forward, π reversing (which blind sectors count).
  MapUpdateResult Update(plant::Plant& plant, sensors::RaycastScene& scene, sensors::Rng& rng,
                         std::vector<plant::OrientedBox> extra_boxes, double travel_heading,
                         const FaultSchedule& faults, SafetySupervisor& supervisor,
                         perception::LensDirtMonitor& lens_dirt, perception::ElevationMap& map,
                         perception::SemanticMap& semantic, const CycleLog& log);

  /// Sure obstacle cells at least `path_obstacle_height` above the ground plane on the last map.
  const std::vector<Eigen::Vector2d>& sure_cells() const { return sure_cells_; }
  /// The frames the last update fused, in order (what a recording keeps).
  const perception::SensorFrames& last_frames() const { return last_frames_; }
  long calls() const { return calls_; }
  double seconds() const { return seconds_; }  ///< wall time spent [s]
  /// Of seconds(): simulating the sensors (sim::SimulateSensorFrames) and fusing their frames
  /// (perception::FuseSensorFrames: elevation map, segmentation, semantic map) [s].
  double simulation_seconds() const { return simulation_seconds_; }
  double fusion_seconds() const { return fusion_seconds_; }

 private:
  MapUpdateConfig config_;
  std::vector<Eigen::Vector2d> sure_cells_;
  perception::SensorFrames last_frames_;
  long frames_arrived_ = 0;  ///< every second one lags under a timestamp fault
  long calls_ = 0;
  double seconds_ = 0;
  double simulation_seconds_ = 0;
  double fusion_seconds_ = 0;
  bool dirt_reported_ = false;
};

}  // namespace autoshovel::app
