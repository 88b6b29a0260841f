// The refined planner's geometric constraints (excavator seed §4.2: "the refined planner chooses
// digs that meet geometric constraints (reachability and collisions)"), checked on the action
// before the forward model is asked, and on the forward model's tip path after.
//
// The nominal tip path of a DigAction, in its arm plane [r, z] turned by the swing:
//   E = (radius, entry_height)                      the tooth tip meets the surface;
//   P = (radius, entry_height − depth)              penetration, straight down;
//   D = (radius − drag_length, entry_height − depth) drag toward the machine at that depth;
//   L = (radius − drag_length, entry_height + lift_clearance)   curl and lift out, straight up.
// A real dig's tip path (the forward model's) differs in detail: the curl swings the tip on an
// arc about the bucket pin; L stands for where the tip is once clear of the surface.
//
// Reachability: the inverse kinematics (ExcavatorKinematics::SolveTip, the generated solution
// within the joint limits) must place the tip at E and P with a bucket attitude φ_bucket (angle
// of the pin-to-tip line from the horizontal, in the arm plane) in the entry range, and at D with
// one in the drag-end range. The ranges say what a sensible digging attitude is: teeth pointing
// down into the ground at entry; at the end of the drag, teeth leading toward the machine.
// Attitudes are tried from the middle of each range outward, `attitude_samples` of them.
//
// Collisions: every point of a tip path, and of each segment between consecutive points at no
// more than `path_spacing`, must be at least `undercarriage_radius` from the swing axis
// (horizontally) and at least `keep_out_margin` outside every keep-out box (base frame).
#pragma once

#include <Eigen/Core>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "runtime/control/excavator/excavator_kinematics.h"
#include "runtime/control/excavator/obstacle_box.h"
#include "runtime/model/description.h"
#include "runtime/planning/dig/dig_action.h"

namespace autoshovel::planning {

inline constexpr double kDegree = std::numbers::pi / 180.0;  ///< [rad]

struct DigGeometryConfig {
  /// φ_bucket range at E and P [rad]: from the teeth reaching forward and down (−60°) to pointing
  /// back toward the machine (−150°).
  double entry_attitude_min = -150.0 * kDegree;
  double entry_attitude_max = -60.0 * kDegree;
  /// φ_bucket range at D [rad]: the teeth lead the drag toward the machine, the bucket floor
  /// still roughly level or starting to curl (−180° to −90°).
  double drag_end_attitude_min = -180.0 * kDegree;
  double drag_end_attitude_max = -90.0 * kDegree;
  int attitude_samples = 7;  ///< per range, >= 1
  /// No tip point nearer the swing axis than this [m]: the track frame's half diagonal plus a
  /// margin (UndercarriageRadius).
  double undercarriage_radius = 3.0;
  double keep_out_margin = 0.3;  ///< [m] clearance from keep-out boxes
  double path_spacing = 0.1;     ///< [m] between checked points along a path
  double lift_clearance = 0.5;   ///< [m] L above the entry height
};

/// Throws std::invalid_argument naming the field (prefixed with `what`).
void Validate(const DigGeometryConfig& config, const std::string& what);

/// Half the diagonal of the excavator's track frame (track length × (gauge + shoe width)) plus
/// `margin` [m]: the radius about the swing axis inside which the tip would meet the tracks in
/// some swing. Throws std::invalid_argument when the description has no track dimensions.
double UndercarriageRadius(const model::MachineDescription& machine, double margin = 0.25);

/// E, P, D, L of the file comment, base frame [m].
std::vector<Eigen::Vector3d> NominalTipPath(const DigAction& action, double lift_clearance);

/// The tip point at arm-plane radius `radius` and height `z` for swing ψ, base frame [m].
Eigen::Vector3d TipInBase(double swing, double radius, double z);

class DigReachability {
 public:
  /// Copies both; throws std::invalid_argument on an invalid config.
  DigReachability(const control::ExcavatorKinematics& kinematics, const DigGeometryConfig& config);

  /// True when E, P and D are reachable as the file comment says; otherwise false with the
  /// first point that is not in `why`.
  bool Reachable(const DigAction& action, std::string& why) const;

  /// Joint positions with the tip at p_base_tip and an attitude in [attitude_min, attitude_max];
  /// nullopt when none of the sampled attitudes is reachable within the joint limits.
  std::optional<control::JointVector> Solve(const Eigen::Vector3d& p_base_tip, double attitude_min,
                                            double attitude_max) const;

 private:
  control::ExcavatorKinematics kinematics_;
  DigGeometryConfig config_;
};

/// False when `tip_path` (base frame) and the segments between its points stay clear of the
/// undercarriage radius and of `keep_out_base` by `config`'s margins; true with the first
/// violation in `why` otherwise.
bool PathCollides(const std::vector<Eigen::Vector3d>& tip_path,
                  const std::vector<control::ObstacleBox>& keep_out_base,
                  const DigGeometryConfig& config, std::string& why);

}  // namespace autoshovel::planning
