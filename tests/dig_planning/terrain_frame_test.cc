// A world-frame terrain map seen from the excavator's base frame (terrain_frame.h).
#include "runtime/planning/dig/terrain_frame.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace autoshovel::planning {
namespace {

TEST(BaseFrameGrid, MovesAndTurnsTheMapIntoTheBaseFrame) {
  // World: a ramp rising 0.1 m per metre of world x, 2 m at x = 0, 0.05 m cells.
  control::HeightGrid map_world(Eigen::Vector2d(-10.0, -10.0), 0.05, 600, 600);
  for (int iy = 0; iy < map_world.ny(); ++iy) {
    for (int ix = 0; ix < map_world.nx(); ++ix) {
      map_world.set_height(ix, iy, 2.0 + 0.1 * map_world.CellCenter(ix, iy).x());
    }
  }
  // The excavator stands at (5, 3), 1.5 m up, turned 30° left.
  const Eigen::Isometry3d T_world_base =
      Eigen::Translation3d(5.0, 3.0, 1.5) *
      Eigen::AngleAxisd(std::numbers::pi / 6, Eigen::Vector3d::UnitZ());
  const control::HeightGrid map_base =
      BaseFrameGrid(map_world, T_world_base, Eigen::Vector2d(-12.0, -12.0), 0.1, 240, 240);
  // Inside the world map: the world ramp under the base cell, less the base's height. Nearest
  // world cell: off by at most half a world cell diagonal along x, 0.1 × 0.035 m.
  for (const Eigen::Vector2d& p_base :
       {Eigen::Vector2d(0.05, 0.05), Eigen::Vector2d(6.05, -2.95), Eigen::Vector2d(-4.95, 7.05)}) {
    const Eigen::Vector3d p_world = T_world_base * Eigen::Vector3d(p_base.x(), p_base.y(), 0.0);
    const double expected = 2.0 + 0.1 * p_world.x() - 1.5;
    EXPECT_NEAR(map_base.HeightAt(p_base.x(), p_base.y()), expected, 0.004) << p_base.transpose();
  }
  // Beyond the world map's edge (world x > 20): unknown.
  EXPECT_TRUE(std::isnan(map_base.HeightAt(11.9, -11.9)));
}

TEST(BaseFrameGrid, RefusesATiltedOrNonFiniteBase) {
  const control::HeightGrid map_world(Eigen::Vector2d(-10.0, -10.0), 0.1, 200, 200, 0.0);
  const Eigen::Isometry3d tilted(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()));
  EXPECT_THROW(BaseFrameGrid(map_world, tilted, Eigen::Vector2d(-5, -5), 0.1, 100, 100),
               std::invalid_argument);
  // Tilt within the allowance: accepted.
  EXPECT_NO_THROW(
      BaseFrameGrid(map_world, tilted, Eigen::Vector2d(-5, -5), 0.1, 100, 100, /*max_tilt=*/0.2));
  Eigen::Isometry3d broken = Eigen::Isometry3d::Identity();
  broken.translation().x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(BaseFrameGrid(map_world, broken, Eigen::Vector2d(-5, -5), 0.1, 100, 100),
               std::invalid_argument);
  EXPECT_THROW(BaseFrameGrid(map_world, Eigen::Isometry3d::Identity(), Eigen::Vector2d(-5, -5), 0.0,
                             100, 100),
               std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::planning
