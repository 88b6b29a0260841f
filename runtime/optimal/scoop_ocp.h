// The optimal-control scoop (issue 41, item 3): from bucket contact to the end of the scooping
// motion, the least energy (travel + hydraulic, the seed's measure, Tables 6–7) that takes a
// target volume into the bucket within a time bound, or the least time within an energy bound.
//
// Direct collocation (trapezoidal, Betts, "Practical Methods for Optimal Control and Estimation
// Using Nonlinear Programming", SIAM 2010, §4.5) over the smooth scoop model (scoop_model.h) in
// two phases:
//   1. the valves' dead time τ = pilot delay + transport delay: the decision to scoop is taken
//      at contact and no valve command reaches a spool before τ, so the arm is held where it
//      was (q̇ = 0) while the drive pushes on; fixed duration, `delay_intervals` trapezoids;
//   2. the scoop proper, free duration T₂ (a decision variable), `intervals` trapezoids.
// Bounds carry the start (contact: speed, attack pose, nothing in the bucket), the joint limits
// and accelerations and the end: the target volume taken, the machine and the arm at rest, the
// bucket racked. Path constraints carry traction (μN), the drive's power, each valve section's
// rated flow, the cylinder forces the pump's pressure allows, the pump's flow and the floor;
// one terminal constraint puts the cutting edge above the pile's surface (out of the pile).
//
// First derivatives are exact: the constraints are evaluated on ceres::Jet over the generated
// dynamics and kinematics (the Jacobian is block-sparse: a trapezoid touches its two nodes and
// T₂). The Lagrangian's Hessian is assembled block by block from central differences of those
// exact block gradients (ceres::Jet cannot be nested with the generated code's double
// constants); with Ipopt's limited-memory approximation instead the solve wandered for
// thousands of iterations. An optional penalty on the controls' change between nodes
// (`control_smoothing`, off by default) damps chattering on singular arcs; the reported energy
// is E(T) alone.
//
// Warm start: a ScoopOcp keeps its last solution and multipliers and starts the next Solve from
// them (Ipopt's warm_start_init_point) when the problem has the same size.
#pragma once

#include <array>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "runtime/optimal/scoop_model.h"

namespace autoshovel::optimal {

enum class ScoopObjective { kMinimumEnergy, kMinimumTime };

struct ScoopOcpOptions {
  ScoopObjective objective = ScoopObjective::kMinimumEnergy;
  int delay_intervals = 4;   ///< trapezoids over the valves' dead time
  int intervals = 20;        ///< trapezoids over the scoop proper
  double target_volume = 0;  ///< V at the end ≥ this [m³]
  double max_time = 10;      ///< contact to end ≤ this [s]
  double min_time = 1;       ///< and ≥ this [s]
  double max_energy = std::numeric_limits<double>::infinity();  ///< kMinimumTime: E(T) ≤ [J]
  double rack_angle = NAN;       ///< bucket joint at the end ≥ this [rad]; NaN: joint max − 0.1
  double exit_clearance = 0.05;  ///< cutting edge above the pile surface at the end [m]
  double max_speed = 3.0;        ///< forward speed bound [m/s]
  /// Joint acceleration bound [rad/s²]: the spool's lag (τ_s ≈ 0.05–0.1 s) takes a joint to
  /// its flow-limited speed (≈ 0.3–0.6 rad/s) in about 0.1 s.
  double max_joint_acceleration = 5.0;
  /// Weight of Σ (Δu/scale)² in the objective [-]. Without it the optimum chatters between
  /// nodes and exploits the trapezoid's error: on the gravel test pile it booked 197 kJ that
  /// the same controls, integrated finely, turn into 333 kJ. With 1e-3 the plan is 217 kJ
  /// and re-integrates within 10 % (ScoopOcpSolve.TrajectoryReintegratesToItsNodes).
  double control_smoothing = 1e-3;
  double tolerance = 1e-6;  ///< Ipopt's tol (scaled NLP error)
  int max_iterations = 3000;
  int print_level = 0;  ///< Ipopt's print_level (0: silent)
  /// The Lagrangian's Hessian from differences of the exact block gradients (true), or Ipopt's
  /// limited-memory quasi-Newton update (false: cheaper iterations, many more of them).
  bool exact_hessian = true;
  /// Ipopt's derivative checker at the starting point: "none", "first-order", "second-order".
  std::string derivative_test = "none";
  bool warm_start = true;
};

/// The machine at contact.
struct ScoopStart {
  double speed = 1.0;               ///< [m/s]
  std::array<double, kJoints> q{};  ///< attack pose [rad]
  double volume = 0;                ///< already in the bucket [m³]
};

struct ScoopOcpSolution {
  bool ok = false;     ///< Ipopt converged (Solve_Succeeded or Solved_To_Acceptable_Level)
  std::string status;  ///< Ipopt's return status, in words
  int iterations = 0;
  double solve_seconds = 0;  ///< wall clock of the solve
  bool warm_started = false;
  double energy = 0;  ///< E(T) [J]
  double time = 0;    ///< T: contact to end [s]
  double volume = 0;  ///< V(T) [m³]
  // Ipopt's unscaled optimality measures at the solution.
  double dual_infeasibility = 0, constraint_violation = 0, complementarity = 0;
  double kkt_error = 0;  ///< Ipopt's overall NLP error (unscaled)
  /// ‖∇f + Jᵀλ − z_L + z_U‖∞ over the free variables, recomputed here from the returned
  /// multipliers in the scaled variables Ipopt saw. It agrees with Ipopt's dual infeasibility
  /// (9e-8 on the gravel test pile) without control smoothing; with it, it differs by about
  /// the smoothing term's gradient (2e-3 there), which is not yet explained.
  double stationarity = 0;
  /// The most violated constraint at the returned point (scaled), for a failed solve's report.
  std::string worst_constraint;
  double worst_violation = 0;
  std::vector<double> time_at;                         ///< node times [s]
  std::vector<std::array<double, kStates>> state;      ///< per node
  std::vector<std::array<double, kControls>> control;  ///< per node

  /// The state and control at time t, interpolated linearly between nodes (held at the ends).
  std::array<double, kStates> StateAt(double t) const;
  std::array<double, kControls> ControlAt(double t) const;
};

class ScoopOcp {
 public:
  ScoopOcp(const ScoopModel& model, const ScoopOcpOptions& options);
  ~ScoopOcp();
  ScoopOcp(const ScoopOcp&) = delete;
  ScoopOcp& operator=(const ScoopOcp&) = delete;

  /// Solves from `start` (warm-started from the last solution when there is one). Never
  /// throws for a failed solve: `ok` is false and `status` says why.
  ScoopOcpSolution Solve(const ScoopStart& start);

  /// Another model (another pile or material) of the same machine class: the next Solve
  /// still warm-starts from the last solution, which has the same size.
  void set_model(const ScoopModel& model) { model_ = &model; }
  const ScoopOcpOptions& options() const { return options_; }
  void set_options(const ScoopOcpOptions& options) { options_ = options; }
  /// The dead time phase 1 lasts [s].
  double dead_time() const;

 private:
  class Nlp;
  const ScoopModel* model_;
  ScoopOcpOptions options_;
  struct WarmStart;
  std::unique_ptr<WarmStart> warm_;
};

}  // namespace autoshovel::optimal
