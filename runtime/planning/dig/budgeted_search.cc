#include "runtime/planning/dig/budgeted_search.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

namespace autoshovel::planning {
namespace {

constexpr int kDims = 4;

// ±1 along each dimension.
constexpr DigGridIndex kNeighbourSteps[] = {{-1, 0, 0, 0}, {1, 0, 0, 0},  {0, -1, 0, 0},
                                            {0, 1, 0, 0},  {0, 0, -1, 0}, {0, 0, 1, 0},
                                            {0, 0, 0, -1}, {0, 0, 0, 1}};

class Search {
 public:
  Search(const std::vector<DigGridIndex>& points, const DigGridIndex& extent,
         const std::function<double(int)>& prior, const std::function<double(int)>& evaluate,
         int budget)
      : points_(points), extent_(extent), prior_(prior), evaluate_(evaluate), budget_(budget) {
    const int n = static_cast<int>(points.size());
    cost_.assign(n, std::numeric_limits<double>::quiet_NaN());
    evaluated_.assign(n, false);
    nearest_.assign(n, std::numeric_limits<double>::infinity());
    std::size_t cells = 1;
    for (int e : extent) cells *= static_cast<std::size_t>(std::max(e, 1));
    slot_.assign(cells, -1);
    for (int i = 0; i < n; ++i) slot_[Flat(points[i])] = i;
  }

  int size() const { return static_cast<int>(points_.size()); }
  bool Spent() const { return static_cast<int>(order_.size()) >= budget_; }
  const std::vector<int>& order() const { return order_; }

  /// Evaluates point i unless it already is or the budget is spent; true when it was evaluated.
  bool Evaluate(int i) {
    if (i < 0 || evaluated_[i] || Spent()) return false;
    evaluated_[i] = true;
    order_.push_back(i);
    cost_[i] = evaluate_(i);
    for (int j = 0; j < size(); ++j) nearest_[j] = std::min(nearest_[j], Distance2(i, j));
    return true;
  }

  /// Evaluates the unevaluated point with the lowest prior now, among the points whose cut
  /// (depth, drag) differs from those of the points picked so far in this round when
  /// `diversify`; a round ends when every cut has had its pick. Among equal priors, the point
  /// farthest from those evaluated (grid indices normalised per dimension), so that a prior
  /// that cannot tell points apart spreads the picks instead of taking them in index order.
  /// False when none is left.
  bool EvaluateNextByPrior(bool diversify) {
    const int cuts = std::max(extent_[2], 1) * std::max(extent_[3], 1);
    if (diversify && static_cast<int>(round_.size()) >= cuts) round_.clear();
    for (int attempt = 0; attempt < 2; ++attempt) {
      int best = -1;
      double best_prior = std::numeric_limits<double>::infinity();
      for (int i = 0; i < size(); ++i) {
        if (evaluated_[i]) continue;
        if (diversify && round_.count(Cut(i)) > 0) continue;
        double p = prior_(i);
        if (std::isnan(p)) p = std::numeric_limits<double>::infinity();
        if (best < 0 || p < best_prior || (p == best_prior && nearest_[i] > nearest_[best])) {
          best = i;
          best_prior = p;
        }
      }
      if (best >= 0) {
        if (diversify) round_.insert(Cut(best));
        return Evaluate(best);
      }
      if (!diversify || round_.empty()) return false;
      round_.clear();  // every cut left is spent this round: start the next
    }
    return false;
  }

  /// Unevaluated ±1 grid neighbours of the best-scored point that has any; empty when none has.
  std::vector<int> NeighboursOfBest() const {
    std::vector<int> scored;
    for (int i : order_) {
      if (!std::isnan(cost_[i])) scored.push_back(i);
    }
    std::sort(scored.begin(), scored.end(),
              [&](int a, int b) { return cost_[a] < cost_[b] || (cost_[a] == cost_[b] && a < b); });
    for (int i : scored) {
      std::vector<int> out;
      for (const DigGridIndex& step : kNeighbourSteps) {
        DigGridIndex index = points_[i];
        bool inside = true;
        for (int d = 0; d < kDims; ++d) {
          index[d] += step[d];
          inside = inside && index[d] >= 0 && index[d] < extent_[d];
        }
        if (!inside) continue;
        const int j = slot_[Flat(index)];
        if (j >= 0 && !evaluated_[j]) out.push_back(j);
      }
      if (!out.empty()) {
        std::sort(out.begin(), out.end());
        return out;
      }
    }
    return {};
  }

 private:
  double Distance2(int i, int j) const {
    double sum = 0;
    for (int d = 0; d < kDims; ++d) {
      if (extent_[d] > 1)
        sum += std::pow(static_cast<double>(points_[i][d] - points_[j][d]) / (extent_[d] - 1), 2);
    }
    return sum;
  }

  int Cut(int i) const { return points_[i][2] * std::max(extent_[3], 1) + points_[i][3]; }

  std::size_t Flat(const DigGridIndex& index) const {
    std::size_t flat = 0;
    for (int d = 0; d < kDims; ++d) {
      flat = flat * static_cast<std::size_t>(std::max(extent_[d], 1)) +
             static_cast<std::size_t>(index[d]);
    }
    return flat;
  }

  const std::vector<DigGridIndex>& points_;
  DigGridIndex extent_;
  const std::function<double(int)>& prior_;
  const std::function<double(int)>& evaluate_;
  int budget_;
  std::vector<double> cost_;
  std::vector<bool> evaluated_;
  std::vector<double> nearest_;  ///< squared normalised distance to the nearest evaluated point
  std::vector<int> slot_;        ///< grid cell → point, -1 for none
  std::vector<int> order_;
  std::set<int> round_;  ///< cuts picked in the current screening round
};

}  // namespace

std::vector<int> BudgetedSearch(const std::vector<DigGridIndex>& points, const DigGridIndex& extent,
                                int budget, int coarse, const std::function<double(int)>& prior,
                                const std::function<double(int)>& evaluate) {
  budget = std::max(0, budget);
  Search search(points, extent, prior, evaluate, budget);
  if (search.size() <= budget) {
    for (int i = 0; i < search.size(); ++i) search.Evaluate(i);
    return search.order();
  }
  coarse = std::clamp(coarse, 1, std::max(budget, 1));
  while (static_cast<int>(search.order().size()) < coarse &&
         search.EvaluateNextByPrior(/*diversify=*/true)) {
  }
  while (!search.Spent()) {
    const std::vector<int> next = search.NeighboursOfBest();
    for (int j : next) search.Evaluate(j);
    if (next.empty() && !search.EvaluateNextByPrior(/*diversify=*/false)) break;
  }
  return search.order();
}

}  // namespace autoshovel::planning
