// The symbolic model of a machine: every expression the emitted code computes, built with GiNaC
// from a validated description. Derivatives (FK Jacobians, lever arms, the plant Jacobian) are
// taken symbolically here, so the emitted code is plain arithmetic.
#pragma once

#include <ginac/ginac.h>

#include <vector>

#include "runtime/model/description.h"

namespace autoshovel::codegen {

/// Symbols named after the C++ expressions that hold them in emitted code (`angles[0]`).
std::vector<GiNaC::symbol> MakeSymbols(const std::string& array, int count);

struct SymbolicMachine {
  int num_links = 0, num_joints = 0, num_angles = 0, num_params = 0, num_states = 0, num_inputs = 0;

  std::vector<GiNaC::symbol> angles;       ///< `angles[i]`: θ_cab, θ_1 … θ_n, (ψ)
  std::vector<GiNaC::symbol> params;       ///< `params[i]`: l_1 … l_n, α_1 … α_n
  std::vector<GiNaC::ex> pose;             ///< Eq. (1)–(2): [x, y, z, φ_n] in the base frame
  std::vector<GiNaC::ex> d_pose_d_angles;  ///< row-major 4 × num_angles
  std::vector<GiNaC::ex> d_pose_d_params;  ///< row-major 4 × num_params

  /// Tip in frame M [x_b, z_b] (Eq. 2) as a function of the angle symbols `angles_i[k]` and
  /// `angles_j[k]`, for the Eq. (3) residual.
  std::vector<GiNaC::ex> tip_m_i, tip_m_j;

  /// Inverse kinematics, for the two elbow branches (σ = +1, −1): joint positions from the
  /// target `target[0..3]` with link lengths `params[k]`.
  std::vector<GiNaC::ex> inverse[2];
  GiNaC::ex inverse_cos_elbow;  ///< cos q_2 of the inverse; outside [-1, 1]: unreachable

  std::vector<GiNaC::symbol> q;  ///< `q[i]`, joint positions
  /// Per actuator: pin-to-pin length L(q) [m] (motors: their joint position) and ∂L/∂q of its
  /// own joint.
  std::vector<GiNaC::ex> cylinder_length, lever_arm;

  std::vector<GiNaC::symbol> x, u;  ///< plant state `x[i]` and input `u[i]`
  /// ẋ = f(x, u), except the accelerations q̈ (rows J … 2J−1, zero here): those solve
  /// M q̈ = force numerically in the emitted code.
  std::vector<GiNaC::ex> rhs;
  std::vector<GiNaC::ex> jacobian;  ///< ∂f/∂x, row-major; rows J … 2J−1 zero (see above)

  // Rigid-body dynamics of the arm (Lagrangian of every moving body through the closed chains).
  std::vector<GiNaC::ex> mass_matrix;     ///< M(q, payload), J × J row-major, symmetric
  std::vector<GiNaC::ex> velocity_terms;  ///< h(q, q̇): Coriolis and centrifugal [N·m]
  std::vector<GiNaC::ex> bias;            ///< h − Q_gravity: M q̈ + bias = actuator + external
  std::vector<GiNaC::ex> force;           ///< right side of M q̈ = force, everything included
  std::vector<GiNaC::ex> energy;          ///< [kinetic T, potential V] [J]
  std::vector<GiNaC::ex> d_force_d_x;     ///< J × num_states
  std::vector<GiNaC::ex> d_mass_d_q;      ///< ∂M/∂q_k: J blocks of J × J
};

SymbolicMachine BuildSymbolicMachine(const model::MachineDescription& machine);

}  // namespace autoshovel::codegen
