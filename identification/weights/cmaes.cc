// CMA-ES after Hansen's tutorial (arXiv:1604.00772); equation numbers below are the tutorial's.
#include "identification/weights/cmaes.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <numbers>
#include <random>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace autoshovel::identification {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Tutorial Appendix B termination constants.
constexpr double kMaxConditionNumber = 1e14;         // ConditionCov
constexpr double kMaxStepGrowth = 1e4;               // TolXUp: σ·max(D) relative to σ0
constexpr double kNoEffectStandardDeviations = 0.2;  // NoEffectCoord
constexpr int kTolFunBaseGenerations = 10;           // TolFun window: 10 + ⌈30 n / λ⌉
constexpr double kTolFunGenerationsPerDimension = 30;

// h_σ threshold (tutorial p. 28, under eq. 45): ‖p_σ‖/√(1 − (1 − c_σ)^{2(g+1)}) must stay below
// (1.4 + 2/(n + 1))·E‖N(0, I)‖ for p_c to be updated.
constexpr double kHSigmaBase = 1.4;

// ---------------------------------------------------------------------------------------------
// Normal deviates: std::mt19937_64 is specified bit for bit; the Box–Muller transform is written
// out because std::normal_distribution's algorithm differs between standard libraries. (std::log,
// std::cos and std::sin may still differ in the last ulp between C libraries.)
class NormalSampler {
 public:
  explicit NormalSampler(std::uint64_t seed) : engine_(seed) {}

  double Next() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double radius = std::sqrt(-2.0 * std::log(UniformOpenAtZero()));
    const double angle = 2.0 * std::numbers::pi * UniformOpenAtZero();
    spare_ = radius * std::sin(angle);
    has_spare_ = true;
    return radius * std::cos(angle);
  }

 private:
  // Uniform on (0, 1] with 53 random bits, so that log() never sees 0.
  double UniformOpenAtZero() {
    constexpr int kDiscardedBits = 64 - 53;
    constexpr double kUlp = 0x1.0p-53;
    return (static_cast<double>(engine_() >> kDiscardedBits) + 1.0) * kUlp;
  }

  std::mt19937_64 engine_;
  double spare_ = 0;
  bool has_spare_ = false;
};

// ---------------------------------------------------------------------------------------------
// Box bounds: repair by projection plus an adaptive quadratic penalty, the method of Hansen,
// Niederberger, Guzzella & Koumoutsakos, "A method for handling uncertainty in evolutionary
// optimization with an application to feedback control of combustion", IEEE TEC 13(1), 2009,
// Sec. IV-B (also pycma's BoundPenalty). f is only ever evaluated at the projected (feasible)
// point; the ranking uses f(projected) + Σ γ_i (x_i − projected_i)²/(n ξ_i), and the CMA update
// uses the unprojected sample, so the sampling distribution stays exactly Gaussian.
//
// Why not resampling: the weights we tune often sit on a bound, and with k coordinates at their
// bounds only ~2^-k of the samples around the optimum are feasible. Why not plain projection: f is
// flat outward from a bound, so the mean would drift away unboundedly. Why an adaptive γ: a fixed
// penalty weight only works for one scale of f; γ is set from the observed spread of f-values per
// unit variance, so the method keeps CMA-ES's invariance to scaling f.
class BoxPenalty {
 public:
  BoxPenalty(const Eigen::VectorXd& lower, const Eigen::VectorXd& upper, int dimension,
             const CmaesStrategyParameters& parameters)
      : lower_(lower.size() == 0 ? Eigen::VectorXd::Constant(dimension, -kInfinity) : lower),
        upper_(upper.size() == 0 ? Eigen::VectorXd::Constant(dimension, kInfinity) : upper),
        weights_(Eigen::VectorXd::Zero(dimension)),
        variance_scale_(Eigen::ArrayXd::Ones(dimension)),
        mu_eff_(parameters.mu_eff),
        history_length_(
            static_cast<std::size_t>(kHistoryBase + 3.0 * dimension / parameters.population)) {
    active_ = (lower_.array() > -kInfinity).any() || (upper_.array() < kInfinity).any();
  }

  bool active() const { return active_; }

  Eigen::VectorXd Project(const Eigen::VectorXd& x) const {
    return x.cwiseMax(lower_).cwiseMin(upper_);
  }

  // (1/n) Σ γ_i (x_i − x_feasible,i)² / ξ_i; zero until the weights are initialised.
  double Penalty(const Eigen::VectorXd& x, const Eigen::VectorXd& x_feasible) const {
    if (!weights_initialized_) return 0.0;
    const Eigen::ArrayXd violation = (x - x_feasible).array();
    return (weights_.array() * violation.square() / variance_scale_).sum() / x.size();
  }

  // Once per generation with the raw f-values and the updated distribution.
  void Update(const std::vector<double>& fitness, const Eigen::VectorXd& mean, double sigma,
              const Eigen::MatrixXd& covariance) {
    if (!active_) return;
    const int n = static_cast<int>(mean.size());
    const Eigen::ArrayXd diagonal = covariance.diagonal().array();

    // ξ_i = exp(0.9 (ln C_ii − mean_j ln C_jj)): the penalty follows the coordinate's variance.
    const double mean_log = diagonal.log().mean();
    variance_scale_ = (kVarianceScaleExponent * (diagonal.log() - mean_log)).exp();

    // Interquartile range of f per unit variance, the scale of f seen by the ranking. Normalised
    // by the variance of the same generation (as pycma does) so that the history stays
    // comparable while σ shrinks; non-finite or zero ranges carry no scale and are skipped.
    std::vector<double> sorted = fitness;
    std::sort(sorted.begin(), sorted.end());
    const std::size_t quarter = (sorted.size() + 1) / 4;
    const std::size_t three_quarters = std::min(sorted.size() - 1, 3 * (sorted.size() + 1) / 4);
    const double spread =
        (sorted[three_quarters] - sorted[quarter]) / (sigma * sigma * diagonal.mean());
    if (std::isfinite(spread) && spread > 0) {
      spread_history_.push_front(spread);
      if (spread_history_.size() > history_length_) spread_history_.pop_back();
    }

    const Eigen::VectorXd mean_feasible = Project(mean);
    const bool mean_outside = (mean_feasible - mean).cwiseAbs().maxCoeff() > 0;
    if (mean_outside && !weights_initialized_ && !spread_history_.empty()) {
      // γ_i = 2 δ_fit: a one-standard-deviation violation costs about twice the median IQR / n.
      weights_.setConstant(kInitialWeightFactor * MedianSpread());
      weights_initialized_ = true;
    }
    if (!weights_initialized_) return;

    // Raise γ_i while m_i stays more than max(1, √n/μ_eff) standard deviations outside, by
    // 1.1^min(1, μ_eff/(10 n)) (the TEC paper prints max; its addendum and pycma use min).
    const double tolerated_deviations = std::max(1.0, std::sqrt(n) / mu_eff_);
    const double growth = std::pow(kWeightGrowthBase, std::min(1.0, mu_eff_ / (10.0 * n)));
    for (int i = 0; i < n; ++i) {
      const double standard_deviation = sigma * std::sqrt(covariance(i, i));
      if (std::abs(mean(i) - mean_feasible(i)) > tolerated_deviations * standard_deviation) {
        weights_(i) *= growth;
      }
    }
  }

 private:
  static constexpr double kHistoryBase = 20;  // δ_fit is the median over 20 + 3n/λ generations
  static constexpr double kVarianceScaleExponent = 0.9;
  static constexpr double kInitialWeightFactor = 2;
  static constexpr double kWeightGrowthBase = 1.1;

  double MedianSpread() const {
    std::vector<double> values(spread_history_.begin(), spread_history_.end());
    const std::size_t middle = values.size() / 2;
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(middle),
                     values.end());
    double median = values[middle];
    if (values.size() % 2 == 0) {
      median =
          0.5 * (median + *std::max_element(values.begin(),
                                            values.begin() + static_cast<std::ptrdiff_t>(middle)));
    }
    return median;
  }

  Eigen::VectorXd lower_, upper_;
  Eigen::VectorXd weights_;        // γ_i
  Eigen::ArrayXd variance_scale_;  // ξ_i
  double mu_eff_;
  std::size_t history_length_;
  std::deque<double> spread_history_;
  bool active_ = false;
  bool weights_initialized_ = false;
};

// ---------------------------------------------------------------------------------------------
std::string Describe(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

void ValidateBound(const Eigen::VectorXd& bound, const char* name, Eigen::Index dimension) {
  if (bound.size() != 0 && bound.size() != dimension) {
    throw std::invalid_argument("MinimizeCmaes: " + std::string(name) + " has size " +
                                std::to_string(bound.size()) + " but x0 has size " +
                                std::to_string(dimension) + " (use an empty vector for none)");
  }
  for (Eigen::Index i = 0; i < bound.size(); ++i) {
    if (std::isnan(bound(i))) {
      throw std::invalid_argument("MinimizeCmaes: " + std::string(name) + "[" + std::to_string(i) +
                                  "] is NaN");
    }
  }
}

void ValidateInput(const Eigen::VectorXd& x0, const CmaesOptions& options) {
  if (x0.size() == 0) throw std::invalid_argument("MinimizeCmaes: x0 is empty");
  for (Eigen::Index i = 0; i < x0.size(); ++i) {
    if (!std::isfinite(x0(i))) {
      throw std::invalid_argument("MinimizeCmaes: x0[" + std::to_string(i) + "] is not finite (" +
                                  Describe(x0(i)) + ")");
    }
  }
  if (!(options.sigma0 > 0) || !std::isfinite(options.sigma0)) {
    throw std::invalid_argument("MinimizeCmaes: sigma0 must be positive and finite, got " +
                                Describe(options.sigma0));
  }
  if (options.max_evaluations <= 0) {
    throw std::invalid_argument("MinimizeCmaes: max_evaluations must be positive, got " +
                                std::to_string(options.max_evaluations));
  }
  ValidateBound(options.lower, "lower", x0.size());
  ValidateBound(options.upper, "upper", x0.size());
  for (Eigen::Index i = 0; i < x0.size(); ++i) {
    const double lower = options.lower.size() ? options.lower(i) : -kInfinity;
    const double upper = options.upper.size() ? options.upper(i) : kInfinity;
    if (lower > upper) {
      throw std::invalid_argument("MinimizeCmaes: lower[" + std::to_string(i) +
                                  "] = " + Describe(lower) + " > upper[" + std::to_string(i) +
                                  "] = " + Describe(upper));
    }
    if (x0(i) < lower || x0(i) > upper) {
      throw std::invalid_argument("MinimizeCmaes: x0[" + std::to_string(i) +
                                  "] = " + Describe(x0(i)) + " is outside the bounds [" +
                                  Describe(lower) + ", " + Describe(upper) + "]");
    }
  }
}

// ---------------------------------------------------------------------------------------------
// The search distribution N(m, σ² C) with C = B D² Bᵀ, and the two evolution paths.
struct Distribution {
  Eigen::VectorXd mean;
  double sigma = 0;
  Eigen::MatrixXd covariance;               // C
  Eigen::MatrixXd basis;                    // B, eigenvectors of C
  Eigen::VectorXd axis_lengths;             // D, square roots of C's eigenvalues
  Eigen::MatrixXd inverse_sqrt_covariance;  // C^{-1/2} = B D^{-1} Bᵀ
  Eigen::VectorXd path_sigma;               // p_σ
  Eigen::VectorXd path_covariance;          // p_c

  // Refreshes B, D and C^{-1/2} from C; false when C is no longer numerically positive definite.
  bool Decompose() {
    covariance = 0.5 * (covariance + covariance.transpose());  // drop rounding asymmetry
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(covariance);
    if (solver.info() != Eigen::Success || !(solver.eigenvalues().minCoeff() > 0)) return false;
    basis = solver.eigenvectors();
    axis_lengths = solver.eigenvalues().cwiseSqrt();
    inverse_sqrt_covariance = basis * axis_lengths.cwiseInverse().asDiagonal() * basis.transpose();
    return true;
  }

  double ConditionNumber() const {
    const double ratio = axis_lengths.maxCoeff() / axis_lengths.minCoeff();
    return ratio * ratio;
  }
};

}  // namespace

CmaesStrategyParameters DefaultCmaesParameters(int dimension, int population) {
  if (dimension < 1) {
    throw std::invalid_argument("DefaultCmaesParameters: dimension must be at least 1, got " +
                                std::to_string(dimension));
  }
  if (population < 0 || population == 1) {
    throw std::invalid_argument("CMA-ES population must be 0 (default) or at least 2, got " +
                                std::to_string(population));
  }
  CmaesStrategyParameters p;
  const double n = dimension;
  p.dimension = dimension;
  // λ = 4 + ⌊3 ln n⌋ (48), μ = ⌊λ/2⌋.
  p.population = population > 0 ? population : 4 + static_cast<int>(std::floor(3 * std::log(n)));
  p.parents = p.population / 2;
  // w'_i = ln((λ + 1)/2) − ln i (49), positive for i ≤ μ, normalised to sum to one (53).
  p.weights.resize(p.parents);
  for (int i = 0; i < p.parents; ++i) {
    p.weights(i) = std::log((p.population + 1) / 2.0) - std::log(i + 1.0);
  }
  p.weights /= p.weights.sum();
  p.mu_eff = 1.0 / p.weights.squaredNorm();
  const double mu_eff = p.mu_eff;
  // c_σ and d_σ (55).
  p.c_sigma = (mu_eff + 2) / (n + mu_eff + 5);
  p.d_sigma = 1 + 2 * std::max(0.0, std::sqrt((mu_eff - 1) / (n + 1)) - 1) + p.c_sigma;
  // c_c (56).
  p.c_c = (4 + mu_eff / n) / (n + 4 + 2 * mu_eff / n);
  // c_1 (57) and c_μ (58) with α_cov = 2.
  constexpr double kAlphaCov = 2;
  p.c_1 = kAlphaCov / ((n + 1.3) * (n + 1.3) + mu_eff);
  p.c_mu = std::min(1 - p.c_1, kAlphaCov * (mu_eff - 2 + 1 / mu_eff) /
                                   ((n + 2) * (n + 2) + kAlphaCov * mu_eff / 2));
  // E‖N(0, I)‖ = √2 Γ((n+1)/2)/Γ(n/2) ≈ √n (1 − 1/(4n) + 1/(21n²)) (p. 28).
  p.expected_norm = std::sqrt(n) * (1 - 1 / (4 * n) + 1 / (21 * n * n));
  // The O(n³) eigendecomposition is needed only every 1/((c_1 + c_μ) n 10) generations
  // (tutorial, Appendix B): C changes little in between, and the cost stays O(n²) per sample.
  p.eigen_interval = std::max(1, static_cast<int>(std::floor(1 / ((p.c_1 + p.c_mu) * n * 10))));
  return p;
}

CmaesResult MinimizeCmaes(const std::function<double(const Eigen::VectorXd&)>& f,
                          const Eigen::VectorXd& x0, const CmaesOptions& options) {
  ValidateInput(x0, options);
  const int n = static_cast<int>(x0.size());
  const CmaesStrategyParameters p = DefaultCmaesParameters(n, options.population);
  const int lambda = p.population;
  const int mu = p.parents;
  if (options.max_evaluations < lambda) {
    throw std::invalid_argument("MinimizeCmaes: max_evaluations (" +
                                std::to_string(options.max_evaluations) +
                                ") is below one generation, λ = " + std::to_string(lambda));
  }

  BoxPenalty box(options.lower, options.upper, n, p);
  NormalSampler normal(options.seed);

  Distribution d;
  d.mean = x0;
  d.sigma = options.sigma0;
  d.covariance = Eigen::MatrixXd::Identity(n, n);
  d.basis = Eigen::MatrixXd::Identity(n, n);
  d.axis_lengths = Eigen::VectorXd::Ones(n);
  d.inverse_sqrt_covariance = Eigen::MatrixXd::Identity(n, n);
  d.path_sigma = Eigen::VectorXd::Zero(n);
  d.path_covariance = Eigen::VectorXd::Zero(n);

  CmaesResult result;
  result.best_x = box.Project(x0);
  const std::size_t tol_fun_window = static_cast<std::size_t>(
      kTolFunBaseGenerations + std::ceil(kTolFunGenerationsPerDimension * n / lambda));
  std::deque<double> best_fitness_history;  // per generation, newest first

  Eigen::MatrixXd steps(n, lambda);  // y_k, one column per candidate
  std::vector<double> fitness(lambda), ranking_fitness(lambda);
  std::vector<int> order(lambda);
  const double hsigma_threshold = (kHSigmaBase + 2.0 / (n + 1)) * p.expected_norm;

  for (int generation = 0;; ++generation) {
    // Sample: z_k ~ N(0, I) (38), y_k = B D z_k ~ N(0, C) (39), x_k = m + σ y_k (40).
    double generation_best = kInfinity;
    for (int k = 0; k < lambda; ++k) {
      Eigen::VectorXd z(n);
      for (int i = 0; i < n; ++i) z(i) = normal.Next();
      steps.col(k) = d.basis * d.axis_lengths.cwiseProduct(z);
      const Eigen::VectorXd x = d.mean + d.sigma * steps.col(k);
      const Eigen::VectorXd x_feasible = box.Project(x);
      double value = f(x_feasible);
      ++result.evaluations;
      // NaN ranks last; only the steps y_k, never f-values, enter the updates below.
      if (std::isnan(value)) value = kInfinity;
      fitness[k] = value;
      double ranked = value + box.Penalty(x, x_feasible);
      if (std::isnan(ranked)) ranked = kInfinity;  // −inf + inf penalty
      ranking_fitness[k] = ranked;
      generation_best = std::min(generation_best, value);
      if (value < result.best_fitness || (generation == 0 && k == 0)) {
        result.best_fitness = value;
        result.best_x = x_feasible;
      }
    }

    // Select: rank by (penalised) fitness; the stable sort keeps ties deterministic.
    for (int k = 0; k < lambda; ++k) order[k] = k;
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return ranking_fitness[a] < ranking_fitness[b]; });
    Eigen::MatrixXd selected(n, mu);
    for (int i = 0; i < mu; ++i) selected.col(i) = steps.col(order[i]);

    // Recombine: ⟨y⟩_w = Σ w_i y_{i:λ} (41), m ← m + c_m σ ⟨y⟩_w with c_m = 1 (42, 54).
    const Eigen::VectorXd weighted_step = selected * p.weights;
    d.mean += d.sigma * weighted_step;

    // Step-size path: p_σ ← (1 − c_σ) p_σ + √(c_σ (2 − c_σ) μ_eff) C^{-1/2} ⟨y⟩_w (43).
    d.path_sigma =
        (1 - p.c_sigma) * d.path_sigma + std::sqrt(p.c_sigma * (2 - p.c_sigma) * p.mu_eff) *
                                             (d.inverse_sqrt_covariance * weighted_step);
    const double path_sigma_norm = d.path_sigma.norm();

    // h_σ stalls the p_c update while ‖p_σ‖ is large, i.e. while σ is rising fast, so that C does
    // not grow too quickly along a linear slope (p. 28).
    const double path_bias_correction =
        std::sqrt(1 - std::pow(1 - p.c_sigma, 2.0 * (generation + 1)));
    const bool h_sigma = path_sigma_norm / path_bias_correction < hsigma_threshold;

    // Covariance path: p_c ← (1 − c_c) p_c + h_σ √(c_c (2 − c_c) μ_eff) ⟨y⟩_w (45).
    d.path_covariance = (1 - p.c_c) * d.path_covariance;
    if (h_sigma) {
      d.path_covariance += std::sqrt(p.c_c * (2 - p.c_c) * p.mu_eff) * weighted_step;
    }

    // C ← (1 + c_1 δ(h_σ) − c_1 − c_μ Σw_j) C + c_1 p_c p_cᵀ + c_μ Σ w_i y_{i:λ} y_{i:λ}ᵀ (47),
    // with Σw_j = 1 (positive weights only, so w°_i = w_i in (46)) and
    // δ(h_σ) = (1 − h_σ) c_c (2 − c_c), which makes up for the variance lost when p_c stalled.
    const double stall_compensation = h_sigma ? 0.0 : p.c_c * (2 - p.c_c);
    d.covariance *= 1 + p.c_1 * stall_compensation - p.c_1 - p.c_mu;
    d.covariance.noalias() += p.c_1 * d.path_covariance * d.path_covariance.transpose();
    d.covariance.noalias() += p.c_mu * selected * p.weights.asDiagonal() * selected.transpose();

    // σ ← σ exp((c_σ/d_σ)(‖p_σ‖/E‖N(0, I)‖ − 1)) (44).
    d.sigma *= std::exp(p.c_sigma / p.d_sigma * (path_sigma_norm / p.expected_norm - 1));

    box.Update(fitness, d.mean, d.sigma, d.covariance);
    result.generations = generation + 1;

    // Lazy eigendecomposition (tutorial, Appendix B).
    const bool decomposed = result.generations % p.eigen_interval != 0 || d.Decompose();

    if (options.on_generation) {
      CmaesProgress progress;
      progress.generation = result.generations;
      progress.evaluations = result.evaluations;
      progress.sigma = d.sigma;
      progress.best_fitness = result.best_fitness;
      progress.generation_best_fitness = generation_best;
      progress.axis_ratio = d.axis_lengths.maxCoeff() / d.axis_lengths.minCoeff();
      progress.mean = d.mean;
      options.on_generation(progress);
    }

    // Termination (Appendix B), cheapest and most informative reasons first.
    best_fitness_history.push_front(generation_best);
    if (best_fitness_history.size() > tol_fun_window) best_fitness_history.pop_back();
    if (generation_best <= options.target_fitness) {
      result.stop_reason = cmaes_stop::kTargetFitness;
      break;
    }
    if (result.evaluations + lambda > options.max_evaluations) {
      result.stop_reason = cmaes_stop::kMaxEvaluations;
      break;
    }
    if (!decomposed || d.ConditionNumber() > kMaxConditionNumber) {
      result.stop_reason = cmaes_stop::kConditionCov;
      break;
    }
    if (best_fitness_history.size() == tol_fun_window) {
      // TolFun: range of recent generation bests and of this generation's values.
      const auto [history_min, history_max] =
          std::minmax_element(best_fitness_history.begin(), best_fitness_history.end());
      const auto [current_min, current_max] = std::minmax_element(fitness.begin(), fitness.end());
      const double range =
          std::max(*history_max, *current_max) - std::min(*history_min, *current_min);
      if (range < options.tol_fun) {  // false for a non-finite range
        result.stop_reason = cmaes_stop::kTolFun;
        break;
      }
    }
    const Eigen::VectorXd coordinate_deviations = d.sigma * d.covariance.diagonal().cwiseSqrt();
    if (coordinate_deviations.maxCoeff() < options.tol_x &&
        (d.sigma * d.path_covariance).cwiseAbs().maxCoeff() < options.tol_x) {
      result.stop_reason = cmaes_stop::kTolX;
      break;
    }
    // TolXUp: σ·max(D) grew by 10⁴: σ0 far too small, or f unbounded below (divergence).
    if (!(d.sigma * d.axis_lengths.maxCoeff() <= kMaxStepGrowth * options.sigma0)) {
      result.stop_reason = cmaes_stop::kTolXUp;
      break;
    }
    // NoEffectCoord: a 0.2-standard-deviation step no longer changes some m_i.
    for (int i = 0; i < n; ++i) {
      if (d.mean(i) == d.mean(i) + kNoEffectStandardDeviations * coordinate_deviations(i)) {
        result.stop_reason = cmaes_stop::kNoEffectCoordinate;
        break;
      }
    }
    if (!result.stop_reason.empty()) break;
  }
  return result;
}

}  // namespace autoshovel::identification
