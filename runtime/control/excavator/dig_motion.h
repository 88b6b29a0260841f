// One dig of the excavator (excavator seed §4.2: "the selected dig is executed by a force based
// closed loop control scheme"): the refined planner's compact action (where the tooth tip enters
// the surface, how deep, how far it drags) turned into a bucket-tip path in the arm plane and
// followed with inverse kinematics, the joint servos doing the rest.
//
// The path, in the arm plane (r from the swing axis, z up), the swing held at the action's ψ:
//   approach   the tip `approach_height` above the entry point, at the entry attitude (where
//              the loading script leaves the bucket, script_parameters.h);
//   penetrate  straight down to `depth` below the entry point;
//   drag       towards the machine by `drag_length` at that depth, rising by `drag_rise` over
//              it, the bucket curling from the entry attitude to the drag-end attitude;
//   curl       the bucket closes (attitude to `curl_attitude`, the opening facing up) while the
//              tip rises by `curl_rise`: the material is captured;
//   lift       the tip rises to `lift_height` above the entry point, the bucket curled.
// A reference point moves along the path at the segment's speed, never more than `max_lead`
// ahead of where the tip is; its inverse kinematics is the joint command. When the attitude asked
// for is outside the bucket's joint range at that point, the nearest reachable attitude is used.
//
// The force-based part (Rocke 1994, as the seed cites it): when the cut is too heavy for the
// crowd, the tip stops making progress while the valves are open; the remaining drag is then
// raised by `stall_raise` (a shallower cut), as an operator lifts the boom to free a stalled
// bucket. A stall is less than `stall_speed` of progress over `stall_window` during the drag.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "runtime/control/excavator/excavator_joints.h"
#include "runtime/control/excavator/excavator_kinematics.h"

namespace autoshovel::control {

/// Where and how to dig: the refined planner's compact task parameters (§4.2).
struct DigStroke {
  double swing = 0;         ///< ψ of the arm plane [rad]
  double radius = 0;        ///< where the tooth tip enters the surface, from the swing axis [m]
  double entry_height = 0;  ///< surface height there, base frame z [m]
  double depth = 0;         ///< below the surface [m]
  double drag_length = 0;   ///< towards the machine [m]
};

struct DigMotionSettings {
  double approach_height = 0.5;     ///< as ScriptSettings::dig_approach_height [m]
  double entry_attitude = -1.4;     ///< φ_bucket at entry, tip steeply down [rad]
  double drag_end_attitude = -2.8;  ///< φ_bucket at the end of the drag [rad]
  double curl_attitude = -3.6;      ///< φ_bucket curled, the opening up [rad]
  double drag_rise = 0.25;          ///< the tip's rise over the drag [m]
  double curl_rise = 0.3;           ///< [m]
  double lift_height = 1.2;         ///< tip above the entry point at the end [m]
  double penetrate_speed = 0.5;     ///< [m/s]
  double drag_speed = 0.7;          ///< [m/s]
  double curl_speed = 0.4;          ///< tip path speed while curling [m/s]
  double lift_speed = 0.8;          ///< [m/s]
  double max_lead = 0.35;           ///< reference ahead of the tip at most [m]
  double stall_speed = 0.08;        ///< progress below this over the window is a stall [m/s]
  double stall_window = 0.6;        ///< [s]
  double stall_raise = 0.12;        ///< raise of the remaining drag per stall [m]
  int max_stalls = 6;               ///< more stalls: the drag is cut short (curl now)
  double finish_tolerance = 0.06;   ///< tip within this of the path's end [m]
  double max_duration = 30;         ///< a dig taking longer is abandoned [s]
};

/// Throws std::invalid_argument naming the field.
void Validate(const DigMotionSettings& settings);

enum class DigPhase { kApproach, kPenetrate, kDrag, kCurl, kLift, kDone, kFailed };
const char* ToString(DigPhase phase);

class DigMotion {
 public:
  /// Builds the path. Throws std::invalid_argument when the stroke is not finite, the depth or
  /// drag length is negative, or a setting is invalid.
  DigMotion(const ExcavatorKinematics& kinematics, const DigStroke& stroke,
            const DigMotionSettings& settings = {});

  /// The joint command for the measured state at `time` [s] (any clock, increasing). Once done
  /// or failed it holds the last command.
  ExcavatorCommand Step(const ExcavatorState& measured, double time);

  DigPhase phase() const { return phase_; }
  bool done() const { return phase_ == DigPhase::kDone; }
  bool failed() const { return phase_ == DigPhase::kFailed; }
  const std::string& failure() const { return failure_; }
  int stalls() const { return stalls_; }
  /// Joint positions at the approach point (where the pass should leave the bucket); nullopt
  /// when out of reach.
  std::optional<JointVector> ApproachPose() const;
  /// The planned tip path in the base frame, sampled every `spacing` metres (for reports and
  /// collision checks).
  std::vector<Eigen::Vector3d> PlannedTipPath(double spacing = 0.1) const;
  const DigStroke& stroke() const { return stroke_; }

 private:
  struct Waypoint {
    Eigen::Vector2d p;  ///< arm plane [r, z]
    double attitude;    ///< φ_bucket [rad]
    double speed;       ///< along the segment ending here [m/s]
    DigPhase phase;     ///< the phase of the segment ending here
  };
  struct PathPoint {
    Eigen::Vector2d p;
    double attitude;
  };
  void RecomputeLengths();
  PathPoint At(double s) const;
  double Length() const { return cumulative_.back(); }
  /// Arc length of the path point nearest the tip at `attitude` φ_bucket, searched around
  /// `s_hint`.
  double Project(const Eigen::Vector2d& tip, double attitude, double s_hint) const;
  std::optional<JointVector> Solve(const PathPoint& point) const;
  void RaiseFrom(double s, double dz);
  DigPhase PhaseAt(double s) const;

  const ExcavatorKinematics& kinematics_;
  DigStroke stroke_;
  DigMotionSettings settings_;
  std::vector<Waypoint> waypoints_;
  std::vector<double> cumulative_;
  DigPhase phase_ = DigPhase::kApproach;
  std::string failure_;
  double s_ref_ = 0;
  double s_tip_ = 0;
  double last_time_ = std::numeric_limits<double>::quiet_NaN();
  double start_time_ = std::numeric_limits<double>::quiet_NaN();
  double window_start_time_ = 0;
  double window_start_s_ = 0;
  int stalls_ = 0;
  ExcavatorCommand last_command_;
};

}  // namespace autoshovel::control
