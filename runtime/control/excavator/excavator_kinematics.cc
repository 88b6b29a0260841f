#include "runtime/control/excavator/excavator_kinematics.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace autoshovel::control {
namespace {

constexpr int kLinks = 3;

}  // namespace

ExcavatorKinematics::ExcavatorKinematics(const model::MachineDescription& machine,
                                         const generated::MachineFunctions& functions)
    : functions_(&functions), machine_name_(machine.name) {
  if (machine.kind != model::MachineKind::kExcavator || !machine.swing ||
      machine.links.size() != kLinks || machine.links[0].name != "boom" ||
      machine.links[1].name != "stick" || machine.links[2].name != "bucket") {
    throw std::invalid_argument("ExcavatorKinematics: " + machine.name +
                                " is not an excavator with links boom, stick, bucket and a swing");
  }
  if (functions.num_links != kLinks || functions.num_joints != kNumExcavatorJoints ||
      functions.num_angles != kLinks + 2 || functions.num_params != 2 * kLinks ||
      functions.forward_kinematics == nullptr || functions.inverse_kinematics == nullptr ||
      std::string(functions.kind) != "excavator") {
    throw std::invalid_argument("ExcavatorKinematics: generated code " +
                                std::string(functions.name) + " is not a 3-link excavator");
  }
  params_.assign(functions.nominal_params, functions.nominal_params + functions.num_params);
  for (int k = 0; k < kLinks; ++k) {
    lengths_[k] = params_[k];
    if (std::abs(lengths_[k] - machine.links[k].length) > 1e-9) {
      throw std::invalid_argument(
          "ExcavatorKinematics: generated code of " + std::string(functions.name) + " has " +
          machine.links[k].name + " length " + std::to_string(lengths_[k]) +
          " m, the description " + std::to_string(machine.links[k].length) + " m");
    }
  }
  for (int j = 0; j < kNumExcavatorJoints; ++j) {
    joint_min_[j] = functions.joint_min[j];
    joint_max_[j] = functions.joint_max[j];
  }
  // The boom foot is what the chain gives with every length zero.
  arm_pivot_ = Pins(JointVector::Zero()).pins[0];
  if ((arm_pivot_ - machine.arm_pivot).norm() > 1e-9) {
    throw std::invalid_argument("ExcavatorKinematics: generated code of " +
                                std::string(functions.name) +
                                " has another boom foot than the description");
  }
}

ArmPlanePins ExcavatorKinematics::Pins(const JointVector& q) const {
  ArmPlanePins out;
  out.swing = q[3];
  out.link_angles[0] = q[0];
  out.link_angles[1] = q[0] + q[1];
  out.link_angles[2] = q[0] + q[1] + q[2];
  // IMU angles with the cab level (θ_cab = 0): φ_k = θ_k + α_k (Eq. 1). The arm is evaluated in
  // its own plane (ψ = 0) so that x is the radial distance, also behind the swing axis.
  double angles[kLinks + 2] = {0.0, 0.0, 0.0, 0.0, 0.0};
  for (int k = 0; k < kLinks; ++k) angles[k + 1] = out.link_angles[k] - params_[kLinks + k];
  double params[2 * kLinks];
  double pose[4];
  for (int end = 0; end <= kLinks; ++end) {
    for (int k = 0; k < 2 * kLinks; ++k) params[k] = params_[k];
    for (int k = end; k < kLinks; ++k) params[k] = 0.0;
    functions_->forward_kinematics(angles, params, pose);
    out.pins[end] = Eigen::Vector2d(pose[0], pose[2]);
  }
  return out;
}

Eigen::Vector2d ExcavatorKinematics::ArmPlanePoint(const ArmPlanePins& pins, int link,
                                                   const Eigen::Vector2d& p_link) {
  const double c = std::cos(pins.link_angles[link]), s = std::sin(pins.link_angles[link]);
  return pins.pins[link] +
         Eigen::Vector2d(c * p_link.x() - s * p_link.y(), s * p_link.x() + c * p_link.y());
}

Eigen::Vector3d ExcavatorKinematics::BaseFromArmPlane(double swing, const Eigen::Vector2d& p_plane,
                                                      double lateral) {
  const double c = std::cos(swing), s = std::sin(swing);
  return Eigen::Vector3d(c * p_plane.x() - s * lateral, s * p_plane.x() + c * lateral, p_plane.y());
}

Eigen::Vector3d ExcavatorKinematics::TipPosition(const JointVector& q) const {
  return BaseFromArmPlane(q[3], Pins(q).pins[3]);
}

std::optional<JointVector> ExcavatorKinematics::SolveBucketPin(const Eigen::Vector2d& p_plane_pin,
                                                               double swing, double bucket) const {
  if (!p_plane_pin.allFinite() || !std::isfinite(swing) || !std::isfinite(bucket)) {
    return std::nullopt;
  }
  // The tip is put one bucket length from the wanted pin, so the inverse kinematics places the
  // pin there whatever the attitude; the generated solver also checks the bucket joint's limits,
  // so attitudes are tried until one is within them, and the bucket joint is then set as asked.
  constexpr int kAttitudes = 24;
  for (int i = 0; i < kAttitudes; ++i) {
    const double attitude = -std::numbers::pi + 2.0 * std::numbers::pi * i / kAttitudes;
    const Eigen::Vector2d tip =
        p_plane_pin + lengths_[2] * Eigen::Vector2d(std::cos(attitude), std::sin(attitude));
    if (!(tip.x() > 0)) continue;  // the solver's swing is the tip's azimuth: keep it in front
    std::optional<JointVector> q = SolveTip(BaseFromArmPlane(swing, tip), attitude);
    if (!q) continue;
    (*q)[2] = bucket;
    (*q)[3] = swing;
    return q;
  }
  return std::nullopt;
}

std::optional<JointVector> ExcavatorKinematics::SolveTip(const Eigen::Vector3d& p_base_tip,
                                                         double attitude) const {
  if (!p_base_tip.allFinite() || !std::isfinite(attitude)) return std::nullopt;
  const double target[4] = {p_base_tip.x(), p_base_tip.y(), p_base_tip.z(), attitude};
  double q[kNumExcavatorJoints];
  if (functions_->inverse_kinematics(target, params_.data(), q) != 0) return std::nullopt;
  JointVector out(q[0], q[1], q[2], q[3]);
  if (FirstNonFinite(out) >= 0) return std::nullopt;
  return out;
}

}  // namespace autoshovel::control
