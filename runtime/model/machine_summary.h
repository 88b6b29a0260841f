// Derived quantities a field engineer checks before trusting a description: reach, dump height,
// bucket-tip workspace, cylinder stroke used against available, lever arms and hydraulic
// capacity at the carry pose. Computed from the description by the interpreted model.
#pragma once

#include <string>
#include <vector>

#include "runtime/model/description.h"

namespace autoshovel::model {

struct ActuatorSummary {
  std::string name;
  std::string joint;
  bool is_motor = false;
  double length_at_joint_min = 0;       ///< [m]
  double length_at_joint_max = 0;       ///< [m]
  double retracted_length = 0;          ///< [m]
  double stroke = 0;                    ///< available [m]
  double stroke_used = 0;               ///< over the joint range [m]
  double lever_min = 0, lever_max = 0;  ///< |dL/dq| over the joint range [m/rad]
  // A cylinder whose length moves with the joints before its own (base on the chassis, rod on
  // a rocker: a frame-mounted Z-bar or parallel-lift tilt cylinder) does not reach the whole
  // joint range at every pose of those joints: its stroke slides a window over it. Then the
  // figures above are over what it reaches (the reachable window, the boom over its whole
  // range): stroke_used is the part of the stroke that keeps the joint within its limits
  // somewhere, lever_min/max over the reachable poses, and length_at_joint_min/max are the
  // shortest and longest lengths that pose the joint within its limits (the margins then say how
  // far the stroke goes past them); the windows and overruns below say where.
  bool moves_with_earlier_joints = false;
  double window_carry_min = 0,
         window_carry_max = 0;                    ///< joint reached at the carry boom angle [rad]
  double window_top_min = 0, window_top_max = 0;  ///< at the boom's upper limit [rad]
  double window_bottom_min = 0, window_bottom_max = 0;  ///< at the boom's lower limit [rad]
  /// How far the stroke lets the joint pass its lower / upper limit at the worst boom angle
  /// (the plant stops a joint only at its cylinder's ends: a limit the cylinder does not hold is
  /// passed) [rad].
  double overrun_below_min = 0, overrun_above_max = 0;
  double lever_at_carry = 0;       ///< dL/dq at the carry pose [m/rad]
  double torque_at_relief = 0;     ///< extending at relief pressure, at carry [N·m]
  double transport_delay = 0;      ///< [s]
  double spool_time_constant = 0;  ///< [s]
};

struct MachineSummary {
  // Workspace of the bucket tip over the joint ranges (base frame, arm plane) [m].
  double tip_x_min = 0, tip_x_max = 0, tip_z_min = 0, tip_z_max = 0;
  double max_reach = 0;             ///< largest horizontal tip distance from the base origin [m]
  double max_reach_at_ground = 0;   ///< same, with the tip at ground level (z = 0) [m]
  double max_tip_height = 0;        ///< [m]
  double max_hinge_pin_height = 0;  ///< highest bucket pivot (loaders: "hinge pin height") [m]
  double dig_depth = 0;             ///< lowest tip below ground (excavators) [m]
  // Loaders: the 45° dump at full lift (SAE J732 / ISO 7131; docs/spec_sheet.md): boom at its
  // upper limit, the bucket's floor (the profile's edge from the cutting edge to the next point)
  // 45° below horizontal.
  bool dump_pose_reachable = false;
  std::vector<double> dump_pose;       ///< joint positions of that pose [rad]
  double dump_floor_to_edge_line = 0;  ///< floor's angle above the pin-to-edge line [rad]
  double dump_clearance = 0;           ///< cutting edge tip above the ground at that pose [m]
  double dump_reach = 0;               ///< tip ahead of the front of the front tyres [m]
  /// The floor's angle to horizontal at full lift with the bucket dumped as far as it goes (its
  /// joint limit, or its tilt cylinder's end), negative down [rad].
  double dump_floor_at_limit = 0;
  std::vector<double> carry_pose;  ///< joint positions used as "carry" [rad]
  std::string carry_pose_definition;
  double lift_capacity_at_carry = 0;  ///< payload the boom holds at relief pressure [kg]
  std::vector<ActuatorSummary> actuators;
  double struck_volume = 0;              ///< profile area × width [m³]
  double payload_at_rated_capacity = 0;  ///< rated (heaped) capacity × design density [kg]
  /// Coarse occupancy of the tip workspace, rows from top (z max) to bottom, '#' reachable.
  std::vector<std::string> workspace_map;
};

MachineSummary Summarize(const MachineDescription& machine);

}  // namespace autoshovel::model
