// The refined planner's evaluation budget (budgeted_search.h) on synthetic costs over the
// 3 × 8 × 4 × 5 dig grid.
#include "runtime/planning/dig/budgeted_search.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <vector>

namespace autoshovel::planning {
namespace {

constexpr DigGridIndex kExtent = {3, 8, 4, 5};

std::vector<DigGridIndex> FullGrid() {
  std::vector<DigGridIndex> out;
  for (int a = 0; a < kExtent[0]; ++a) {
    for (int b = 0; b < kExtent[1]; ++b) {
      for (int c = 0; c < kExtent[2]; ++c) {
        for (int d = 0; d < kExtent[3]; ++d) out.push_back({a, b, c, d});
      }
    }
  }
  return out;
}

// A bowl with its minimum at `centre`.
double Bowl(const DigGridIndex& g, const DigGridIndex& centre) {
  double sum = 0;
  for (int d = 0; d < 4; ++d) sum += (d + 1) * std::pow(g[d] - centre[d], 2);
  return sum;
}

TEST(BudgetedSearch, EvaluatesEveryPointOnceWhenTheyFit) {
  const std::vector<DigGridIndex> points = {{0, 0, 0, 0}, {1, 2, 3, 4}, {2, 7, 0, 1}};
  std::vector<int> calls(points.size(), 0);
  const std::vector<int> order = BudgetedSearch(
      points, kExtent, 3, 1, [](int) { return 0.0; },
      [&](int i) {
        ++calls[i];
        return 1.0;
      });
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(calls, (std::vector<int>{1, 1, 1}));
}

TEST(BudgetedSearch, NeverExceedsTheBudgetNorAsksTwice) {
  std::mt19937 rng(7);
  std::vector<DigGridIndex> points;
  for (const DigGridIndex& g : FullGrid()) {
    if (std::uniform_real_distribution<double>(0, 1)(rng) < 0.6) points.push_back(g);
  }
  std::vector<double> cost(points.size()), prior(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    cost[i] = std::uniform_real_distribution<double>(0, 1)(rng);
    // A third infeasible.
    if (i % 3 == 0) cost[i] = std::numeric_limits<double>::quiet_NaN();
    prior[i] = std::uniform_real_distribution<double>(0, 1)(rng);
  }
  for (int budget : {1, 5, 17, 40}) {
    int calls = 0;
    std::set<int> seen;
    const std::vector<int> order = BudgetedSearch(
        points, kExtent, budget, 5, [&](int i) { return prior[i]; },
        [&](int i) {
          ++calls;
          EXPECT_TRUE(seen.insert(i).second) << "point " << i << " asked twice";
          return cost[i];
        });
    EXPECT_EQ(calls, budget);
    EXPECT_EQ(static_cast<int>(order.size()), budget);
  }
}

TEST(BudgetedSearch, ScreeningGoesRoundTheCutsBestPriorFirst) {
  const std::vector<DigGridIndex> points = FullGrid();
  // The prior prefers large swing and radius indices, whatever the cut.
  auto prior = [&](int i) { return -(points[i][0] * 10.0 + points[i][1]); };
  std::vector<int> asked;
  BudgetedSearch(points, kExtent, 40, 20, prior, [&](int i) {
    asked.push_back(i);
    return 1.0;
  });
  ASSERT_EQ(asked.size(), 40u);
  std::set<std::pair<int, int>> cuts;
  for (int k = 0; k < 20; ++k) {
    const DigGridIndex& g = points[asked[k]];
    EXPECT_TRUE(cuts.insert({g[2], g[3]}).second) << "cut repeated within the first round";
    // Each cut's pick is its most promising entry point.
    EXPECT_EQ(g[0], 2);
    EXPECT_EQ(g[1], 7);
  }
}

TEST(BudgetedSearch, RefinementWalksToTheMinimumOfABowl) {
  const std::vector<DigGridIndex> points = FullGrid();  // 480 points
  const DigGridIndex centre = {1, 5, 2, 3};
  // An uninformative prior: the screening sees one entry per cut, the refinement the rest.
  int calls = 0;
  double best = std::numeric_limits<double>::infinity();
  BudgetedSearch(
      points, kExtent, 60, 20, [](int) { return 0.0; },
      [&](int i) {
        ++calls;
        best = std::min(best, Bowl(points[i], centre));
        return Bowl(points[i], centre);
      });
  EXPECT_EQ(calls, 60);
  EXPECT_EQ(best, 0.0);
}

TEST(BudgetedSearch, InfeasiblePointsDoNotStopTheRefinement) {
  const std::vector<DigGridIndex> points = FullGrid();
  const DigGridIndex centre = {1, 5, 2, 3};
  // Everything at swing sample 0 is infeasible (a third of the grid), the prior is flat.
  std::vector<int> asked;
  BudgetedSearch(
      points, kExtent, 60, 20, [](int) { return 0.0; },
      [&](int i) {
        asked.push_back(i);
        return points[i][0] == 0 ? std::numeric_limits<double>::quiet_NaN()
                                 : Bowl(points[i], centre);
      });
  int infeasible = 0;
  double best = std::numeric_limits<double>::infinity();
  for (int i : asked) {
    if (points[i][0] == 0) {
      ++infeasible;
    } else {
      best = std::min(best, Bowl(points[i], centre));
    }
  }
  EXPECT_EQ(best, 0.0);
  // Met in the spread screening and as neighbours of feasible points, never refined around.
  EXPECT_LT(infeasible, 20);
}

TEST(BudgetedSearch, FlatPriorSpreadsTheScreening) {
  const std::vector<DigGridIndex> points = FullGrid();
  std::vector<int> asked;
  BudgetedSearch(
      points, kExtent, 20, 20, [](int) { return 0.0; },
      [&](int i) {
        asked.push_back(i);
        return 1.0;
      });
  std::set<int> swings, radii;
  for (int i : asked) {
    swings.insert(points[i][0]);
    radii.insert(points[i][1]);
  }
  EXPECT_EQ(swings.size(), 3u);
  EXPECT_GE(radii.size(), 4u);
}

}  // namespace
}  // namespace autoshovel::planning
