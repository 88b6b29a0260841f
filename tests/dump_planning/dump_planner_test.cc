// Template based dump planning (excavator seed §4.3) on scans of a simulated bed.
#include "runtime/planning/dump/dump_planner.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "runtime/planning/dump/grid_filters.h"
#include "truck_bed_sim.h"

namespace autoshovel::planning {
namespace {

using dump_sim::ExampleBedPose;
using dump_sim::kExampleBed;
using dump_sim::ScanConfig;
using dump_sim::SimulatedBed;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

BedHeightMap ScanMap(const SimulatedBed& sim, const ScanConfig& scan, unsigned seed) {
  std::mt19937 rng(seed);
  const Eigen::Isometry3d T_world_bed = ExampleBedPose();
  return BedHeightMap::FromWorldPoints(sim.bed(), T_world_bed, sim.Scan(T_world_bed, scan, rng));
}

// The footprint rectangle grown by the wall margin lies inside the bed.
void ExpectFootprintInside(const DumpPlan& plan, const DumpPlannerConfig& config) {
  const double reach_x = 0.5 * config.footprint_along_bed_m + config.wall_margin_m;
  const double reach_y = 0.5 * config.footprint_across_bed_m + config.wall_margin_m;
  EXPECT_GE(plan.p_bed_dump.x() - reach_x, -1e-9);
  EXPECT_LE(plan.p_bed_dump.x() + reach_x, kExampleBed.length_m + 1e-9);
  EXPECT_GE(plan.p_bed_dump.y() - reach_y, -1e-9);
  EXPECT_LE(plan.p_bed_dump.y() + reach_y, kExampleBed.width_m + 1e-9);
}

TEST(DumpPlanner, FirstDumpIntoAnEmptyBedGoesToTheMiddle) {
  const DumpPlanner planner;
  const SimulatedBed empty(kExampleBed);
  // Noise-free: every score ties exactly and the tie-break alone decides.
  const DumpPlan exact = planner.Plan(ScanMap(empty, {.noise_m = 0.0}, 1), ExampleBedPose());
  EXPECT_EQ(exact.cell, Eigen::Vector2i(15, 7));  // one of the four cells at the centre
  // With 3 cm range noise the scores differ by millimetres, inside the tie tolerance: still the
  // middle (the four centre cells or their neighbours).
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const DumpPlan plan = planner.Plan(ScanMap(empty, {}, seed), ExampleBedPose());
    EXPECT_NEAR(plan.p_bed_dump.x(), 2.4, 0.225 + 1e-9) << seed;
    EXPECT_NEAR(plan.p_bed_dump.y(), 1.2, 0.225 + 1e-9) << seed;
    EXPECT_NEAR(plan.p_bed_dump.z(), 0.0, 0.03) << seed;
  }
}

TEST(DumpPlanner, HeapAtOneEndSendsTheLoadToTheLowestRegionAtTheOtherEnd) {
  const DumpPlannerConfig config;
  const DumpPlanner planner(config);
  for (const bool heap_in_front : {true, false}) {
    SCOPED_TRACE(heap_in_front);
    SimulatedBed sim(kExampleBed);
    sim.Pour({heap_in_front ? 0.9 : 3.9, 1.2}, 2.0);
    const DumpPlan plan = planner.Plan(ScanMap(sim, {}, 3), ExampleBedPose());
    // The heap's toe is near the middle of the bed; the load goes well beyond it, into the empty
    // half (not onto the toe, which the 7 x 7 template alone would rate as low as the rest).
    if (heap_in_front) {
      EXPECT_GT(plan.p_bed_dump.x(), 3.0);
    } else {
      EXPECT_LT(plan.p_bed_dump.x(), 1.8);
    }
    // Against the true surface: no allowed cell has a lower patch under the template (within
    // what 3 cm scan noise can hide).
    const double side = plan.template_size * 0.15;
    const double chosen = sim.MeanHeight(plan.p_bed_dump.head<2>(), side);
    double lowest = std::numeric_limits<double>::infinity();
    for (int ix = 0; ix < plan.feasible.rows(); ++ix) {
      for (int iy = 0; iy < plan.feasible.cols(); ++iy) {
        if (!plan.feasible(ix, iy)) continue;
        const Eigen::Vector2d c((ix + 0.5) * 0.15, (iy + 0.5) * 0.15);
        lowest = std::min(lowest, sim.MeanHeight(c, side));
      }
    }
    EXPECT_LE(chosen, lowest + 0.02);
    ExpectFootprintInside(plan, config);
  }
}

TEST(DumpPlanner, TheBucketFootprintStaysInsideTheWallsEvenWhenTheLowestSpotIsAgainstOne) {
  DumpPlannerConfig config;
  const DumpPlanner planner(config);
  SimulatedBed sim(kExampleBed);
  sim.Fill(0.5);
  sim.Dig({0.0, 0.0}, {0.6, 0.6}, 0.4);  // a low pocket in the corner at the origin
  const DumpPlan plan = planner.Plan(ScanMap(sim, {}, 4), ExampleBedPose());

  // Unconstrained, the template would pick a cell at the wall: the margin does the work here.
  Eigen::Index best_x = 0;
  Eigen::Index best_y = 0;
  plan.score_map.maxCoeff(&best_x, &best_y);
  EXPECT_FALSE(plan.feasible(best_x, best_y));
  EXPECT_TRUE(plan.feasible(plan.cell.x(), plan.cell.y()));
  ExpectFootprintInside(plan, config);
  // ... and the load still goes as near the pocket as the walls allow: the first allowed cell.
  EXPECT_NEAR(plan.p_bed_dump.x(), 0.825, 1e-9);  // 0.6 + 0.15 = 0.75, next centre 0.825
  EXPECT_NEAR(plan.p_bed_dump.y(), 0.675, 1e-9);  // 0.5 + 0.15 = 0.65, next centre 0.675
  EXPECT_TRUE(plan.score_map.allFinite());
  EXPECT_TRUE(plan.prepared_heights.allFinite());
}

TEST(DumpPlanner, DumpPointIsGivenInTheBedAndTheWorldFrame) {
  const DumpPlanner planner;
  SimulatedBed sim(kExampleBed);
  sim.Pour({1.2, 1.2}, 1.0);
  const Eigen::Isometry3d T_world_bed = ExampleBedPose();
  const DumpPlan plan = planner.Plan(ScanMap(sim, {}, 5), T_world_bed);
  EXPECT_TRUE(plan.p_world_dump.isApprox(T_world_bed * plan.p_bed_dump, 1e-12));
  EXPECT_TRUE((T_world_bed.inverse() * plan.p_world_dump).isApprox(plan.p_bed_dump, 1e-9));
  EXPECT_DOUBLE_EQ(plan.p_bed_dump.z(), plan.prepared_heights(plan.cell.x(), plan.cell.y()));
  EXPECT_DOUBLE_EQ(plan.score, plan.score_map(plan.cell.x(), plan.cell.y()));
  // The dump point sits on the scanned surface, not on the scanner's frame.
  EXPECT_NEAR(plan.p_bed_dump.z(), sim.Height(plan.p_bed_dump.head<2>()), 0.05);

  // The same scan taken with the bed elsewhere in the world plans the same cell.
  Eigen::Isometry3d moved = Eigen::Isometry3d::Identity();
  moved.translate(Eigen::Vector3d(-20, 3, 0.2));
  moved.rotate(Eigen::AngleAxisd(-2.0, Eigen::Vector3d::UnitZ()));
  std::mt19937 rng(5);
  const DumpPlan again = planner.Plan(
      BedHeightMap::FromWorldPoints(kExampleBed, moved, sim.Scan(moved, {}, rng)), moved);
  EXPECT_EQ(again.cell, plan.cell);
}

TEST(DumpPlanner, CellsHiddenByAWallAreFilledWithTheMeanOfTheSeenCells) {
  const DumpPlanner planner;
  SimulatedBed sim(kExampleBed);
  sim.Pour({2.4, 1.6}, 1.5);
  const BedHeightMap map = ScanMap(sim, {.occluded_y_m = 0.45}, 6);
  ASSERT_EQ(map.known_count(), 32 * 13);  // the three columns y < 0.45 m are unseen
  const DumpPlan plan = planner.Plan(map, ExampleBedPose());
  EXPECT_EQ(plan.known_cells, 32 * 13);
  EXPECT_EQ(plan.filled_cells, 32 * 3);
  const Eigen::MatrixXd smoothed =
      SmoothKnown(map.heights(), map.known_mask(), planner.config().smoothing_sigma_cells);
  const double seen_mean = KnownMean(smoothed, map.known_mask());
  for (int ix = 0; ix < 32; ++ix) {
    for (int iy = 0; iy < 3; ++iy) EXPECT_DOUBLE_EQ(plan.prepared_heights(ix, iy), seen_mean);
  }
  EXPECT_GT(seen_mean, 0.05);  // the heap shows: the unseen strip is not taken as empty
}

TEST(DumpPlanner, HoleTemplateFindsADepressionThatTheFlatTemplateIgnores) {
  // A bed filled higher toward the rear, with a small pit in the high part: the flat template
  // wants the low front, the hole template the pit.
  SimulatedBed sim(kExampleBed);
  sim.Fill(0.1);
  sim.Tilt(0.1);
  sim.Dig({3.15, 0.9}, {3.6, 1.5}, 0.25);
  const BedHeightMap map = ScanMap(sim, {.noise_m = 0.01}, 7);

  DumpPlannerConfig flat_config;
  const DumpPlan flat = DumpPlanner(flat_config).Plan(map, ExampleBedPose());
  EXPECT_LT(flat.p_bed_dump.x(), 1.2);

  DumpPlannerConfig hole_config;
  hole_config.shape = DumpTemplateShape::kHole;
  hole_config.template_size = 5;
  const DumpPlan hole = DumpPlanner(hole_config).Plan(map, ExampleBedPose());
  EXPECT_NEAR(hole.p_bed_dump.x(), 3.375, 0.15 + 1e-9);
  EXPECT_NEAR(hole.p_bed_dump.y(), 1.2, 0.15 + 1e-9);
  // The 0.25 m pit, narrower than the 3 × 3 inner block once smoothed, still scores well clear
  // of the plane's zero.
  EXPECT_GT(hole.score, 0.06);
}

TEST(DumpPlanner, TemplateSizeIsChosenFromTheBucketUnlessGiven) {
  DumpPlannerConfig config;
  config.footprint_along_bed_m = 0.7;
  config.footprint_across_bed_m = 0.6;
  EXPECT_EQ(DumpPlanner(config).TemplateSize(0.15), 5);
  config.footprint_along_bed_m = 1.2;
  EXPECT_EQ(DumpPlanner(config).TemplateSize(0.15), 7);
  config.template_size = 5;
  EXPECT_EQ(DumpPlanner(config).TemplateSize(0.15), 5);
  const DumpPlan plan = DumpPlanner(config).Plan(BedHeightMap(kExampleBed, 0.15), ExampleBedPose());
  EXPECT_EQ(plan.template_size, 5);
}

TEST(DumpPlanner, BadConfigurationAndInputAreRejectedWithAClearError) {
  const auto make = [](auto edit) {
    DumpPlannerConfig config;
    edit(config);
    return DumpPlanner(config);
  };
  EXPECT_THROW(make([](auto& c) { c.smoothing_sigma_cells = -1; }), std::invalid_argument);
  EXPECT_THROW(make([](auto& c) { c.smoothing_sigma_cells = kNaN; }), std::invalid_argument);
  EXPECT_THROW(make([](auto& c) { c.template_size = 6; }), std::invalid_argument);
  EXPECT_THROW(make([](auto& c) { c.template_size = 17; }), std::invalid_argument);
  EXPECT_THROW(make([](auto& c) { c.footprint_along_bed_m = 0; }), std::invalid_argument);
  EXPECT_THROW(make([](auto& c) { c.footprint_across_bed_m = kNaN; }), std::invalid_argument);
  EXPECT_THROW(make([](auto& c) { c.wall_margin_m = -0.1; }), std::invalid_argument);
  EXPECT_THROW(make([](auto& c) { c.tie_tolerance_m = kNaN; }), std::invalid_argument);

  const DumpPlanner planner;
  // A bed too small for the bucket and its margins.
  EXPECT_THROW(planner.Plan(BedHeightMap({1.2, 2.4}, 0.15), ExampleBedPose()),
               std::invalid_argument);
  Eigen::Isometry3d bad_pose = ExampleBedPose();
  bad_pose.linear()(0, 0) = kNaN;
  EXPECT_THROW(planner.Plan(BedHeightMap(kExampleBed, 0.15), bad_pose), std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::planning
