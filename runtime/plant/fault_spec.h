// Faults the simulated yard injects into a loader's sensors, actuators and inventory (issue 9:
// dust, vibration, dropped frames, tired operators). A fault is a kind, a window of time within
// a cycle and, optionally, the cycles it strikes; the simulator applies it, the main job's
// safety supervisor (runtime/app/safety_supervisor.h) must cope with it. docs/faults.md gives
// each kind's expected behaviour and the test that shows it.
//
// In a scenario or campaign file:
//
//   faults:
//     - kind: lidar_dropout        # every LiDAR frame lost
//       start_s: 2.0               # seconds after the cycle began
//       duration_s: 1.5            # omitted: to the end of the cycle
//       cycles: [0, 2]             # omitted: every cycle
//     - kind: localisation_jump    # the pose estimate jumps and stays off
//       start_s: 3.0
//       offset_m: [1.0, 0.0]       # world x, y
//       heading_deg: 10
//     - kind: stuck_valve          # the joint's spool jams at neutral
//       joint: boom
//     - kind: material_mistyped    # the station's inventory names the wrong material
//       reported: big_gravel
//     - kind: person_enters_path   # a person steps onto the planned path
//       start_s: 1.0
//       ahead_m: 7.0               # that far along the path from where the machine is then
//     - kind: lidar_dead_sector    # one LiDAR returns nothing in an azimuth sector
//       lidar: front_solid_state
//       sector_deg: [-10, 20]      # sensor frame, 0 = its x axis, positive to the left
//     - kind: camera_lens_dirt     # a dark blot on the lens
//       center: [0.5, 0.7]         # image fractions (u right, v down)
//       radius: 0.15               # fraction of the image width
//     - kind: imu_bias_drift       # an arm IMU's bias walks off
//       joint: boom
//       rate_deg_s: 0.5
//     - kind: imu_stuck            # an arm IMU repeats its last reading
//       joint: bucket
//     - kind: encoder_noise        # white noise on the articulation encoder and arm angles
//       sigma_deg: 1.0
//     - kind: hydraulic_delay_drift  # every valve's transport delay scaled
//       factor: 1.5
//     - kind: timestamps_out_of_order  # every second frame arrives late
//       sensor: lidar              # lidar | camera
//       lag_s: 0.3
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

namespace autoshovel::core {
class MapReader;
}

namespace autoshovel::plant {

enum class FaultKind {
  kLidarDropout,          ///< no LiDAR frame arrives
  kCameraBlackout,        ///< no usable camera frame arrives
  kLocalisationJump,      ///< the localisation's pose is off by a fixed offset
  kStuckValve,            ///< one joint's valve spool stays at neutral, whatever is commanded
  kMaterialMistyped,      ///< the inventory reports another material for every pile
  kPersonEntersPath,      ///< a person appears on the path ahead and stays
  kLidarDeadSector,       ///< one LiDAR returns nothing within an azimuth sector
  kCameraLensDirt,        ///< a dark blot covers part of the image
  kImuBiasDrift,          ///< an arm IMU's bias grows at a constant rate
  kImuStuck,              ///< an arm IMU keeps repeating the reading it had when the fault began
  kEncoderNoise,          ///< white noise on the articulation encoder and the arm angles
  kHydraulicDelayDrift,   ///< every valve's transport delay scaled by a factor
  kTimestampsOutOfOrder,  ///< every second frame of a sensor arrives late
};
const char* ToString(FaultKind kind);

struct FaultSpec {
  FaultKind kind = FaultKind::kLidarDropout;
  double start_s = 0;  ///< from the cycle's start [s]
  double duration_s = std::numeric_limits<double>::infinity();
  std::vector<int> cycles;  ///< empty: every cycle
  std::string where;        ///< file:line of the entry, for messages
  // Kind-specific parameters.
  Eigen::Vector2d offset_m = Eigen::Vector2d::Zero();  ///< localisation_jump [m]
  double heading_rad = 0;                              ///< localisation_jump [rad]
  std::string joint;     ///< stuck_valve, imu_bias_drift, imu_stuck: "boom" or "bucket"
  std::string reported;  ///< material_mistyped: the material the inventory names
  double ahead_m = 0;    ///< person_enters_path [m]
  std::string lidar;     ///< lidar_dead_sector: the description's LiDAR name
  Eigen::Vector2d sector_rad = Eigen::Vector2d::Zero();  ///< lidar_dead_sector: from, to [rad]
  Eigen::Vector2d center = Eigen::Vector2d::Zero();      ///< camera_lens_dirt: (u, v) fractions
  double radius = 0;      ///< camera_lens_dirt: fraction of the image width
  double rate_rad_s = 0;  ///< imu_bias_drift [rad/s]
  double sigma_rad = 0;   ///< encoder_noise: 1σ [rad]
  double factor = 1;      ///< hydraulic_delay_drift [-]
  std::string sensor;     ///< timestamps_out_of_order: "lidar" or "camera"
  double lag_s = 0;       ///< timestamps_out_of_order [s]

  /// Whether the fault strikes cycle `cycle` at `t` seconds after its start.
  bool ActiveAt(int cycle, double t) const;
  /// Whether it strikes cycle `cycle` at all.
  bool InCycle(int cycle) const;
};

/// Reads the optional `faults` list of a scenario or campaign file. Problems go to the reader's
/// sink with their location (unknown kind, negative times, a parameter of another kind).
std::vector<FaultSpec> ReadFaults(core::MapReader& root);

/// A file holding just a `faults` list (`autoshovel run --faults FILE`). Throws
/// core::InputError with every problem located.
std::vector<FaultSpec> LoadFaults(const std::string& path);

}  // namespace autoshovel::plant
