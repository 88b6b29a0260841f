// Plan-view clearance between the loader footprint and obstacle boxes.
#include "runtime/app/safety_margin.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "runtime/app/crowd_lookahead.h"
#include "runtime/perception/semantic_map.h"

namespace autoshovel::app {
namespace {

Quad Square(double x, double y, double half) {
  return {Eigen::Vector2d(x - half, y - half), Eigen::Vector2d(x + half, y - half),
          Eigen::Vector2d(x + half, y + half), Eigen::Vector2d(x - half, y + half)};
}

TEST(SafetyMargin, QuadDistanceIsEuclideanBetweenOutlines) {
  EXPECT_NEAR(QuadDistance(Square(0, 0, 1), Square(5, 0, 1)), 3.0, 1e-12);             // faces
  EXPECT_NEAR(QuadDistance(Square(0, 0, 1), Square(4, 4, 1)), std::sqrt(8.0), 1e-12);  // corners
  EXPECT_EQ(QuadDistance(Square(0, 0, 1), Square(1.5, 0.5, 1)), 0.0);                  // overlap
  EXPECT_EQ(QuadDistance(Square(0, 0, 3), Square(0, 0, 1)), 0.0);                      // inside
}

TEST(SafetyMargin, FootprintClearanceFindsTheNearestBox) {
  perception::MachineFootprint f;
  f.hinge_xy = Eigen::Vector2d(0, 0);
  f.heading_front = 0;
  f.front_length = 5;
  f.rear_length = 4;
  f.half_width = 1.5;
  plant::OrientedBox ahead, beside;
  ahead.name = "ahead";
  ahead.center = Eigen::Vector3d(8, 0, 1);
  ahead.half_extents = Eigen::Vector3d(1, 1, 1);
  beside.name = "beside";
  beside.center = Eigen::Vector3d(-2, 4, 1);
  beside.half_extents = Eigen::Vector3d(1, 0.5, 1);
  beside.yaw = std::numbers::pi / 2;  // 1 m along y now: spans y 3..5, x −2.5..−1.5
  const Clearance c = FootprintClearance(f, {ahead, beside});
  EXPECT_NEAR(c.distance, 1.5, 1e-12);  // rear frame's side at y = 1.5 to the box at y = 3
  EXPECT_EQ(c.obstacle, 1);
  // Articulated 90° to the right (γ = −90°), the rear frame trails along −y, away from
  // "beside"; the front frame still faces "ahead" (2 m; "beside" is 2.12 m from its corner).
  f.articulation = -std::numbers::pi / 2;
  EXPECT_NEAR(FootprintClearance(f, {ahead, beside}).distance, 2.0, 1e-12);
}

// The look-ahead's distance: only cells ahead and within the corridor count, measured from the
// front edge to the cell's near face (half a cell before its centre).
TEST(CrowdLookahead, DistanceAheadCountsOnlyTheCorridorAhead) {
  const std::vector<Eigen::Vector2d> cells = {
      {10.0, 0.5},   // ahead, in the corridor: 10 − 6 − 0.15
      {7.0, 3.0},    // nearer but beside the corridor (|y| > 2)
      {-3.0, 0.0}};  // behind
  EXPECT_NEAR(DistanceAhead(cells, {0, 0}, 0.0, 2.0, 6.0, 0.3), 3.85, 1e-12);
  // Heading north, the same cells are all outside the corridor or behind.
  EXPECT_TRUE(std::isinf(DistanceAhead(cells, {0, 0}, std::numbers::pi / 2, 0.4, 6.0, 0.3)));
}

TEST(CrowdLookahead, FootprintDistanceToCellsSeesBothFrames) {
  perception::MachineFootprint f;
  f.hinge_xy = {0, 0};
  f.heading_front = 0;
  f.articulation = 0;
  f.front_length = 6.0;
  f.rear_length = 4.0;
  f.half_width = 1.5;
  // Beside the front frame: 3 − 1.5 − 0.15; beyond its corner: hypot(2, 1) − 0.15.
  EXPECT_NEAR(FootprintDistanceToCells(f, {{3.0, 3.0}}, 0.3), 1.35, 1e-12);
  EXPECT_NEAR(FootprintDistanceToCells(f, {{8.0, 2.5}}, 0.3), std::hypot(2.0, 1.0) - 0.15, 1e-12);
  // Behind: the rear frame turned by the articulation. With γ = 90° the rear frame points
  // along +y from the hinge (heading 0 − 90°: its backwards axis is +y), so a cell at (0, 5)
  // lies 1 m past its end; with γ = 0 the same cell is 3.5 m beside it.
  int nearest = -2;
  EXPECT_NEAR(FootprintDistanceToCells(f, {{-9, 0}, {0.0, 5.0}}, 0.3, &nearest), 3.35, 1e-12);
  EXPECT_EQ(nearest, 1);
  f.articulation = std::numbers::pi / 2;
  EXPECT_NEAR(FootprintDistanceToCells(f, {{0.0, 5.0}}, 0.3), 0.85, 1e-12);
  // Inside: negative by the half cell; no cells: +inf.
  EXPECT_NEAR(FootprintDistanceToCells(f, {{1.0, 0.0}}, 0.3), -0.15, 1e-12);
  EXPECT_TRUE(std::isinf(FootprintDistanceToCells(f, {}, 0.3)));
}

// A wall's row of sure cells (obstacle 1.0, pile 0.1) with, in front of it, the blurred crest:
// a row of confident obstacle cells that carry pile evidence too (obstacle 0.97, pile 0.8), and a
// pile top seen obliquely (obstacle 0.7). Growth takes the confident cells within `growth`
// cells of a sure one, never the oblique top.
TEST(CrowdLookahead, SureObstacleCellsGrowByTheGivenCellsOnly) {
  perception::GridMap map(0.3, Eigen::Vector2d(3.0, 3.0), Eigen::Vector2d(0, 0));  // 10 × 10
  map.Add("class", static_cast<float>(perception::CellClass::kGround));
  map.Add("obstacle_confidence", 0.0f);
  map.Add("pile_confidence", 0.0f);
  auto set = [&](int ix, float obstacle, float pile) {
    for (int iy = 0; iy < 10; ++iy) {
      const perception::Index i(ix, iy);
      map.at("class", i) = static_cast<float>(perception::CellClass::kObstacle);
      map.at("obstacle_confidence", i) = obstacle;
      map.at("pile_confidence", i) = pile;
    }
  };
  set(9, 1.0f, 0.1f);   // the wall: sure
  set(8, 0.97f, 0.8f);  // the crest against it: confident, not sure (0.97 − 0.8 < 0.5)
  set(7, 0.97f, 0.8f);
  set(6, 0.7f, 0.6f);  // an obliquely seen top: not even confident
  auto columns = [&](int growth) {
    std::vector<int> xs;
    for (const Eigen::Vector2d& p : SureObstacleCells(map, 0.5, growth)) {
      perception::Index i;
      EXPECT_TRUE(map.IndexOf(p, i));
      if (std::find(xs.begin(), xs.end(), i.x()) == xs.end()) xs.push_back(i.x());
    }
    std::sort(xs.begin(), xs.end());
    return xs;
  };
  EXPECT_EQ(columns(0), std::vector<int>({9}));
  EXPECT_EQ(columns(1), std::vector<int>({8, 9}));
  EXPECT_EQ(columns(2), std::vector<int>({7, 8, 9}));
  EXPECT_EQ(columns(5), std::vector<int>({7, 8, 9}));
  EXPECT_EQ(SureObstacleCells(map, 0.5, 1).size(), 20u);
}

}  // namespace
}  // namespace autoshovel::app
