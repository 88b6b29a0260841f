// The coarse planner (excavator seed §4.2, Fig. 12): regions from the top of the face to the
// bottom and from left (the truck's side, larger swing) to right, skipped when empty, offered
// again while they still hold material.
#include "runtime/planning/dig/coarse_dig_planner.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

#include "dig_test_support.h"
#include "runtime/planning/dig/region_material.h"

namespace autoshovel::planning {
namespace {

using testing::BenchMap;
using testing::kNaN;
using testing::MapFrom;

// Three 0.25 rad columns over a 4.5 m to 8.5 m sector, 1 m bands on a floor at 0 m.
CoarseDigConfig FaceConfig() {
  CoarseDigConfig config;
  config.sector.swing_min = -0.375;
  config.sector.swing_max = 0.375;
  config.sector.radius_min = 5.0;
  config.sector.radius_max = 8.5;
  config.sector.floor_height = 0.0;
  config.region_swing_width = 0.25;
  config.region_height = 1.0;
  return config;
}

// A 2.6 m face covering the whole sector: bands 0, 1 and 2 (the top one 0.6 m thick).
control::HeightGrid Face() { return BenchMap(2.6, 4.8, 8.8, -0.45, 0.45); }

std::vector<std::pair<int, int>> ColumnsAndBands(const std::vector<DigRegion>& regions) {
  std::vector<std::pair<int, int>> out;
  for (const DigRegion& r : regions) out.emplace_back(r.column, r.band);
  return out;
}

// Takes every cell of the region's footprint down to the band bottom (a perfect dig of it).
void EmptyRegion(control::HeightGrid& map, const DigRegion& region) {
  ForEachCellInPolarBox(map, region.swing_min, region.swing_max, region.radius_min,
                        region.radius_max, [&](int ix, int iy, double h) {
                          if (std::isfinite(h) && h > region.z_min) {
                            map.set_height(ix, iy, region.z_min);
                          }
                        });
}

void ExpectThrowNaming(const CoarseDigConfig& config, const std::string& field) {
  try {
    CoarseDigPlanner planner(config);
    ADD_FAILURE() << "no exception for " << field;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
  }
}

TEST(CoarseDigPlanner, ColumnsRunFromTheTruckSideAndBandsStackUpFromTheFloor) {
  const CoarseDigPlanner planner(FaceConfig());
  ASSERT_EQ(planner.columns(), 3);
  for (int c = 0; c + 1 < planner.columns(); ++c) {
    // Column c is left of (larger swing than) column c + 1, and they share an edge.
    EXPECT_NEAR(planner.Region(c, 0).swing_min, planner.Region(c + 1, 0).swing_max, 1e-12);
    EXPECT_GT(planner.Region(c, 0).swing_min, planner.Region(c + 1, 0).swing_min);
  }
  EXPECT_DOUBLE_EQ(planner.Region(0, 0).swing_max, 0.375);
  EXPECT_DOUBLE_EQ(planner.Region(2, 0).swing_min, -0.375);
  EXPECT_DOUBLE_EQ(planner.Region(1, 2).z_min, 2.0);
  EXPECT_DOUBLE_EQ(planner.Region(1, 2).z_max, 3.0);
  EXPECT_EQ(planner.BandCount(Face()), 3);
  EXPECT_THROW(planner.Region(3, 0), std::invalid_argument);
}

TEST(CoarseDigPlanner, DefaultOrderIsTopDownThenLeftToRight) {
  const CoarseDigPlanner planner(FaceConfig());
  const std::vector<std::pair<int, int>> expected = {{0, 2}, {1, 2}, {2, 2}, {0, 1}, {1, 1},
                                                     {2, 1}, {0, 0}, {1, 0}, {2, 0}};
  EXPECT_EQ(ColumnsAndBands(planner.RegionsWithMaterial(Face())), expected);
}

TEST(CoarseDigPlanner, ColumnsFirstOrderWhenAsked) {
  CoarseDigConfig config = FaceConfig();
  config.order = DigRegionOrder::kLeftToRightThenTopDown;
  const CoarseDigPlanner planner(config);
  const std::vector<std::pair<int, int>> expected = {{0, 2}, {0, 1}, {0, 0}, {1, 2}, {1, 1},
                                                     {1, 0}, {2, 2}, {2, 1}, {2, 0}};
  EXPECT_EQ(ColumnsAndBands(planner.RegionsWithMaterial(Face())), expected);
}

TEST(CoarseDigPlanner, EmptiedRegionsAreNotOfferedAgain) {
  const CoarseDigPlanner planner(FaceConfig());
  control::HeightGrid map = Face();
  const std::vector<std::pair<int, int>> expected =
      ColumnsAndBands(planner.RegionsWithMaterial(map));
  std::vector<std::pair<int, int>> offered;
  for (int dig = 0; dig < 20; ++dig) {
    const std::optional<DigRegion> next = planner.NextRegion(map);
    if (!next) break;
    offered.emplace_back(next->column, next->band);
    EmptyRegion(map, *next);
  }
  EXPECT_EQ(offered, expected);  // each once, in order, then nothing
  EXPECT_FALSE(planner.NextRegion(map).has_value());
}

TEST(CoarseDigPlanner, PartlyDugRegionIsOfferedAgain) {
  const CoarseDigPlanner planner(FaceConfig());
  control::HeightGrid map = Face();
  const DigRegion first = *planner.NextRegion(map);
  // Dig only the near half of the region.
  DigRegion near = first;
  near.radius_max = 6.5;
  EmptyRegion(map, near);
  const DigRegion again = *planner.NextRegion(map);
  EXPECT_TRUE(SameRegion(first, again));
  EXPECT_LT(again.volume, 0.7 * first.volume);
  EXPECT_GT(again.volume, 0.3 * first.volume);
}

TEST(CoarseDigPlanner, SkipsRegionsWithoutMaterialAboveTheFloor) {
  CoarseDigConfig config = FaceConfig();
  const CoarseDigPlanner planner(config);
  // Left column: a hole below the floor; middle: 5 cm of residue (under the 0.1 m threshold);
  // right: 0.8 m of material.
  const control::HeightGrid map = MapFrom([](double x, double y) {
    const double swing = std::atan2(y, x), r = std::hypot(x, y);
    if (r < 4.8 || r > 8.8) return 0.0;
    if (swing > 0.125) return -0.5;
    if (swing > -0.125) return 0.05;
    return 0.8;
  });
  const std::vector<DigRegion> regions = planner.RegionsWithMaterial(map);
  ASSERT_EQ(regions.size(), 1u);
  EXPECT_EQ(regions[0].column, 2);
  EXPECT_EQ(regions[0].band, 0);
  // 0.8 m over a quarter-radian sector from 5 m to 8.5 m.
  const double area = 0.5 * 0.25 * (8.5 * 8.5 - 5.0 * 5.0);
  EXPECT_NEAR(regions[0].volume, 0.8 * area, 0.03 * 0.8 * area);
}

TEST(CoarseDigPlanner, UnknownCellsHoldNoMaterial) {
  const CoarseDigPlanner planner(FaceConfig());
  // The left column unseen (NaN), the rest 0.8 m high.
  const control::HeightGrid map = MapFrom([](double x, double y) {
    const double r = std::hypot(x, y);
    if (r < 4.8 || r > 8.8) return 0.0;
    return std::atan2(y, x) > 0.125 ? kNaN : 0.8;
  });
  const std::vector<DigRegion> regions = planner.RegionsWithMaterial(map);
  ASSERT_EQ(regions.size(), 2u);
  EXPECT_EQ(regions[0].column, 1);
  EXPECT_EQ(regions[1].column, 2);
  EXPECT_EQ(regions[0].unknown_cells, 0);
  const RegionMaterial left = MeasureMaterial(map, planner.Region(0, 0), 0.1);
  EXPECT_EQ(left.volume, 0.0);
  EXPECT_EQ(left.known_cells, 0);
  EXPECT_GT(left.unknown_cells, 500);
  EXPECT_TRUE(std::isnan(left.top_height));
  // An unseen map has no bands.
  EXPECT_EQ(planner.BandCount(MapFrom([](double, double) { return kNaN; })), 0);
}

TEST(CoarseDigPlanner, RegionMeasuresItsOwnBandOnly) {
  const CoarseDigPlanner planner(FaceConfig());
  const control::HeightGrid map = Face();
  const double area = 0.5 * 0.25 * (8.5 * 8.5 - 5.0 * 5.0);
  for (const DigRegion& r : planner.RegionsWithMaterial(map)) {
    const double thickness = r.band == 2 ? 0.6 : 1.0;
    EXPECT_NEAR(r.volume, thickness * area, 0.03 * thickness * area)
        << "column " << r.column << " band " << r.band;
    EXPECT_DOUBLE_EQ(r.top_height, 2.6);
  }
}

TEST(CoarseDigPlanner, ExhaustedRegionsAreSkipped) {
  CoarseDigPlanner planner(FaceConfig());
  const control::HeightGrid map = Face();
  const DigRegion first = *planner.NextRegion(map);
  planner.MarkExhausted(first);
  EXPECT_TRUE(planner.IsExhausted(first));
  const DigRegion second = *planner.NextRegion(map);
  EXPECT_EQ(second.column, 1);
  EXPECT_EQ(second.band, 2);
  // Still listed (it holds material), only not offered.
  EXPECT_EQ(planner.RegionsWithMaterial(map).size(), 9u);
  planner.ClearExhausted();
  EXPECT_TRUE(SameRegion(*planner.NextRegion(map), first));
}

TEST(CoarseDigPlanner, InvalidConfigNamesTheField) {
  CoarseDigConfig c = FaceConfig();
  c.sector.swing_max = c.sector.swing_min;
  ExpectThrowNaming(c, "CoarseDigConfig.sector.swing_max");
  c = FaceConfig();
  c.sector.swing_min = -4.0;
  ExpectThrowNaming(c, "CoarseDigConfig.sector.swing_min");
  c = FaceConfig();
  c.sector.radius_min = 0.0;
  ExpectThrowNaming(c, "CoarseDigConfig.sector.radius_min");
  c = FaceConfig();
  c.sector.radius_max = 4.0;
  ExpectThrowNaming(c, "CoarseDigConfig.sector.radius_max");
  c = FaceConfig();
  c.sector.floor_height = kNaN;
  ExpectThrowNaming(c, "CoarseDigConfig.sector.floor_height");
  c = FaceConfig();
  c.region_swing_width = 0.0;
  ExpectThrowNaming(c, "CoarseDigConfig.region_swing_width");
  c = FaceConfig();
  c.region_height = -1.0;
  ExpectThrowNaming(c, "CoarseDigConfig.region_height");
  c = FaceConfig();
  c.min_material_thickness = 1.0;  // not below region_height
  ExpectThrowNaming(c, "CoarseDigConfig.min_material_thickness");
  c = FaceConfig();
  c.min_region_volume = kNaN;
  ExpectThrowNaming(c, "CoarseDigConfig.min_region_volume");
}

}  // namespace
}  // namespace autoshovel::planning
