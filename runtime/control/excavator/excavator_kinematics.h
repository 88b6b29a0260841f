// Where the excavator's linkage is for joint positions q, from the generated forward and inverse
// kinematics (generated/<machine>/, wheel-loader seed Eq. 1–2 extended by the swing): the base
// frame has its origin on the swing axis at ground level, x forward of the undercarriage, z up.
// The arm works in a vertical plane through the swing axis, turned by ψ about z; a point of
// that plane is given by its radial distance r from the swing axis (negative behind it) and its
// height z, and lies at (r cos ψ, r sin ψ, z) in the base frame.
//
// Intermediate pins come from the same generated function: the chain is Σ l_k (cos φ_k, sin φ_k)
// added to the boom foot, so evaluating it with the lengths beyond link k set to zero gives the
// pin at the end of link k (the IMU offsets α_k are converted, so any calibrated parameters work).
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "generated/machine_functions.h"
#include "runtime/control/excavator/excavator_joints.h"
#include "runtime/model/description.h"

namespace autoshovel::control {

/// The arm for one q: the pins in the arm plane [r, z] and the links' angles φ_k in frame M.
struct ArmPlanePins {
  std::array<Eigen::Vector2d, 4> pins;  ///< boom foot, boom tip, bucket pin, bucket tip [m]
  std::array<double, 3> link_angles{};  ///< φ_boom, φ_stick, φ_bucket [rad]
  double swing = 0;                     ///< ψ [rad]
};

class ExcavatorKinematics {
 public:
  /// Holds copies of what it needs. Throws std::invalid_argument when the description is not an
  /// excavator with boom, stick, bucket and swing, or the generated code is not for it (sizes,
  /// or its boom foot and lengths differ from the description's).
  ExcavatorKinematics(const model::MachineDescription& machine,
                      const generated::MachineFunctions& functions);

  /// Pins and link angles for joint positions q (generated forward kinematics).
  ArmPlanePins Pins(const JointVector& q) const;

  /// A point given in link k's frame (origin at its pivot, x along the link) in the arm plane.
  static Eigen::Vector2d ArmPlanePoint(const ArmPlanePins& pins, int link,
                                       const Eigen::Vector2d& p_link);

  /// A point of the arm plane [r, z] plus a lateral offset y (left of the plane) in the base frame.
  static Eigen::Vector3d BaseFromArmPlane(double swing, const Eigen::Vector2d& p_plane,
                                          double lateral = 0.0);

  /// Bucket tip pose [x, y, z] in the base frame and its attitude φ_bucket.
  Eigen::Vector3d TipPosition(const JointVector& q) const;

  /// Joint positions that put the bucket pin at [r, z] of the arm plane turned by `swing`, the
  /// bucket joint at `bucket` (generated inverse kinematics, the solution within the joint
  /// limits). nullopt when out of reach or only outside the limits.
  std::optional<JointVector> SolveBucketPin(const Eigen::Vector2d& p_plane_pin, double swing,
                                            double bucket) const;

  /// Joint positions that put the bucket tip at `p_base_tip` with attitude φ_bucket = `attitude`.
  std::optional<JointVector> SolveTip(const Eigen::Vector3d& p_base_tip, double attitude) const;

  const Eigen::Vector2d& arm_pivot() const { return arm_pivot_; }
  const std::array<double, 3>& link_lengths() const { return lengths_; }
  const JointVector& joint_min() const { return joint_min_; }
  const JointVector& joint_max() const { return joint_max_; }
  const std::string& machine_name() const { return machine_name_; }

 private:
  const generated::MachineFunctions* functions_;
  std::vector<double> params_;  ///< [l_1..l_3, α_1..α_3]
  std::array<double, 3> lengths_{};
  Eigen::Vector2d arm_pivot_;
  JointVector joint_min_, joint_max_;
  std::string machine_name_;
};

}  // namespace autoshovel::control
