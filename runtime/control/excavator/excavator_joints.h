// The joint vector of the excavator control layer (excavator seed §4.4). Joints are in the plant
// order of the machine description and of the generated code, q = [boom, stick, bucket, swing]:
//   boom    φ₁, the boom's angle in frame M (x forward, z up; positive raises it),
//   stick   q₂ = φ₂ − φ₁, relative to the boom (negative folds it under the boom, "crowd in"),
//   bucket  q₃ = φ₃ − φ₂, relative to the stick (negative curls the tip towards the stick),
//   swing   ψ, the upper structure about the vertical axis through the base origin.
// The seed numbers its joints differently (θ₁ swing, θ₂ boom, θ₃ stick, θ₄ bucket) and measures
// them from other zeros, so its Fig. 14 numbers are not ours; docs/excavator_scripts.md maps them.
#pragma once

#include <Eigen/Core>
#include <string_view>

namespace autoshovel::control {

using JointVector = Eigen::Vector4d;  ///< [boom, stick, bucket, swing] [rad]

enum class ExcavatorJoint { kBoom = 0, kStick = 1, kBucket = 2, kSwing = 3 };
inline constexpr int kNumExcavatorJoints = 4;
inline constexpr ExcavatorJoint kAllExcavatorJoints[kNumExcavatorJoints] = {
    ExcavatorJoint::kBoom, ExcavatorJoint::kStick, ExcavatorJoint::kBucket, ExcavatorJoint::kSwing};

inline constexpr int JointIndex(ExcavatorJoint joint) { return static_cast<int>(joint); }
std::string_view JointName(ExcavatorJoint joint);

/// What the machine reports: joint positions [rad] and rates [rad/s].
struct ExcavatorState {
  JointVector q = JointVector::Zero();
  JointVector qd = JointVector::Zero();
};

/// What the low-level joint controllers are sent: desired joint positions (seed §4.4, the right-
/// hand sides of the rules), or a stop (§4.5): every joint brakes to rest and holds.
struct ExcavatorCommand {
  JointVector position = JointVector::Zero();  ///< [rad]; ignored when `stop`
  bool stop = false;
};

/// The first non-finite entry of `v`, or -1.
int FirstNonFinite(const JointVector& v);

}  // namespace autoshovel::control
