// CMA-ES, the Covariance Matrix Adaptation Evolution Strategy, for derivative-free minimisation
// of a few bounded parameters (the shovel-point scoring weights). It follows N. Hansen, "The CMA
// Evolution Strategy: A Tutorial", arXiv:1604.00772 (below: "the tutorial"): the
// (μ/μ_W, λ)-CMA-ES of its Fig. 6 with the default parameters of its Table 1 restricted to
// positive recombination weights (no active CMA), rank-one and rank-μ covariance updates,
// cumulative step-size adaptation with the h_σ stall, and its termination criteria (Appendix B).
//
// Why CMA-ES: the scoring objective is non-smooth, so gradients (even finite-difference ones) are
// unreliable, and it has only about five parameters, where CMA-ES needs a few thousand
// evaluations at most. It uses only the ranking of f-values, so it is invariant to any monotone
// rescaling of the objective.
//
// Determinism: every random number comes from std::mt19937_64 (bit-exact by the standard) turned
// into normal deviates by a written-out Box–Muller transform, so one seed gives one path with any
// standard library (std::normal_distribution is implementation-defined).
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>

namespace autoshovel::identification {

/// What the optimiser reports after every generation (for logging; it must not throw).
struct CmaesProgress {
  int generation = 0;                  ///< generations completed
  int evaluations = 0;                 ///< calls of f so far
  double sigma = 0;                    ///< step size σ
  double best_fitness = 0;             ///< best f seen so far
  double generation_best_fitness = 0;  ///< best f of this generation
  double axis_ratio = 1;  ///< √(cond C) at the last eigendecomposition: longest / shortest axis
  Eigen::VectorXd mean;   ///< distribution mean m after the update
};

struct CmaesOptions {
  int population = 0;   ///< λ; 0 picks the default 4 + ⌊3 ln n⌋ (tutorial eq. 48); else ≥ 2
  double sigma0 = 0.3;  ///< initial step size, in the units of x
  int max_evaluations = 10000;  ///< stops before a generation would exceed this
  /// Stops once a generation's best f is at or below this.
  double target_fitness = -std::numeric_limits<double>::infinity();
  /// Stops when the best f of the last 10 + ⌈30n/λ⌉ generations and all f of the latest one lie
  /// within this range (tutorial Appendix B, TolFun); 0 disables.
  double tol_fun = 1e-12;
  /// Stops when σ·√C_ii and σ·|p_c,i| are all below this (TolX), absolute in the units of x (the
  /// tutorial suggests 1e-12·σ0); 0 disables.
  double tol_x = 1e-12;
  std::uint64_t seed = 1;
  /// Box bounds, each of size n or empty (unbounded); ±inf entries leave a side open. f is only
  /// ever called inside the box: samples are projected onto it and ranked with an adaptive
  /// quadratic penalty on the projection distance (Hansen et al. 2009; see cmaes.cc for why).
  Eigen::VectorXd lower, upper;
  /// Called after each generation; may be empty.
  std::function<void(const CmaesProgress&)> on_generation;
};

/// Why the run ended: one of the names below.
namespace cmaes_stop {
inline constexpr const char* kTargetFitness = "target_fitness";
inline constexpr const char* kMaxEvaluations = "max_evaluations";
inline constexpr const char* kTolFun = "tol_fun";
inline constexpr const char* kTolX = "tol_x";
/// cond(C) > 1e14: further updates would only add rounding noise (tutorial Appendix B).
inline constexpr const char* kConditionCov = "condition_cov";
/// A 0.2-σ step along some coordinate no longer changes m in floating point (NoEffectCoord).
inline constexpr const char* kNoEffectCoordinate = "no_effect_coordinate";
/// σ·max(D) grew 10⁴-fold over sigma0: σ0 far too small, or f unbounded below (TolXUp).
inline constexpr const char* kTolXUp = "tol_x_up";
}  // namespace cmaes_stop

struct CmaesResult {
  Eigen::VectorXd best_x;  ///< best point evaluated (inside the box when bounded)
  double best_fitness = std::numeric_limits<double>::infinity();  ///< f(best_x); +inf if all NaN
  int evaluations = 0;  ///< calls of f, NaN-returning ones included
  int generations = 0;
  std::string stop_reason;  ///< one of cmaes_stop::k*
};

/// The default strategy parameters of the tutorial's Table 1 (eqs. 48–58) for positive weights
/// only; exposed so that tests can compare them with published values.
struct CmaesStrategyParameters {
  int dimension = 0;         ///< n
  int population = 0;        ///< λ
  int parents = 0;           ///< μ = ⌊λ/2⌋
  Eigen::VectorXd weights;   ///< w_1 ≥ … ≥ w_μ > 0, Σ w_i = 1
  double mu_eff = 0;         ///< μ_eff = 1/Σ w_i²
  double c_sigma = 0;        ///< c_σ, cumulation for the step-size path
  double d_sigma = 0;        ///< d_σ, step-size damping
  double c_c = 0;            ///< c_c, cumulation for the rank-one path
  double c_1 = 0;            ///< c_1, rank-one learning rate
  double c_mu = 0;           ///< c_μ, rank-μ learning rate
  double expected_norm = 0;  ///< E‖N(0, I)‖
  int eigen_interval = 1;    ///< generations between eigendecompositions of C
};

/// Throws std::invalid_argument if n < 1 or population is neither 0 nor ≥ 2.
CmaesStrategyParameters DefaultCmaesParameters(int dimension, int population = 0);

/// Minimises f from x0. Throws std::invalid_argument, naming the problem, for: empty x0, a NaN or
/// infinite x0 entry, sigma0 ≤ 0 or not finite, a bad population or max_evaluations, lower/upper
/// of the wrong size, NaN bounds, lower > upper, x0 outside the bounds. f returning NaN counts as
/// an evaluation and ranks that candidate last (+inf); exceptions from f propagate.
CmaesResult MinimizeCmaes(const std::function<double(const Eigen::VectorXd&)>& f,
                          const Eigen::VectorXd& x0, const CmaesOptions& options);

}  // namespace autoshovel::identification
