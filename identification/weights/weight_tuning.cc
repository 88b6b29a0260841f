#include "identification/weights/weight_tuning.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "identification/weights/cmaes.h"
#include "runtime/perception/pile_extraction.h"

namespace autoshovel::identification {
namespace {

constexpr double kLogRatioBound = 6.0;  // |ln(k_i / k_a)| ≤ 6

ShovelWeights FromLogRatios(const Eigen::VectorXd& z) {
  ShovelWeights w{};
  double sum = 1.0;  // k_a's own e^0
  for (int i = 0; i < 4; ++i) sum += std::exp(z[i]);
  for (int i = 0; i < 4; ++i) w[i] = std::exp(z[i]) / sum;
  w[4] = 1.0 / sum;
  return w;
}

}  // namespace

ShovelWeights WeightsOf(const planning::ShovelPointConfig& config) {
  return {config.k_t, config.k_s, config.k_c, config.k_e, config.k_a};
}

ScoredDemonstration ScoreDemonstration(const Demonstration& demonstration,
                                       const planning::LoaderGeometry& loader,
                                       const planning::ShovelPointConfig& config) {
  ScoredDemonstration scored;
  scored.id = demonstration.id;
  scored.nearest = std::numeric_limits<double>::infinity();
  perception::GridMap map = demonstration.map;  // ExtractPiles may add layers
  const std::vector<perception::ExtractedPile> piles =
      perception::ExtractPiles(map, demonstration.ground_plane);
  const planning::ShovelPointResult result = planning::SelectShovelPoints(
      map, piles, demonstration.ground_plane, demonstration.start, loader, config);
  std::vector<const planning::ShovelCandidate*> feasible;
  for (const planning::ShovelCandidate& c : result.ranked) {
    if (c.feasible) feasible.push_back(&c);
  }
  // Candidate order, so that ties do not depend on the weights the ranking was made with.
  std::stable_sort(feasible.begin(), feasible.end(), [](const auto* a, const auto* b) {
    if (a->pose.pile != b->pose.pile) return a->pose.pile < b->pose.pile;
    if (a->pose.point != b->pose.point) return a->pose.point < b->pose.point;
    return a->pose.entry_offset < b->pose.entry_offset;
  });
  for (const planning::ShovelCandidate* c : feasible) {
    const planning::ScoreBreakdown& s = c->scores;
    scored.scores.push_back({s.s_t, s.s_s, s.s_c, s.s_e, s.s_a});
    const double d = (c->pose.xy - demonstration.expert_xy).norm();
    scored.distance_to_expert.push_back(d);
    scored.nearest = std::min(scored.nearest, d);
  }
  return scored;
}

double SelectedDistance(const ScoredDemonstration& scored, const ShovelWeights& weights) {
  double best = -std::numeric_limits<double>::infinity();
  double distance = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < scored.scores.size(); ++i) {
    double f = 0;  // Eq. (18)
    for (int k = 0; k < 5; ++k) f += weights[k] * scored.scores[i][k];
    if (f > best) best = f, distance = scored.distance_to_expert[i];
  }
  return distance;
}

double ExpectedDistance(const ScoredDemonstration& scored, const ShovelWeights& weights,
                        double temperature) {
  if (scored.scores.empty()) return std::numeric_limits<double>::infinity();
  std::vector<double> f(scored.scores.size());
  double top = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < f.size(); ++i) {
    f[i] = 0;
    for (int k = 0; k < 5; ++k) f[i] += weights[k] * scored.scores[i][k];
    top = std::max(top, f[i]);
  }
  double mass = 0, sum = 0;  // shifted by the top score: no overflow
  for (std::size_t i = 0; i < f.size(); ++i) {
    const double p = std::exp((f[i] - top) / temperature);
    mass += p;
    sum += p * scored.distance_to_expert[i];
  }
  return sum / mass;
}

Agreement MeasureAgreement(const std::vector<ScoredDemonstration>& set,
                           const ShovelWeights& weights) {
  Agreement a;
  a.demonstrations = static_cast<int>(set.size());
  std::vector<double> distances;
  int within_1m = 0, within_2m = 0, reachable = 0;
  for (const ScoredDemonstration& s : set) {
    const double d = SelectedDistance(s, weights);
    if (!std::isfinite(d)) {
      ++a.without_candidates;
      continue;
    }
    distances.push_back(d);
    within_1m += d <= 1.0;
    within_2m += d <= 2.0;
    reachable += s.nearest <= 1.0;
  }
  if (a.demonstrations == 0) return a;
  a.within_1m = static_cast<double>(within_1m) / a.demonstrations;
  a.within_2m = static_cast<double>(within_2m) / a.demonstrations;
  a.best_possible_within_1m = static_cast<double>(reachable) / a.demonstrations;
  if (!distances.empty()) {
    double sum = 0;
    for (const double d : distances) sum += d;
    a.mean_distance = sum / static_cast<double>(distances.size());
    std::sort(distances.begin(), distances.end());
    const std::size_t n = distances.size();
    a.median_distance =
        n % 2 == 1 ? distances[n / 2] : 0.5 * (distances[n / 2 - 1] + distances[n / 2]);
  }
  return a;
}

WeightTuningResult TuneWeights(const std::vector<ScoredDemonstration>& training,
                               const ShovelWeights& initial, const WeightTuningOptions& options) {
  if (training.empty()) throw std::invalid_argument("weight tuning: no training demonstrations");
  for (const double w : initial) {
    if (!(w > 0) || !std::isfinite(w)) {
      throw std::invalid_argument("weight tuning: initial weights must be positive and finite");
    }
  }
  // Demonstrations without a feasible candidate say nothing about the weights.
  std::vector<const ScoredDemonstration*> usable;
  for (const ScoredDemonstration& s : training) {
    if (!s.scores.empty()) usable.push_back(&s);
  }
  if (usable.empty()) {
    throw std::invalid_argument(
        "weight tuning: no training demonstration has a feasible candidate");
  }
  const auto hard = [&](const ShovelWeights& w) {
    double sum = 0;
    for (const ScoredDemonstration* s : usable) sum += SelectedDistance(*s, w);
    return sum / static_cast<double>(usable.size());
  };
  // CMA-ES ranks by the softmax-expected distance, which slopes across the hard objective's
  // plateaus; every point it tries is also judged by the hard objective, and the best of those
  // is the result.
  Eigen::VectorXd best_z;
  double best_hard = std::numeric_limits<double>::infinity();
  const auto objective = [&](const Eigen::VectorXd& z) {
    const ShovelWeights w = FromLogRatios(z);
    const double h = hard(w);
    if (h < best_hard) best_hard = h, best_z = z;
    double sum = 0;
    for (const ScoredDemonstration* s : usable) sum += ExpectedDistance(*s, w, options.temperature);
    return sum / static_cast<double>(usable.size());
  };
  Eigen::VectorXd z0(4);
  for (int i = 0; i < 4; ++i) {
    z0[i] = std::clamp(std::log(initial[i] / initial[4]), -kLogRatioBound, kLogRatioBound);
  }
  CmaesOptions cmaes;
  cmaes.sigma0 = options.sigma0;
  cmaes.max_evaluations = options.max_evaluations;
  cmaes.seed = options.seed;
  // The objective is piecewise constant: equal f-values over a generation are a plateau, not
  // convergence, so the f-based stop is off and the budget or TolX ends the run.
  cmaes.tol_fun = 0;
  cmaes.tol_x = 1e-6;
  cmaes.lower = Eigen::VectorXd::Constant(4, -kLogRatioBound);
  cmaes.upper = Eigen::VectorXd::Constant(4, kLogRatioBound);
  if (options.progress) {
    cmaes.on_generation = [&](const CmaesProgress& p) {
      options.progress(p.evaluations, p.best_fitness);
    };
  }
  objective(z0);  // CMA-ES samples around its start without evaluating it: the start competes too
  const CmaesResult r = MinimizeCmaes(objective, z0, cmaes);
  WeightTuningResult result;
  result.weights = FromLogRatios(best_z);
  result.objective = best_hard;
  result.evaluations = r.evaluations;
  result.stop_reason = r.stop_reason;
  return result;
}

}  // namespace autoshovel::identification
