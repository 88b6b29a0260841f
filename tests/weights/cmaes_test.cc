// CMA-ES (identification/weights/cmaes.h): evaluation counts against published figures,
// invariances, bounds, determinism, NaN objectives and bad input.
//
// Reference figures and where they come from (n = 10 unless said otherwise):
//   • Strategy parameters: pycma prints "(5_w,10)-aCMA-ES (mu_w=3.2,w_1=45%) in dimension 10"
//     (cma/evolution_strategy.py doctest), "(3_w,7) mu_w=2.3 w_1=58%" (3-D), "(4_w,8) mu_w=2.6
//     w_1=52%" (4-D), "(4_w,9) mu_w=2.8 w_1=49%" (6-D) (cma/test.py, boundary_handler.py).
//   • Rosenbrock 4-D from 0.5, σ0 = 0.5: 1664 evaluations to the best point, f < 1e-12, in the
//     doctest of Hansen's purecma.py (positive weights, the algorithm implemented here).
//   • Rosenbrock 10-D from 0.1, σ0 = 0.3: pycma's doctest asserts < 8000 evaluations to 1e-12.
//   • Sphere and ellipsoid (condition 1e6) from 1, σ0 = 1, to 1e-10: about 1.5e3 and 6e3–7e3 as
//     quoted from Hansen & Ostermeier 2001 / Hansen 2006; we could not read those papers here.
//     An independent re-statement of purecma's update equations in Python gave 1636 mean
//     evaluations on the sphere (40 seeds), the same as this implementation (≈ 1630).
// Counts are averaged over several seeds; single runs scatter by about ±10 %.
#include "identification/weights/cmaes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace autoshovel::identification {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using Objective = std::function<double(const VectorXd&)>;

constexpr int kDimension = 10;
constexpr double kTarget = 1e-10;
constexpr int kSeeds = 8;
// A correct implementation lands within a few percent of the references; ±25 % still fails
// for a wrong damping, learning rate or weight, which typically costs a factor of 1.5 or more.
constexpr double kCountTolerance = 0.25;

double Sphere(const VectorXd& x) { return x.squaredNorm(); }

// f = Σ 10^{6 (i−1)/(n−1)} x_i²: axis lengths spread over 10³, Hessian condition 10⁶.
double Ellipsoid(const VectorXd& x) {
  constexpr double kCondition = 1e6;
  const int n = static_cast<int>(x.size());
  double sum = 0;
  for (int i = 0; i < n; ++i) sum += std::pow(kCondition, i / (n - 1.0)) * x(i) * x(i);
  return sum;
}

double Rosenbrock(const VectorXd& x) {
  double sum = 0;
  for (Eigen::Index i = 0; i + 1 < x.size(); ++i) {
    sum += 100 * std::pow(x(i) * x(i) - x(i + 1), 2) + std::pow(1 - x(i), 2);
  }
  return sum;
}

struct SeedStatistics {
  double mean_evaluations = 0;  // over the runs that reached the target
  int successes = 0;
};

SeedStatistics RunSeeds(const Objective& f, const VectorXd& x0, double sigma0, double target,
                        int seeds) {
  SeedStatistics statistics;
  double total = 0;
  for (int seed = 1; seed <= seeds; ++seed) {
    CmaesOptions options;
    options.sigma0 = sigma0;
    options.seed = static_cast<std::uint64_t>(seed);
    options.target_fitness = target;
    options.max_evaluations = 50000;
    const CmaesResult result = MinimizeCmaes(f, x0, options);
    if (result.best_fitness <= target) {
      ++statistics.successes;
      total += result.evaluations;
    }
  }
  if (statistics.successes > 0) statistics.mean_evaluations = total / statistics.successes;
  return statistics;
}

// Also records the count (see --gtest_output=json) to compare runs across changes.
void ExpectNear(double measured, double reference, const char* what) {
  ::testing::Test::RecordProperty("mean_evaluations", std::to_string(measured));
  ::testing::Test::RecordProperty("reference_evaluations", std::to_string(reference));
  EXPECT_GT(measured, (1 - kCountTolerance) * reference) << what;
  EXPECT_LT(measured, (1 + kCountTolerance) * reference) << what;
}

// A fixed orthogonal matrix: QR of a matrix with uniform entries from a seeded mt19937_64.
MatrixXd FixedRotation(int n) {
  std::mt19937_64 engine(42);
  MatrixXd random(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      random(i, j) = static_cast<double>(engine() >> 11) * 0x1.0p-53 * 2 - 1;
    }
  }
  return Eigen::HouseholderQR<MatrixXd>(random).householderQ();
}

// ------------------------------------------------------------------------------------------
TEST(CmaesParameters, MatchPycmaPrintedValues) {
  struct Expected {
    int n, lambda, mu;
    double mu_eff;
    int first_weight_percent;
  };
  for (const Expected& e : {Expected{10, 10, 5, 3.2, 45}, Expected{3, 7, 3, 2.3, 58},
                            Expected{4, 8, 4, 2.6, 52}, Expected{6, 9, 4, 2.8, 49}}) {
    const CmaesStrategyParameters p = DefaultCmaesParameters(e.n);
    EXPECT_EQ(p.population, e.lambda) << "n = " << e.n;
    EXPECT_EQ(p.parents, e.mu) << "n = " << e.n;
    EXPECT_NEAR(p.mu_eff, e.mu_eff, 0.05) << "n = " << e.n;  // printed rounded to 0.1
    // pycma prints w_1 truncated to whole percent.
    EXPECT_EQ(static_cast<int>(100 * p.weights(0)), e.first_weight_percent) << "n = " << e.n;
  }
}

TEST(CmaesParameters, SatisfyTheTutorialsConstraints) {
  for (int n : {1, 2, 5, 10, 40, 200}) {
    const CmaesStrategyParameters p = DefaultCmaesParameters(n);
    EXPECT_NEAR(p.weights.sum(), 1.0, 1e-15);
    for (int i = 1; i < p.parents; ++i) EXPECT_LT(p.weights(i), p.weights(i - 1));
    EXPECT_GT(p.weights.minCoeff(), 0);
    EXPECT_GE(p.mu_eff, 1);
    EXPECT_LE(p.mu_eff, p.parents);
    EXPECT_LE(p.c_1 + p.c_mu, 1);  // C stays positive definite
    EXPECT_GT(p.c_sigma, 0);
    EXPECT_LT(p.c_sigma, 1);
    EXPECT_LE(p.c_c, 1);
    EXPECT_GE(p.eigen_interval, 1);
    // E‖N(0, I)‖ = √2 Γ((n+1)/2)/Γ(n/2); the tutorial's series is good to 1e-3 relative.
    const double exact =
        std::sqrt(2.0) * std::exp(std::lgamma((n + 1) / 2.0) - std::lgamma(n / 2.0));
    EXPECT_NEAR(p.expected_norm / exact, 1.0, 1e-3) << "n = " << n;
  }
}

// ------------------------------------------------------------------------------------------
TEST(CmaesConvergence, SphereMatchesPublishedEvaluationCount) {
  constexpr double kReferenceEvaluations = 1600;
  const SeedStatistics s = RunSeeds(Sphere, VectorXd::Ones(kDimension), 1.0, kTarget, kSeeds);
  EXPECT_EQ(s.successes, kSeeds);
  ExpectNear(s.mean_evaluations, kReferenceEvaluations, "sphere n=10 evaluations to 1e-10");
}

TEST(CmaesConvergence, EllipsoidMatchesPublishedEvaluationCount) {
  constexpr double kReferenceEvaluations = 6000;
  const SeedStatistics s = RunSeeds(Ellipsoid, VectorXd::Ones(kDimension), 1.0, kTarget, kSeeds);
  EXPECT_EQ(s.successes, kSeeds);
  ExpectNear(s.mean_evaluations, kReferenceEvaluations, "ellipsoid n=10 evaluations to 1e-10");
}

TEST(CmaesConvergence, RosenbrockReachesTheGlobalMinimum) {
  constexpr double kReferenceEvaluations = 6000;
  constexpr double kPycmaUpperBound = 8000;  // to 1e-12, with active CMA
  const SeedStatistics s =
      RunSeeds(Rosenbrock, VectorXd::Constant(kDimension, 0.1), 0.3, kTarget, kSeeds);
  // The local minimum near x = (−1, 1, …, 1) catches some runs; most must reach x* = 1.
  EXPECT_GE(s.successes, kSeeds - 2);
  ExpectNear(s.mean_evaluations, kReferenceEvaluations, "Rosenbrock n=10 evaluations to 1e-10");
  EXPECT_LT(s.mean_evaluations, kPycmaUpperBound);
}

TEST(CmaesConvergence, Rosenbrock4dMatchesPurecmaDoctest) {
  constexpr double kPurecmaEvaluations = 1664;
  const SeedStatistics s = RunSeeds(Rosenbrock, VectorXd::Constant(4, 0.5), 0.5, 1e-12, kSeeds);
  EXPECT_GE(s.successes, kSeeds - 2);
  ExpectNear(s.mean_evaluations, kPurecmaEvaluations, "Rosenbrock n=4 evaluations to 1e-12");
}

TEST(CmaesConvergence, RotatedEllipsoidCostsTheSame) {
  const MatrixXd rotation = FixedRotation(kDimension);
  const Objective rotated = [&](const VectorXd& x) { return Ellipsoid(rotation * x); };
  // Start at the rotated image of 1 so both runs start from the same f-value.
  const VectorXd x0 = rotation.transpose() * VectorXd::Ones(kDimension);
  const SeedStatistics plain =
      RunSeeds(Ellipsoid, VectorXd::Ones(kDimension), 1.0, kTarget, kSeeds);
  const SeedStatistics turned = RunSeeds(rotated, x0, 1.0, kTarget, kSeeds);
  EXPECT_EQ(turned.successes, kSeeds);
  RecordProperty("mean_evaluations", std::to_string(turned.mean_evaluations));
  RecordProperty("reference_evaluations", std::to_string(plain.mean_evaluations));
  EXPECT_NEAR(turned.mean_evaluations / plain.mean_evaluations, 1.0, 0.25);
}

// With σ0 a hundred times too small, σ must first grow and p_c points along the path for many
// generations. The h_σ stall (tutorial p. 28) keeps that from stretching C: on the sphere, whose
// ideal C is isotropic, the axis ratio stays below 4 (measured ≤ 3.0 over 12 seeds; without the
// stall it reaches 7–9).
TEST(CmaesConvergence, HSigmaStallKeepsTheSphereIsotropicWhileSigmaGrows) {
  constexpr double kMaxAxisRatio = 4;
  for (std::uint64_t seed : {1, 2, 3, 4}) {
    CmaesOptions options;
    options.sigma0 = 1e-2;
    options.seed = seed;
    options.target_fitness = kTarget;
    double largest_axis_ratio = 1;
    options.on_generation = [&](const CmaesProgress& progress) {
      largest_axis_ratio = std::max(largest_axis_ratio, progress.axis_ratio);
    };
    const CmaesResult result = MinimizeCmaes(Sphere, VectorXd::Ones(kDimension), options);
    EXPECT_EQ(result.stop_reason, cmaes_stop::kTargetFitness) << "seed " << seed;
    EXPECT_LT(largest_axis_ratio, kMaxAxisRatio) << "seed " << seed;
  }
}

TEST(CmaesConvergence, DefaultTerminationEndsNearTheOptimum) {
  CmaesOptions options;
  options.sigma0 = 1.0;
  const CmaesResult result = MinimizeCmaes(Sphere, VectorXd::Ones(5), options);
  EXPECT_TRUE(result.stop_reason == cmaes_stop::kTolFun || result.stop_reason == cmaes_stop::kTolX)
      << result.stop_reason;
  EXPECT_LT(result.best_fitness, 1e-11);
}

// ------------------------------------------------------------------------------------------
TEST(CmaesBounds, ActiveUpperBoundIsHitExactlyAndNeverCrossed) {
  constexpr double kUpper = 1.0;
  for (std::uint64_t seed : {1, 2, 3}) {
    CmaesOptions options;
    options.sigma0 = 0.5;
    options.seed = seed;
    options.upper = VectorXd::Constant(kDimension, kUpper);
    double highest_evaluated = -std::numeric_limits<double>::infinity();
    const Objective shifted_sphere = [&](const VectorXd& x) {
      highest_evaluated = std::max(highest_evaluated, x.maxCoeff());
      return (x.array() - 2).square().sum();
    };
    const CmaesResult result = MinimizeCmaes(shifted_sphere, VectorXd::Zero(kDimension), options);
    EXPECT_LE(highest_evaluated, kUpper) << "seed " << seed;
    EXPECT_LT((result.best_x.array() - kUpper).abs().maxCoeff(), 1e-6) << "seed " << seed;
    EXPECT_NEAR(result.best_fitness, kDimension, 1e-5) << "seed " << seed;
  }
}

TEST(CmaesBounds, BoxWithSomeBoundsActiveEndsAtTheProjectedOptimum) {
  VectorXd centre(5);
  centre << -1, 0.3, 0.5, 2, 0.9;  // outside, inside, inside, outside, inside [0, 1]
  CmaesOptions options;
  options.sigma0 = 0.3;
  options.lower = VectorXd::Zero(5);
  options.upper = VectorXd::Ones(5);
  bool all_inside = true;
  const Objective f = [&](const VectorXd& x) {
    all_inside = all_inside && x.minCoeff() >= 0 && x.maxCoeff() <= 1;
    return (x - centre).squaredNorm();
  };
  const CmaesResult result = MinimizeCmaes(f, VectorXd::Constant(5, 0.5), options);
  EXPECT_TRUE(all_inside);
  const VectorXd expected = centre.cwiseMax(0.0).cwiseMin(1.0);
  EXPECT_LT((result.best_x - expected).cwiseAbs().maxCoeff(), 1e-6);
}

// The penalty weight follows the spread of f, so scaling f by a power of two (exact in floating
// point) must leave the whole bounded run bit-identical: no hidden absolute scale of f.
TEST(CmaesBounds, PenaltyIsInvariantToScalingTheObjective) {
  constexpr double kScale = 0x1.0p40;
  CmaesOptions options;
  options.sigma0 = 0.5;
  options.tol_fun = 0;  // absolute in f, so it would break the invariance
  options.upper = VectorXd::Constant(5, 1.0);
  const Objective f = [](const VectorXd& x) { return (x.array() - 2).square().sum(); };
  const Objective scaled = [&](const VectorXd& x) { return kScale * f(x); };
  const CmaesResult a = MinimizeCmaes(f, VectorXd::Zero(5), options);
  const CmaesResult b = MinimizeCmaes(scaled, VectorXd::Zero(5), options);
  EXPECT_EQ(a.evaluations, b.evaluations);
  EXPECT_EQ(a.stop_reason, b.stop_reason);
  EXPECT_TRUE(a.best_x == b.best_x);
  EXPECT_EQ(kScale * a.best_fitness, b.best_fitness);
}

// ------------------------------------------------------------------------------------------
struct Trace {
  std::vector<double> sigmas;
  std::vector<VectorXd> means;
};

CmaesResult RunTraced(std::uint64_t seed, Trace& trace) {
  CmaesOptions options;
  options.sigma0 = 0.5;
  options.seed = seed;
  options.max_evaluations = 2000;
  options.on_generation = [&](const CmaesProgress& progress) {
    trace.sigmas.push_back(progress.sigma);
    trace.means.push_back(progress.mean);
  };
  return MinimizeCmaes(Rosenbrock, VectorXd::Zero(5), options);
}

TEST(CmaesDeterminism, SameSeedGivesBitIdenticalRuns) {
  Trace first, second;
  const CmaesResult a = RunTraced(7, first);
  const CmaesResult b = RunTraced(7, second);
  EXPECT_EQ(a.evaluations, b.evaluations);
  EXPECT_EQ(a.generations, b.generations);
  EXPECT_EQ(a.best_fitness, b.best_fitness);
  EXPECT_TRUE(a.best_x == b.best_x);
  EXPECT_EQ(first.sigmas, second.sigmas);
  ASSERT_EQ(first.means.size(), second.means.size());
  for (std::size_t g = 0; g < first.means.size(); ++g) {
    EXPECT_TRUE(first.means[g] == second.means[g]) << "generation " << g;
  }
}

TEST(CmaesDeterminism, DifferentSeedsTakeDifferentPaths) {
  Trace first, second;
  const CmaesResult a = RunTraced(7, first);
  const CmaesResult b = RunTraced(8, second);
  EXPECT_FALSE(first.means.front() == second.means.front());
  EXPECT_NE(first.sigmas.front(), second.sigmas.front());
  EXPECT_FALSE(a.best_x == b.best_x);
}

TEST(CmaesProgressReport, CountsGenerationsAndEvaluations) {
  std::vector<CmaesProgress> reports;
  CmaesOptions options;
  options.max_evaluations = 200;
  options.on_generation = [&](const CmaesProgress& p) { reports.push_back(p); };
  const CmaesResult result = MinimizeCmaes(Sphere, VectorXd::Ones(kDimension), options);
  const int lambda = DefaultCmaesParameters(kDimension).population;
  ASSERT_EQ(static_cast<int>(reports.size()), result.generations);
  EXPECT_EQ(result.stop_reason, cmaes_stop::kMaxEvaluations);
  EXPECT_LE(result.evaluations, options.max_evaluations);
  for (std::size_t g = 0; g < reports.size(); ++g) {
    EXPECT_EQ(reports[g].generation, static_cast<int>(g) + 1);
    EXPECT_EQ(reports[g].evaluations, static_cast<int>(g + 1) * lambda);
    EXPECT_GE(reports[g].generation_best_fitness, reports[g].best_fitness);
    EXPECT_GE(reports[g].axis_ratio, 1.0);
  }
}

// ------------------------------------------------------------------------------------------
TEST(CmaesNan, NanOnHalfTheDomainStillConverges) {
  for (std::uint64_t seed : {1, 2, 3}) {
    int nan_evaluations = 0;
    // Undefined for x_0 < 0, right next to the optimum at 0: about a tenth of all samples.
    const Objective half_defined = [&](const VectorXd& x) {
      if (x(0) < 0) {
        ++nan_evaluations;
        return std::numeric_limits<double>::quiet_NaN();
      }
      return x.squaredNorm();
    };
    CmaesOptions options;
    options.sigma0 = 1.0;
    options.seed = seed;
    options.target_fitness = kTarget;
    const CmaesResult result = MinimizeCmaes(half_defined, VectorXd::Ones(kDimension), options);
    EXPECT_EQ(result.stop_reason, cmaes_stop::kTargetFitness) << "seed " << seed;
    EXPECT_TRUE(result.best_x.allFinite());
    EXPECT_LE(result.best_fitness, kTarget);
    EXPECT_GE(result.best_x(0), 0);
    EXPECT_GT(nan_evaluations, result.evaluations / 20) << "the NaN region was not exercised";
  }
}

TEST(CmaesNan, AlwaysNanObjectiveEndsWithInfiniteFitnessAndFiniteState) {
  int calls = 0;
  const Objective undefined = [&](const VectorXd&) {
    ++calls;
    return std::numeric_limits<double>::quiet_NaN();
  };
  CmaesOptions options;
  options.max_evaluations = 600;
  const CmaesResult result = MinimizeCmaes(undefined, VectorXd::Ones(3), options);
  EXPECT_EQ(result.evaluations, calls);
  EXPECT_LE(result.evaluations, options.max_evaluations);
  EXPECT_EQ(result.best_fitness, std::numeric_limits<double>::infinity());
  EXPECT_TRUE(result.best_x.allFinite());
}

// ------------------------------------------------------------------------------------------
void ExpectInvalid(const VectorXd& x0, const CmaesOptions& options, const std::string& message) {
  try {
    MinimizeCmaes(Sphere, x0, options);
    ADD_FAILURE() << "no exception; expected one naming: " << message;
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find(message), std::string::npos)
        << "message \"" << error.what() << "\" does not name \"" << message << "\"";
  }
}

TEST(CmaesBadInput, IsRejectedWithAMessageNamingTheProblem) {
  const CmaesOptions defaults;
  ExpectInvalid(VectorXd(), defaults, "x0 is empty");

  VectorXd with_nan = VectorXd::Zero(3);
  with_nan(1) = std::numeric_limits<double>::quiet_NaN();
  ExpectInvalid(with_nan, defaults, "x0[1] is not finite");
  VectorXd with_inf = VectorXd::Zero(3);
  with_inf(2) = std::numeric_limits<double>::infinity();
  ExpectInvalid(with_inf, defaults, "x0[2] is not finite");

  for (double sigma0 : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN()}) {
    CmaesOptions options;
    options.sigma0 = sigma0;
    ExpectInvalid(VectorXd::Zero(3), options, "sigma0");
  }

  CmaesOptions wrong_size;
  wrong_size.lower = VectorXd::Zero(2);
  ExpectInvalid(VectorXd::Zero(3), wrong_size, "lower has size 2 but x0 has size 3");
  wrong_size.lower = VectorXd();
  wrong_size.upper = VectorXd::Zero(4);
  ExpectInvalid(VectorXd::Zero(3), wrong_size, "upper has size 4 but x0 has size 3");

  CmaesOptions crossed;
  crossed.lower = VectorXd::Constant(3, 2.0);
  crossed.upper = VectorXd::Constant(3, 1.0);
  ExpectInvalid(VectorXd::Constant(3, 1.5), crossed, "lower[0] = 2 > upper[0] = 1");

  CmaesOptions nan_bound;
  nan_bound.upper = VectorXd::Constant(3, std::numeric_limits<double>::quiet_NaN());
  ExpectInvalid(VectorXd::Zero(3), nan_bound, "upper[0] is NaN");

  CmaesOptions box;
  box.lower = VectorXd::Zero(3);
  box.upper = VectorXd::Ones(3);
  VectorXd outside = VectorXd::Constant(3, 0.5);
  outside(1) = 1.5;
  ExpectInvalid(outside, box, "x0[1] = 1.5 is outside the bounds [0, 1]");

  CmaesOptions one_parent;
  one_parent.population = 1;
  ExpectInvalid(VectorXd::Zero(3), one_parent, "population");

  CmaesOptions no_budget;
  no_budget.max_evaluations = 0;
  ExpectInvalid(VectorXd::Zero(3), no_budget, "max_evaluations");
  no_budget.max_evaluations = 3;  // below λ = 7 in 3-D
  ExpectInvalid(VectorXd::Zero(3), no_budget, "max_evaluations (3) is below one generation");
}

}  // namespace
}  // namespace autoshovel::identification
