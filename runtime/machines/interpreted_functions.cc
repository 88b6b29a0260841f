#include "runtime/machines/interpreted_functions.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "runtime/model/dual.h"
#include "runtime/model/interpreted_model.h"

namespace autoshovel::machines {

namespace {

// One interpreted machine: its own copy of the description (InterpretedModel holds a
// reference), the model, and the arrays MachineFunctions points into.
struct Interpreted {
  std::string key;
  model::MachineDescription machine;
  std::unique_ptr<model::InterpretedModel> model;
  std::string kind;
  std::vector<double> nominal_params, joint_min, joint_max;
  std::vector<int> actuator_joint;
  generated::MachineFunctions functions{};
};

std::mutex slots_mutex;
std::array<std::unique_ptr<Interpreted>, kInterpretedSlots> slots;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void ForwardKinematics(const Interpreted& m, const double* angles, const double* params,
                       double* pose) {
  m.model->ForwardKinematics(angles, params, pose);
}

// Row-major 4 x num_angles and 4 x num_params, one forward-mode pass per input.
void ForwardKinematicsJacobians(const Interpreted& m, const double* angles, const double* params,
                                double* pose, double* d_pose_d_angles, double* d_pose_d_params) {
  using D = model::Dual<double>;
  const int na = m.functions.num_angles, np = m.functions.num_params;
  std::vector<D> a(na), p(np);
  std::array<D, 4> out;
  for (int input = 0; input < na + np; ++input) {
    for (int k = 0; k < na; ++k) a[k] = D(angles[k], input == k ? 1.0 : 0.0);
    for (int k = 0; k < np; ++k) p[k] = D(params[k], input == na + k ? 1.0 : 0.0);
    m.model->ForwardKinematics(a.data(), p.data(), out.data());
    for (int r = 0; r < 4; ++r) {
      if (input < na) {
        d_pose_d_angles[r * na + input] = out[r].d;
      } else {
        d_pose_d_params[r * np + input - na] = out[r].d;
      }
    }
  }
  ForwardKinematics(m, angles, params, pose);
}

bool WithinLimits(const Interpreted& m, const double* q) {
  for (int j = 0; j < m.functions.num_joints; ++j) {
    if (!(q[j] >= m.joint_min[j] - 1e-9 && q[j] <= m.joint_max[j] + 1e-9)) return false;
  }
  return true;
}

// The generated inverse (codegen/symbolic_model.cc, BuildKinematics) evaluated numerically: the
// planar two-link problem (boom, next link) to the wrist point, both elbow branches, the first
// within the joint limits wins.
int InverseKinematics(const Interpreted& m, const double* target, const double* params, double* q) {
  const model::MachineDescription& d = m.machine;
  const int joints = m.functions.num_joints;
  double wx = 0, wz = 0;
  if (d.swing) {
    wx = std::hypot(target[0], target[1]) - d.arm_pivot.x() - params[2] * std::cos(target[3]);
    wz = target[2] - d.arm_pivot.y() - params[2] * std::sin(target[3]);
  } else {
    wx = target[0] - d.arm_pivot.x();
    wz = target[2] - d.arm_pivot.y();
  }
  const double l1 = params[0], l2 = params[1];
  const double cos_elbow = (wx * wx + wz * wz - l1 * l1 - l2 * l2) / (2.0 * l1 * l2);
  if (!(cos_elbow >= -1.0 && cos_elbow <= 1.0)) return 1;
  std::vector<std::vector<double>> branch(2, std::vector<double>(joints, 0.0));
  for (int b = 0; b < 2; ++b) {
    const double q2 = (b == 0 ? 1.0 : -1.0) * std::acos(cos_elbow);
    const double q1 = std::atan2(wz, wx) - std::atan2(l2 * std::sin(q2), l1 + l2 * std::cos(q2));
    branch[b][0] = q1;
    branch[b][1] = q2;
    if (d.swing) {
      branch[b][2] = target[3] - q1 - q2;
      branch[b][3] = std::atan2(target[1], target[0]);
    }
    for (double& angle : branch[b]) angle = std::remainder(angle, 2.0 * std::numbers::pi);
  }
  for (int b = 0; b < 2; ++b) {
    if (WithinLimits(m, branch[b].data())) {
      std::copy(branch[b].begin(), branch[b].end(), q);
      return 0;
    }
  }
  std::copy(branch[0].begin(), branch[0].end(), q);
  return 2;
}

double CylinderLength(const Interpreted& m, int actuator, const double* q) {
  if (actuator < 0 || actuator >= m.functions.num_actuators) return kNaN;
  return m.model->CylinderLength(actuator, q);
}

double LeverArm(const Interpreted& m, int actuator, const double* q) {
  if (actuator < 0 || actuator >= m.functions.num_actuators) return kNaN;
  return m.model->LeverArms(actuator, q)[m.actuator_joint[actuator]];
}

// As the generated JointFromCylinderLength: bracketed Newton on the actuator's own joint.
int JointFromCylinderLength(const Interpreted& m, int actuator, double length, const double* q,
                            double* q_out) {
  if (actuator < 0 || actuator >= m.functions.num_actuators) return 1;
  const int joint = m.actuator_joint[actuator];
  std::copy(q, q + m.functions.num_joints, q_out);
  double low = m.joint_min[joint], high = m.joint_max[joint];
  q_out[joint] = low;
  const double length_low = CylinderLength(m, actuator, q_out);
  q_out[joint] = high;
  const double length_high = CylinderLength(m, actuator, q_out);
  const double sign = length_high > length_low ? 1.0 : -1.0;
  if (sign * (length - length_low) < 0.0 || sign * (length - length_high) > 0.0) return 1;
  double angle = 0.5 * (low + high);
  for (int iteration = 0; iteration < 100; ++iteration) {
    q_out[joint] = angle;
    const double error = CylinderLength(m, actuator, q_out) - length;
    if (std::abs(error) < 1e-13) break;
    if (sign * error > 0.0) {
      high = angle;
    } else {
      low = angle;
    }
    const double newton = angle - error / LeverArm(m, actuator, q_out);
    angle = (newton > low && newton < high) ? newton : 0.5 * (low + high);
    if (high - low < 1e-15) break;
  }
  q_out[joint] = angle;
  return 0;
}

void PlantRhs(const Interpreted& m, const double* x, const double* u, double* xdot) {
  m.model->PlantRhs(x, u, xdot);
}

void PlantJacobian(const Interpreted& m, const double* x, const double* u, double* jacobian) {
  m.model->PlantJacobian(x, u, jacobian);
}

// Eq. (3): r = measured − (p_M(θ_i) − p_M(θ_j)), the tip in the arm plane (swing left out).
void TipDisplacementResidual(const Interpreted& m, const double* angles_i, const double* angles_j,
                             const double* measured, const double* params, double* residual) {
  const int na = m.functions.num_angles;
  std::vector<double> a_i(angles_i, angles_i + na), a_j(angles_j, angles_j + na);
  if (m.machine.swing) a_i.back() = a_j.back() = 0.0;
  std::array<double, 4> pose_i{}, pose_j{};
  m.model->ForwardKinematics(a_i.data(), params, pose_i.data());
  m.model->ForwardKinematics(a_j.data(), params, pose_j.data());
  residual[0] = measured[0] - (pose_i[0] - pose_j[0]);
  residual[1] = measured[1] - (pose_i[2] - pose_j[2]);
}

// Rigid-body terms of M(q) q̈ + bias(q, q̇) = actuator + external forces.
void MassMatrix(const Interpreted& m, const double* q, double payload, double* mass) {
  const int J = m.functions.num_joints;
  std::vector<double> qd(J, 0.0), velocity_terms(J), gravity(J);
  m.model->Dynamics(q, qd.data(), payload, 0.0, mass, velocity_terms.data(), gravity.data());
}

void BiasForces(const Interpreted& m, const double* q, const double* qd, double payload,
                double pitch, double* bias) {
  const int J = m.functions.num_joints;
  std::vector<double> mass(J * J), gravity(J);
  m.model->Dynamics(q, qd, payload, pitch, mass.data(), bias, gravity.data());
  for (int j = 0; j < J; ++j) bias[j] -= gravity[j];
}

void MechanicalEnergy(const Interpreted& m, const double* q, const double* qd, double payload,
                      double pitch, double* energy) {
  const std::array<double, 2> e = m.model->MechanicalEnergy(q, qd, payload, pitch);
  energy[0] = e[0];
  energy[1] = e[1];
}

// Plain function pointers carry no data: slot S's trampolines reach slots[S].
template <int S>
struct Slot {
  static const Interpreted& M() { return *slots[S]; }
  static void Forward(const double* a, const double* p, double* pose) {
    ForwardKinematics(M(), a, p, pose);
  }
  static void Jacobians(const double* a, const double* p, double* pose, double* da, double* dp) {
    ForwardKinematicsJacobians(M(), a, p, pose, da, dp);
  }
  static int Inverse(const double* target, const double* p, double* q) {
    return InverseKinematics(M(), target, p, q);
  }
  static double Length(int actuator, const double* q) { return CylinderLength(M(), actuator, q); }
  static double Lever(int actuator, const double* q) { return LeverArm(M(), actuator, q); }
  static int JointFromLength(int actuator, double length, const double* q, double* q_out) {
    return JointFromCylinderLength(M(), actuator, length, q, q_out);
  }
  static void Rhs(double /*t*/, const double* x, const double* u, double* xdot) {
    PlantRhs(M(), x, u, xdot);
  }
  static void Jacobian(double /*t*/, const double* x, const double* u, double* jacobian) {
    PlantJacobian(M(), x, u, jacobian);
  }
  static void Residual(const double* ai, const double* aj, const double* measured, const double* p,
                       double* residual) {
    TipDisplacementResidual(M(), ai, aj, measured, p, residual);
  }
  static void Mass(const double* q, double payload, double* mass) {
    MassMatrix(M(), q, payload, mass);
  }
  static void Bias(const double* q, const double* qd, double payload, double pitch, double* bias) {
    BiasForces(M(), q, qd, payload, pitch, bias);
  }
  static void Energy(const double* q, const double* qd, double payload, double pitch,
                     double* energy) {
    MechanicalEnergy(M(), q, qd, payload, pitch, energy);
  }
  static void Fill(generated::MachineFunctions& f) {
    f.forward_kinematics = &Forward;
    f.forward_kinematics_jacobians = &Jacobians;
    f.inverse_kinematics = &Inverse;
    f.cylinder_length = &Length;
    f.lever_arm = &Lever;
    f.joint_from_cylinder_length = &JointFromLength;
    f.plant_rhs = &Rhs;
    f.plant_jacobian = &Jacobian;
    f.tip_displacement_residual = &Residual;
    f.mass_matrix = &Mass;
    f.bias_forces = &Bias;
    f.mechanical_energy = &Energy;
  }
};

template <std::size_t... S>
void FillSlot(int slot, generated::MachineFunctions& f, std::index_sequence<S...>) {
  ((static_cast<int>(S) == slot ? Slot<static_cast<int>(S)>::Fill(f) : void()), ...);
}

std::string KeyOf(const model::MachineDescription& machine) {
  std::string key = machine.name + '\n' + machine.sha256;
  for (const std::string& overlay : machine.overlays) key += '\n' + overlay;
  return key;
}

}  // namespace

const generated::MachineFunctions& InterpretedFunctions(const model::MachineDescription& machine) {
  const std::string key = KeyOf(machine);
  std::lock_guard<std::mutex> lock(slots_mutex);
  int free_slot = -1;
  for (int s = 0; s < kInterpretedSlots; ++s) {
    if (slots[s] && slots[s]->key == key) return slots[s]->functions;
    if (!slots[s] && free_slot < 0) free_slot = s;
  }
  if (free_slot < 0) {
    throw std::runtime_error("cannot interpret machine '" + machine.name +
                             "': " + std::to_string(kInterpretedSlots) +
                             " interpreted machines are loaded already");
  }
  auto m = std::make_unique<Interpreted>();
  m->key = key;
  m->machine = machine;
  m->model = std::make_unique<model::InterpretedModel>(m->machine);
  const model::ModelSizes sizes = m->model->sizes();
  m->kind = model::ToString(machine.kind);
  m->nominal_params = m->model->NominalParams();
  for (const model::Link& link : m->machine.links) {
    m->joint_min.push_back(link.joint_min);
    m->joint_max.push_back(link.joint_max);
  }
  if (m->machine.swing) {
    m->joint_min.push_back(m->machine.swing->joint_min);
    m->joint_max.push_back(m->machine.swing->joint_max);
  }
  for (const model::Actuator& actuator : m->machine.hydraulics.actuators) {
    m->actuator_joint.push_back(actuator.joint == "swing" ? sizes.num_joints - 1
                                                          : m->machine.LinkIndex(actuator.joint));
  }
  generated::MachineFunctions& f = m->functions;
  f.name = m->machine.name.c_str();
  f.kind = m->kind.c_str();
  f.source_file = m->machine.source_file.c_str();
  f.source_sha256 = m->machine.sha256.c_str();
  f.num_links = sizes.num_links;
  f.num_joints = sizes.num_joints;
  f.num_angles = sizes.num_angles;
  f.num_params = sizes.num_params;
  f.num_states = sizes.num_states;
  f.num_inputs = sizes.num_inputs;
  f.num_actuators = static_cast<int>(m->actuator_joint.size());
  f.nominal_params = m->nominal_params.data();
  f.joint_min = m->joint_min.data();
  f.joint_max = m->joint_max.data();
  f.actuator_joint = m->actuator_joint.data();
  FillSlot(free_slot, f, std::make_index_sequence<kInterpretedSlots>{});
  slots[free_slot] = std::move(m);
  return slots[free_slot]->functions;
}

}  // namespace autoshovel::machines
