// The main job's safety supervisor (issue 9): what the machine does when its data or its
// actuators cannot be trusted. Decided as a field safety engineer would, after ISO 17757's rule
// that an autonomous earth-moving machine stops rather than move on data it cannot trust:
//
// - Sensor watchdog: no motion is commanded on a map older than `max_sensor_age`. While driving
//   to a shovel point, a LiDAR or camera that has delivered nothing for that long holds the
//   machine stopped (brake on, valves at rest); when both deliver again it drives on (a
//   recovery). During the scoop the cycle runs on the map taken before contact (the trigger and
//   the look-ahead need no new frames), so a dropout there changes nothing.
// - Localisation: between two control ticks the pose may move only as far as the machine can
//   (speed × dt plus `jump_distance`, and `jump_heading`). A larger step is a jump: the pose
//   estimate, the map's frame and the planned path no longer agree, and nothing on board tells
//   which is right. The machine stops and the cycle is abandoned (safe stop, not completed).
// - Actuators: a joint whose valve is commanded open by at least `stuck_command` for
//   `stuck_time` while it neither moves nor rests at a limit either stalls under load or does
//   not answer its valve, told apart by the pressure of the chamber the valve feeds:
//   - at (within `stall_pressure_margin` of) the most the supply can hold there, for at least
//     `stall_confirm_time` (StallLimit: the relief valve's setting, or a load-sensing pump's
//     maximum less its margin when that is lower), with the pump's own pressure there too, the
//     hydraulics push as hard as they can and the load is more than they lift: a stall under
//     load, not a fault. The pump's pressure is what tells it from a trapped chamber that an
//     outside load presses up (the pile on a bucket whose spool is jammed shut: the plant's
//     boom cap side reaches 277 bar that way while the pump idles). It is reported once
//     ("boom stalls under load at relief (278 bar) …") and the controller ends what it was
//     doing (control::ScoopCycle::JointStalledUnderLoad: the scoop ends, keeping its load, and
//     the machine retreats). A stall that lasts `max_stall_time` all the same is a fault.
//   - below it (no pressure built up: a stuck spool, a burst hose, a dead IMU) the joint does
//     not answer its valve: the machine stops and the cycle is abandoned. So is every unanswered
//     joint whose machine reports no working or pump pressure (NaN): a stall cannot be told.
// - Frame order: a frame is used only when it is newer than the newest already used from that
//   sensor and younger than `max_sensor_age` (AcceptFrame). A late frame fused at the pose of
//   its arrival would put old returns where the machine is now, and could overwrite newer
//   evidence (a person who just stepped in) with older; it is dropped and counted, and only
//   used frames feed the watchdog.
// - Degraded sensors (docs/faults.md): a LiDAR blind in a sector that faces the direction of
//   travel (within `blind_sector_cone`), or a camera whose view is masked for dirt beyond
//   `max_masked_fraction`, holds the machine like a silent sensor while driving.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <string>

#include "runtime/control/scoop_cycle.h"
#include "runtime/core/actuator_command.h"
#include "runtime/model/description.h"

namespace autoshovel::app {

struct SupervisorConfig {
  double max_sensor_age = 0.5;  ///< [s]
  double jump_distance = 0.3;   ///< beyond the motion the speed explains, per tick [m]
  double jump_heading = 0.05;   ///< per tick [rad] (the XCMG yaws at most ~0.5 rad/s)
  double stuck_command = 0.3;   ///< valve opening that must move the joint [-]
  double stuck_time = 2.0;      ///< [s]
  double stuck_rate = 0.005;    ///< joint speed below which it counts as not moving [rad/s]
  double limit_margin = 0.05;   ///< a joint this close to a limit may rest [rad]
  /// An unanswered joint whose working chamber is at least (1 − this) times its StallLimit
  /// stalls under load [-]. 10 %: the plant's load-sensing compensator holds the fed chamber
  /// within its 15 bar margin of the pump's maximum at stall (235 of 250 bar on the XCMG), where
  /// a lift at full opening works at up to 160 bar (docs/faults.md).
  double stall_pressure_margin = 0.1;
  double stall_confirm_time = 0.5;    ///< at that pressure for at least this long [s]
  double max_stall_time = 10.0;       ///< a stall not ended by then is a fault [s]
  double blind_sector_cone = 1.0472;  ///< half-angle about the travel direction [rad] (60°)
  double max_masked_fraction = 0.25;  ///< of the camera image masked for dirt [-]
};

enum class SensorStream { kLidar, kCamera };

/// The most pressure the supply can hold in an actuator's working chamber [Pa], and what sets
/// it: the relief valve, or a load-sensing pump whose maximum less its compensator margin (the
/// valves' rated drop, plant.cc LoadSensing) is lower than the relief setting.
struct StallLimit {
  double pressure = NAN;  ///< [Pa]; NaN: unknown (no stall can be told)
  std::string what;       ///< "relief" or "the load-sensing pump's limit"
};
StallLimit StallLimitOf(const model::MachineDescription& machine, int actuator);

/// One joint as the supervisor sees it at one control tick.
struct JointReading {
  double valve = 0;  ///< commanded opening [-1, 1]; positive feeds the cap side
  double q = 0;      ///< [rad]
  double qd = 0;     ///< [rad/s]
  /// Pressure of the chamber the valve feeds (cap side for a positive opening, rod side for a
  /// negative one) [Pa]; NaN when the machine has no transducer there.
  double working_pressure = NAN;
  /// The pump's output pressure [Pa]; NaN when not sensed.
  double pump_pressure = NAN;
};

struct JointRange {
  double q_min = 0, q_max = 0;  ///< joint limits [rad]
  StallLimit stall;             ///< of the joint's actuator
};

/// Joint `joint` (0: boom, 1: bucket) of `machine` as the supervisor reads it: the valve
/// opening last commanded, the sensed angle and rate, and the pressure of the chamber that
/// opening feeds (cap side for a positive opening, rod side for a negative one).
JointReading ReadJoint(const model::MachineDescription& machine, int joint,
                       const control::Proprioception& sensed, const core::ActuatorCommand& command);
/// The joint's limits and its actuator's StallLimit.
JointRange RangeOf(const model::MachineDescription& machine, int joint);

enum class JointState {
  kAnswers,          ///< moving, resting at a limit, not commanded, or not yet decided
  kStallsUnderLoad,  ///< not moving with its working chamber at the stall limit: not a fault
  kDoesNotAnswer,    ///< a fault: the machine stops and the cycle is abandoned
};

struct JointCheck {
  JointState state = JointState::kAnswers;
  std::string message;        ///< why, for kStallsUnderLoad and kDoesNotAnswer
  bool first_report = false;  ///< kStallsUnderLoad: the first tick of this stall
};

class SafetySupervisor {
 public:
  explicit SafetySupervisor(const SupervisorConfig& config = {}) : config_(config) {}

  void LidarFrame(double t) { last_lidar_ = t; }
  void CameraFrame(double t) { last_camera_ = t; }
  /// A frame of `stream` stamped `stamp` arrives at `now`. Returns whether it may be used (see
  /// above); a used frame counts for the watchdog as LidarFrame/CameraFrame(stamp).
  bool AcceptFrame(SensorStream stream, double stamp, double now);
  /// Frames refused by AcceptFrame as late or out of order.
  long refused_frames() const { return refused_frames_; }
  /// "" when both sensors delivered within the age limit at `t`, else what is stale.
  std::string StaleSensors(double t) const;

  /// Feeds the localised pose of one control tick; returns "" or the jump it shows.
  std::string CheckPose(double t, const Eigen::Vector2d& hinge_xy, double heading, double speed);

  /// Feeds one joint's (0: boom, 1: bucket) commanded valve, motion and working pressure at
  /// `t`; says whether it answers, stalls under load or does not answer (above).
  JointCheck CheckJoint(int joint, const std::string& name, double t, const JointReading& reading,
                        const JointRange& range);

  /// The machine holds a stop for `reason` (counted once per stop) / drives on again.
  void Stop(const std::string& reason);
  void Resume();
  bool stopped() const { return stopped_; }
  const std::string& reason() const { return reason_; }
  int safe_stops() const { return safe_stops_; }
  int recoveries() const { return recoveries_; }

 private:
  SupervisorConfig config_;
  double last_lidar_ = -1e9, last_camera_ = -1e9;
  long refused_frames_ = 0;
  bool have_pose_ = false;
  double last_t_ = 0, last_heading_ = 0;
  Eigen::Vector2d last_xy_ = Eigen::Vector2d::Zero();
  double unanswered_since_[2] = {-1, -1};
  double at_stall_limit_since_[2] = {-1, -1};
  bool stall_reported_[2] = {false, false};
  bool stopped_ = false;
  std::string reason_;
  int safe_stops_ = 0, recoveries_ = 0;
};

}  // namespace autoshovel::app
