// CMA-ES benchmarks: `build/cmaes_bench`. One full minimisation to f < 1e-10 per iteration, in
// n = 10 from x0 = 1, σ0 = 1; the counter `evaluations` is the mean number of calls of f (about
// 1.6e3 on the sphere and 6e3 on the ellipsoid), so time per evaluation is time / evaluations.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>

#include "identification/weights/cmaes.h"

namespace {

using autoshovel::identification::CmaesOptions;
using autoshovel::identification::CmaesResult;
using autoshovel::identification::MinimizeCmaes;
using Eigen::VectorXd;

constexpr int kDimension = 10;

double Sphere(const VectorXd& x) { return x.squaredNorm(); }

// Condition 1e6: Σ 10^{6 (i−1)/(n−1)} x_i².
double Ellipsoid(const VectorXd& x) {
  const int n = static_cast<int>(x.size());
  double sum = 0;
  for (int i = 0; i < n; ++i) sum += std::pow(1e6, i / (n - 1.0)) * x(i) * x(i);
  return sum;
}

void Minimise(benchmark::State& state, double (*f)(const VectorXd&)) {
  std::uint64_t seed = 1;
  double evaluations = 0;
  for (auto _ : state) {
    CmaesOptions options;
    options.sigma0 = 1.0;
    options.target_fitness = 1e-10;
    options.seed = seed++;  // a new path each iteration, so the counter is an average
    const CmaesResult result = MinimizeCmaes(f, VectorXd::Ones(kDimension), options);
    benchmark::DoNotOptimize(result.best_fitness);
    evaluations += result.evaluations;
  }
  state.counters["evaluations"] =
      benchmark::Counter(evaluations, benchmark::Counter::kAvgIterations);
}

void BM_CmaesSphere10(benchmark::State& state) { Minimise(state, Sphere); }
void BM_CmaesEllipsoid10(benchmark::State& state) { Minimise(state, Ellipsoid); }

BENCHMARK(BM_CmaesSphere10)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CmaesEllipsoid10)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
