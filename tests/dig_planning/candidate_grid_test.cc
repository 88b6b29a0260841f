// The refined planner's candidate grid in a region (candidate_grid.h).
#include "runtime/planning/dig/candidate_grid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "dig_test_support.h"

namespace autoshovel::planning {
namespace {

using testing::kNaN;
using testing::MapFrom;

DigRegion Region() {
  DigRegion r;
  r.swing_min = -0.3;
  r.swing_max = 0.0;
  r.radius_min = 5.0;
  r.radius_max = 7.0;
  r.z_min = 1.0;
  r.z_max = 2.0;
  return r;
}

TEST(CandidateGrid, SamplesTheRegionAndTheConfiguredBounds) {
  DigGridConfig config;
  config.swing_samples = 3;
  config.radius_step = 0.5;
  config.depth_min = 0.2;
  config.depth_max = 0.6;
  config.depth_samples = 3;
  config.drag_min = 1.0;
  config.drag_max = 2.0;
  config.drag_samples = 2;
  const DigRegion region = Region();
  const std::array<int, 4> extent = DigGridExtent(config, region);
  EXPECT_EQ(extent, (std::array<int, 4>{3, 5, 3, 2}));  // radii 5, 5.5, ..., 7
  const control::HeightGrid map = MapFrom([](double, double) { return 1.9; });
  const std::vector<DigGridPoint> grid = EnumerateDigGrid(config, region, map);
  ASSERT_EQ(grid.size(), 90u);
  // Index order: swing slowest, drag fastest.
  EXPECT_EQ(grid[1].index, (std::array<int, 4>{0, 0, 0, 1}));
  EXPECT_EQ(grid[89].index, (std::array<int, 4>{2, 4, 2, 1}));
  // Swing at slice centres, radius from end to end, depth and drag end to end.
  EXPECT_NEAR(grid[0].action.swing, -0.25, 1e-12);
  EXPECT_NEAR(grid[89].action.swing, -0.05, 1e-12);
  EXPECT_NEAR(grid[0].action.radius, 5.0, 1e-12);
  EXPECT_NEAR(grid[89].action.radius, 7.0, 1e-12);
  EXPECT_NEAR(grid[0].action.depth, 0.2, 1e-12);
  EXPECT_NEAR(grid[89].action.depth, 0.6, 1e-12);
  EXPECT_NEAR(grid[0].action.drag_length, 1.0, 1e-12);
  EXPECT_NEAR(grid[89].action.drag_length, 2.0, 1e-12);
  for (const DigGridPoint& p : grid) {
    EXPECT_EQ(p.rejection, DigGridRejection::kNone) << p.why;
    EXPECT_NEAR(p.action.entry_height, 1.9, 1e-12);
  }
}

TEST(CandidateGrid, CutsAreClippedToTheBandBottomOnce) {
  DigGridConfig config;  // depths 0.2, 0.4, 0.6, 0.8
  const DigRegion region = Region();
  // 0.5 m of material above the band bottom (1 m).
  const control::HeightGrid map = MapFrom([](double, double) { return 1.5; });
  for (const DigGridPoint& p : EnumerateDigGrid(config, region, map)) {
    switch (p.index[2]) {
      case 0:
      case 1:
        EXPECT_EQ(p.rejection, DigGridRejection::kNone);
        break;
      case 2:  // 0.6 m clipped to 0.5 m: the cut down to the band bottom
        EXPECT_EQ(p.rejection, DigGridRejection::kNone);
        EXPECT_NEAR(p.action.depth, 0.5, 1e-12);
        break;
      default:  // 0.8 m would repeat it
        EXPECT_EQ(p.rejection, DigGridRejection::kRepeatedCut);
        EXPECT_NEAR(p.action.depth, 0.5, 1e-12);
    }
  }
}

TEST(CandidateGrid, NoMaterialAndUnknownSurface) {
  const DigGridConfig config;
  const DigRegion region = Region();
  // Left of swing -0.1 unseen (entry swings -0.25, -0.15, -0.05); right of it 5 cm above the
  // band bottom (less than min_cut_depth).
  const control::HeightGrid map =
      MapFrom([](double x, double y) { return std::atan2(y, x) > -0.1 ? kNaN : 1.05; });
  for (const DigGridPoint& p : EnumerateDigGrid(config, region, map)) {
    if (p.action.swing > -0.1) {
      EXPECT_EQ(p.rejection, DigGridRejection::kUnknownSurface);
      EXPECT_TRUE(std::isnan(p.action.entry_height));
    } else {
      EXPECT_EQ(p.rejection, DigGridRejection::kNoMaterial);
    }
    EXPECT_FALSE(p.why.empty());
  }
}

TEST(CandidateGrid, InvalidConfigNamesTheField) {
  auto expect_field = [](const DigGridConfig& c, const std::string& field) {
    try {
      Validate(c, "grid");
      ADD_FAILURE() << field;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("grid." + field), std::string::npos) << e.what();
    }
  };
  DigGridConfig c;
  c.depth_samples = 0;
  expect_field(c, "depth_samples");
  c = {};
  c.drag_max = 0.5;
  expect_field(c, "drag_max");
  c = {};
  c.drag_samples = -1;
  expect_field(c, "drag_samples");
  c = {};
  c.depth_min = 0.0;
  expect_field(c, "depth_min");
  c = {};
  c.min_cut_depth = -0.1;
  expect_field(c, "min_cut_depth");
  EXPECT_NO_THROW(Validate(DigGridConfig{}, "grid"));
}

}  // namespace
}  // namespace autoshovel::planning
