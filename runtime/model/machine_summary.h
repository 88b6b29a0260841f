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
  double lever_at_carry = 0;            ///< dL/dq at the carry pose [m/rad]
  double torque_at_relief = 0;          ///< extending at relief pressure, at carry [N·m]
  double transport_delay = 0;           ///< [s]
  double spool_time_constant = 0;       ///< [s]
};

struct MachineSummary {
  // Workspace of the bucket tip over the joint ranges (base frame, arm plane) [m].
  double tip_x_min = 0, tip_x_max = 0, tip_z_min = 0, tip_z_max = 0;
  double max_reach = 0;             ///< largest horizontal tip distance from the base origin [m]
  double max_reach_at_ground = 0;   ///< same, with the tip at ground level (z = 0) [m]
  double max_tip_height = 0;        ///< [m]
  double max_hinge_pin_height = 0;  ///< highest bucket pivot (loaders: "hinge pin height") [m]
  double dig_depth = 0;             ///< lowest tip below ground (excavators) [m]
  // Loaders: the 45° dump at full lift (standard spec-sheet figures).
  bool dump_pose_reachable = false;
  double dump_clearance = 0;       ///< tip height, boom up, bucket 45° down [m]
  double dump_reach = 0;           ///< tip ahead of the front tyres at that pose [m]
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
