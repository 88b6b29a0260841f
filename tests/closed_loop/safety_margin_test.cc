// Plan-view clearance between the loader footprint and obstacle boxes.
#include "runtime/app/safety_margin.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "runtime/app/crowd_lookahead.h"

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

}  // namespace
}  // namespace autoshovel::app
