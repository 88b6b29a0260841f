// The fill distribution of the bed (excavator seed §4.3, "loaded evenly and completely").
#include "runtime/planning/dump/fill_summary.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace autoshovel::planning {
namespace {

TEST(FillSummary, DescribesTheKnownCellsOnly) {
  BedHeightMap map({0.6, 0.3}, 0.15);  // 4 × 2 cells
  map.SetHeight(0, 0, 0.1);
  map.SetHeight(1, 1, 0.2);
  map.SetHeight(2, 0, 0.3);
  map.SetHeight(3, 1, 0.6);
  const FillSummary s = SummarizeFill(map, 0.25);
  EXPECT_EQ(s.known_cells, 4);
  EXPECT_DOUBLE_EQ(s.known_fraction, 0.5);
  EXPECT_NEAR(s.mean_height_m, 0.3, 1e-12);
  EXPECT_NEAR(s.std_height_m, std::sqrt((0.04 + 0.01 + 0.0 + 0.09) / 4), 1e-12);
  EXPECT_DOUBLE_EQ(s.min_height_m, 0.1);
  EXPECT_DOUBLE_EQ(s.max_height_m, 0.6);
  EXPECT_DOUBLE_EQ(s.level_m, 0.25);
  EXPECT_DOUBLE_EQ(s.fraction_above_level, 0.5);
}

TEST(FillSummary, AnUnseenBedGivesZerosNotNaNAndALevelMustBeFinite) {
  const BedHeightMap map({4.8, 2.4}, 0.15);
  const FillSummary s = SummarizeFill(map, 0.5);
  EXPECT_EQ(s.known_cells, 0);
  EXPECT_EQ(s.mean_height_m, 0.0);
  EXPECT_EQ(s.std_height_m, 0.0);
  EXPECT_EQ(s.fraction_above_level, 0.0);
  EXPECT_THROW(SummarizeFill(map, std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::planning
