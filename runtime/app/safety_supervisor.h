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
//   `stuck_time` while it neither moves nor rests at a limit does not answer its valve (a stuck
//   spool, a dead IMU): the machine stops and the cycle is abandoned.
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
#include <string>

namespace autoshovel::app {

struct SupervisorConfig {
  double max_sensor_age = 0.5;        ///< [s]
  double jump_distance = 0.3;         ///< beyond the motion the speed explains, per tick [m]
  double jump_heading = 0.05;         ///< per tick [rad] (the XCMG yaws at most ~0.5 rad/s)
  double stuck_command = 0.3;         ///< valve opening that must move the joint [-]
  double stuck_time = 2.0;            ///< [s]
  double stuck_rate = 0.005;          ///< joint speed below which it counts as not moving [rad/s]
  double limit_margin = 0.05;         ///< a joint this close to a limit may rest [rad]
  double blind_sector_cone = 1.0472;  ///< half-angle about the travel direction [rad] (60°)
  double max_masked_fraction = 0.25;  ///< of the camera image masked for dirt [-]
};

enum class SensorStream { kLidar, kCamera };

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

  /// Feeds one joint's commanded valve and motion at `t`; "" or why it does not answer.
  std::string CheckJoint(int joint, const std::string& name, double t, double valve, double q,
                         double qd, double q_min, double q_max);

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
  bool stopped_ = false;
  std::string reason_;
  int safe_stops_ = 0, recoveries_ = 0;
};

}  // namespace autoshovel::app
