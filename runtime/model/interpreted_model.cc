#include "runtime/model/interpreted_model.h"

#include <cmath>
#include <stdexcept>

namespace autoshovel::model {

ModelSizes SizesOf(const MachineDescription& machine) {
  ModelSizes sizes;
  sizes.num_links = static_cast<int>(machine.num_links());
  sizes.num_joints = static_cast<int>(machine.num_joints());
  sizes.num_angles = sizes.num_links + 1 + (machine.swing ? 1 : 0);
  sizes.num_params = 2 * sizes.num_links;
  sizes.num_states = 5 * sizes.num_joints;
  sizes.num_inputs = 3 * sizes.num_joints + 2;
  return sizes;
}

double BucketProfileArea(const MachineDescription& machine) {
  const auto& polygon = machine.bucket.profile;
  double twice_area = 0;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const auto& a = polygon[i];
    const auto& b = polygon[(i + 1) % polygon.size()];
    twice_area += a.x() * b.y() - b.x() * a.y();
  }
  return std::abs(twice_area) / 2.0;
}

double BucketLevelAttitude(const MachineDescription& machine) {
  const auto& profile = machine.bucket.profile;
  if (profile.size() < 2) throw std::invalid_argument("bucket profile has fewer than 2 points");
  // The opening's direction in the bucket frame is γ; it points backwards (π) at φ = π − γ.
  const Eigen::Vector2d opening = profile.back() - profile.front();
  return M_PI - std::atan2(opening.y(), opening.x());
}

Eigen::Vector2d BucketPayloadCenter(const MachineDescription& machine) {
  // Shoelace centroid of the cross-section polygon.
  const auto& polygon = machine.bucket.profile;
  double twice_area = 0;
  Eigen::Vector2d weighted = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const auto& a = polygon[i];
    const auto& b = polygon[(i + 1) % polygon.size()];
    const double cross = a.x() * b.y() - b.x() * a.y();
    twice_area += cross;
    weighted += cross * (a + b);
  }
  if (twice_area == 0) throw std::invalid_argument("bucket profile has zero area");
  return weighted / (3.0 * twice_area);
}

InterpretedModel::InterpretedModel(const MachineDescription& machine)
    : machine_(machine), sizes_(SizesOf(machine)), payload_center_(BucketPayloadCenter(machine)) {
  for (int j = 0; j < sizes_.num_joints; ++j) {
    const int actuator = machine.ActuatorOfJoint(j);
    if (actuator < 0)
      throw std::invalid_argument("joint " + std::to_string(j) + " has no actuator");
    actuator_of_joint_.push_back(actuator);
  }
}

std::vector<double> InterpretedModel::NominalParams() const {
  std::vector<double> params(sizes_.num_params);
  for (int k = 0; k < sizes_.num_links; ++k) {
    params[k] = machine_.links[k].length;
    params[sizes_.num_links + k] = machine_.links[k].imu_offset;
  }
  return params;
}

std::vector<double> InterpretedModel::AnglesFromJoints(const double* q,
                                                       const double* params) const {
  const int n = sizes_.num_links;
  std::vector<double> angles(sizes_.num_angles, 0.0);
  double phi = 0;
  for (int k = 0; k < n; ++k) {
    phi = k == 0 ? q[0] : phi + q[k];
    angles[k + 1] = phi - params[n + k];  // inverse of Eq. (1) with θ_cab = 0
  }
  if (machine_.swing) angles[n + 1] = q[n];
  return angles;
}

Eigen::Vector4d InterpretedModel::TipFromJoints(const double* q) const {
  const std::vector<double> params = NominalParams();
  const std::vector<double> angles = AnglesFromJoints(q, params.data());
  Eigen::Vector4d pose;
  ForwardKinematics(angles.data(), params.data(), pose.data());
  return pose;
}

std::vector<double> InterpretedModel::GravityTorques(const double* q, double payload,
                                                     double pitch) const {
  const int J = sizes_.num_joints;
  const std::vector<double> qd(J, 0.0);
  std::vector<double> mass(J * J), velocity_terms(J), gravity(J);
  Dynamics(q, qd.data(), payload, pitch, mass.data(), velocity_terms.data(), gravity.data());
  return gravity;
}

std::array<double, 2> InterpretedModel::MechanicalEnergy(const double* q, const double* qd,
                                                         double payload, double pitch) const {
  const int J = sizes_.num_joints;
  std::vector<double> mass(J * J), velocity_terms(J), gravity(J);
  Dynamics(q, qd, payload, pitch, mass.data(), velocity_terms.data(), gravity.data());
  double kinetic = 0;
  for (int i = 0; i < J; ++i) {
    for (int j = 0; j < J; ++j) kinetic += 0.5 * mass[i * J + j] * qd[i] * qd[j];
  }
  std::vector<BodyState<double>> bodies;
  double potential = 0;
  if (MovingBodies(q, payload, bodies)) {
    const double g_x = -plant::kGravity * std::sin(pitch);
    const double g_z = -plant::kGravity * std::cos(pitch);
    for (const auto& b : bodies) potential -= b.mass * (g_x * b.center.x + g_z * b.center.z);
  }
  return {kinetic, potential};
}

void InterpretedModel::PlantJacobian(const double* x, const double* u, double* jacobian) const {
  // Forward mode, one column per pass, with the same dual numbers the lever arms use (Eigen's
  // dynamic AutoDiffScalar mixes empty and sized derivative vectors badly in this code).
  const int n = sizes_.num_states;
  std::vector<Dual<double>> xs(n), xdot(n);
  for (int c = 0; c < n; ++c) {
    for (int i = 0; i < n; ++i) xs[i] = Dual<double>(x[i], i == c ? 1.0 : 0.0);
    PlantRhs(xs.data(), u, xdot.data());
    for (int r = 0; r < n; ++r) jacobian[r * n + c] = xdot[r].d;
  }
}

}  // namespace autoshovel::model
