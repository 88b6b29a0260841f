// Arm kinematic calibration (wheel-loader seed §3.1, Eq. 3–4, §7.1): the link lengths l_k and
// IMU mounting offsets α_k that make the generated forward kinematics (Eq. 1–2) reproduce the
// measured displacements of the bucket tip between consecutive poses,
//   min Σ_i ‖Δp_{i,i+1} − (p_b(θ_i) − p_b(θ_{i+1}))‖²   s.t. l_k > 0, −π < α_k < π,
// solved by Ceres' Levenberg–Marquardt until the projected gradient's ∞-norm is ≤ 1e-10.
//
// The residual's Jacobian comes from the generated code (forward_kinematics_jacobians), so the
// same solver serves every generated machine. Written in (l, α), the problem is a polar
// reparametrisation of a linear least-squares problem in (l cos α, l sin α): there is one
// minimum, reached from any start inside the bounds, provided the poses excite every parameter.
// That is checked: fewer than 3 poses, or a Jacobian at the solution whose condition number
// exceeds 1e8 (poses nearly collinear, or a joint never moved), is reported as degenerate and
// no parameters are returned.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "generated/machine_functions.h"

namespace autoshovel::identification {

struct ArmCalibrationData {
  /// Per pose the IMU angles [θ_cab, θ_1 … θ_n (, ψ_swing)] [rad] (Eq. 1).
  std::vector<std::vector<double>> angles;
  /// Measured tip displacement from pose i to pose i+1, p(θ_i) − p(θ_{i+1}), in frame M's
  /// x–z plane [m]; one fewer than poses.
  std::vector<Eigen::Vector2d> displacements;
  std::string source;  ///< file it came from (for messages)
};

struct ArmCalibrationResult {
  bool ok = false;
  std::string degenerate;        ///< why no answer was given ("" when ok)
  std::vector<double> params;    ///< [l_1 … l_n, α_1 … α_n]
  std::vector<double> initial;   ///< where the solver started
  std::vector<double> std_dev;   ///< 1σ from (JᵀJ)⁻¹ scaled by the residual variance
  double cost = 0;               ///< ½ Σ r² at the solution [m²]
  double gradient_max_norm = 0;  ///< projected gradient ∞-norm at the solution
  double condition_number = 0;   ///< of the Jacobian at the solution
  int iterations = 0;
  std::vector<Eigen::Vector2d> residuals;  ///< per displacement, at the solution [m]
  /// Per displacement at the start (NaN where the start is outside the workspace) [m].
  std::vector<Eigen::Vector2d> initial_residuals;
};

/// Calibrates the arm of `machine` from `data`, starting at `initial` (size num_params; empty:
/// the machine's nominal parameters). Throws std::invalid_argument for malformed data (sizes,
/// non-finite values); degenerate data give ok == false with the reason.
ArmCalibrationResult CalibrateArm(const generated::MachineFunctions& machine,
                                  const ArmCalibrationData& data, std::vector<double> initial = {});

}  // namespace autoshovel::identification
