// The truck-bed terrain map (excavator seed §4.3): 15 cm cells over the bed found by truck
// recognition, points outside the bed dropped, unknown cells flagged.
#include "runtime/planning/dump/bed_height_map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "truck_bed_sim.h"

namespace autoshovel::planning {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(BedHeightMap, GridGeometryFollowsTheCellSizeAndTheBedBounds) {
  const BedHeightMap map(dump_sim::kExampleBed, 0.15);
  EXPECT_EQ(map.cells_x(), 32);  // 4.8 m / 0.15 m, no sliver cell from rounding
  EXPECT_EQ(map.cells_y(), 16);
  EXPECT_EQ(map.known_count(), 0);
  EXPECT_TRUE(map.CellCentre(0, 0).isApprox(Eigen::Vector2d(0.075, 0.075)));
  EXPECT_TRUE(map.CellCentre(31, 15).isApprox(Eigen::Vector2d(4.725, 2.325)));
  EXPECT_THROW(map.CellCentre(32, 0), std::out_of_range);

  // A side that is not a whole number of cells gets a partial last cell.
  const BedHeightMap ragged({4.85, 2.4}, 0.15);
  EXPECT_EQ(ragged.cells_x(), 33);

  // Cells are half-open except at the far edges, which belong to the last cells.
  EXPECT_EQ(*map.CellOf({0.0, 0.0}), Eigen::Vector2i(0, 0));
  EXPECT_EQ(*map.CellOf({0.15, 0.1499}), Eigen::Vector2i(1, 0));
  EXPECT_EQ(*map.CellOf({4.8, 2.4}), Eigen::Vector2i(31, 15));
  EXPECT_FALSE(map.CellOf({-0.01, 1.0}));
  EXPECT_FALSE(map.CellOf({4.81, 1.0}));
  EXPECT_FALSE(map.CellOf({1.0, 2.41}));
  EXPECT_FALSE(map.CellOf({kNaN, 1.0}));
}

TEST(BedHeightMap, BinsWorldPointsThroughTheBedPoseAndDropsPointsOutsideTheBed) {
  const Eigen::Isometry3d T_world_bed = dump_sim::ExampleBedPose();
  const std::vector<Eigen::Vector3d> p_bed = {
      {0.20, 0.20, 0.10}, {0.25, 0.28, 0.30},  // cell (1, 1): mean 0.2, max 0.3
      {2.43, 1.23, 0.50},                      // cell (16, 8)
      {-0.05, 1.0, 0.9},  {4.9, 1.0, 0.9},     // beyond the front and rear walls
      {2.0, -0.02, 0.9},  {2.0, 2.45, 0.9},    // beyond the side walls
      {3.0, 1.0, 2.5},                         // above the height window (dust)
  };
  std::vector<Eigen::Vector3d> p_world;
  for (const Eigen::Vector3d& p : p_bed) p_world.push_back(T_world_bed * p);

  BedHeightMapConfig config;
  config.max_height_m = 2.0;
  const BedHeightMap mean =
      BedHeightMap::FromWorldPoints(dump_sim::kExampleBed, T_world_bed, p_world, config);
  EXPECT_EQ(mean.known_count(), 2);
  ASSERT_TRUE(mean.known(1, 1));
  EXPECT_NEAR(mean.height(1, 1), 0.2, 1e-12);
  ASSERT_TRUE(mean.known(16, 8));
  EXPECT_NEAR(mean.height(16, 8), 0.5, 1e-12);
  EXPECT_FALSE(mean.known(20, 6));     // the dust point's cell
  EXPECT_EQ(mean.height(20, 6), 0.0);  // unknown cells hold 0, never NaN
  EXPECT_TRUE(mean.heights().allFinite());

  config.reduction = CellReduction::kMax;
  const BedHeightMap max =
      BedHeightMap::FromWorldPoints(dump_sim::kExampleBed, T_world_bed, p_world, config);
  EXPECT_NEAR(max.height(1, 1), 0.3, 1e-12);
}

TEST(BedHeightMap, BadInputIsRejectedWithAClearError) {
  EXPECT_THROW(BedHeightMap(dump_sim::kExampleBed, 0.0), std::invalid_argument);
  EXPECT_THROW(BedHeightMap(dump_sim::kExampleBed, -0.15), std::invalid_argument);
  EXPECT_THROW(BedHeightMap(dump_sim::kExampleBed, kNaN), std::invalid_argument);
  EXPECT_THROW(BedHeightMap({0.0, 2.4}, 0.15), std::invalid_argument);
  EXPECT_THROW(BedHeightMap({4.8, 0.0}, 0.15), std::invalid_argument);
  EXPECT_THROW(BedHeightMap({kNaN, 2.4}, 0.15), std::invalid_argument);
  EXPECT_THROW(BedHeightMap({std::numeric_limits<double>::infinity(), 2.4}, 0.15),
               std::invalid_argument);
  EXPECT_THROW(BedHeightMap(dump_sim::kExampleBed, 1e-4), std::invalid_argument);  // 115 M cells

  const std::vector<Eigen::Vector3d> nan_point = {{1.0, 1.0, 0.2}, {1.0, kNaN, 0.2}};
  EXPECT_THROW(BedHeightMap::FromBedPoints(dump_sim::kExampleBed, nan_point),
               std::invalid_argument);
  EXPECT_THROW(BedHeightMap::FromWorldPoints(dump_sim::kExampleBed, Eigen::Isometry3d::Identity(),
                                             nan_point),
               std::invalid_argument);
  Eigen::Isometry3d bad_pose = Eigen::Isometry3d::Identity();
  bad_pose.translation().x() = kNaN;
  const std::vector<Eigen::Vector3d> fine = {{1.0, 1.0, 0.2}};
  EXPECT_THROW(BedHeightMap::FromWorldPoints(dump_sim::kExampleBed, bad_pose, fine),
               std::invalid_argument);
  BedHeightMapConfig nan_window;
  nan_window.max_height_m = kNaN;
  EXPECT_THROW(BedHeightMap::FromBedPoints(dump_sim::kExampleBed, fine, nan_window),
               std::invalid_argument);

  BedHeightMap map(dump_sim::kExampleBed, 0.15);
  EXPECT_THROW(map.SetHeight(3, 3, kNaN), std::invalid_argument);
  EXPECT_THROW(map.SetHeight(-1, 3, 0.1), std::out_of_range);
  EXPECT_THROW(map.SetHeight(3, 16, 0.1), std::out_of_range);
  map.SetHeight(3, 3, 0.4);
  EXPECT_TRUE(map.known(3, 3));
  map.SetUnknown(3, 3);
  EXPECT_FALSE(map.known(3, 3));
  EXPECT_EQ(map.height(3, 3), 0.0);
}

}  // namespace
}  // namespace autoshovel::planning
