// Loading a truck "evenly and completely" (excavator seed §4.3): successive loads poured where
// the planner says, each planned on a fresh noisy scan of the simulated bed, against the naive
// strategy of always dumping at the bed's centre. Prints the fill figures of
// docs/dump_planning.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "runtime/planning/dump/dump_planner.h"
#include "runtime/planning/dump/fill_summary.h"
#include "truck_bed_sim.h"

namespace autoshovel::planning {
namespace {

using dump_sim::ExampleBedPose;
using dump_sim::kExampleBed;
using dump_sim::ScanConfig;
using dump_sim::SimulatedBed;

constexpr int kPasses = 6;
constexpr double kBucketVolume = 1.0;  // m³ per load: 6 loads ≈ 0.52 m over the 11.5 m² bed

struct LoadingRun {
  std::vector<double> std_after_pass;  ///< true fill std after each pass [m]
  double max_height_m = 0;
  double volume_m3 = 0;
  std::vector<Eigen::Vector2d> dumps;  ///< bed-frame dump points
};

enum class Strategy {
  kCentre,        ///< every load at the bed centre
  kPlanner,       ///< DumpPlanner on a fresh scan after each load
  kGreedyOracle,  ///< knows the true surface and tries pouring at every other allowed cell
  kFixedPattern,  ///< 2 rows × 3 columns over the allowed area, laid out knowing there are 6
};

double TrueStd(const SimulatedBed& sim) { return SummarizeFill(sim.Truth(), 0.0).std_height_m; }

// The cell whose simulated pour leaves the flattest true surface (a one-step look-ahead that no
// real planner has: it sees through occlusion and noise and knows how soil settles). Every other
// allowed cell, to keep the test fast.
Eigen::Vector2d GreedyOracleTarget(const SimulatedBed& sim, const DumpPlanner& planner) {
  const BedHeightMap grid(kExampleBed, 0.15);
  const CellMask allowed = planner.FeasibleCells(grid);
  double best_std = std::numeric_limits<double>::infinity();
  Eigen::Vector2d best = grid.CellCentre(grid.cells_x() / 2, grid.cells_y() / 2);
  for (int ix = 0; ix < grid.cells_x(); ix += 2) {
    for (int iy = 0; iy < grid.cells_y(); iy += 2) {
      if (!allowed(ix, iy)) continue;
      SimulatedBed trial = sim;
      trial.Pour(grid.CellCentre(ix, iy), kBucketVolume);
      const double trial_std = TrueStd(trial);
      if (trial_std < best_std) {
        best_std = trial_std;
        best = grid.CellCentre(ix, iy);
      }
    }
  }
  return best;
}

// Pours kPasses loads by `strategy`, each planner decision on a scan taken after the previous
// load. The bucket lands with 5 cm (1σ) of scatter about its target.
LoadingRun Load(Strategy strategy, const DumpPlanner& planner, const ScanConfig& scan,
                unsigned seed) {
  SimulatedBed sim(kExampleBed);
  std::mt19937 rng(seed);
  std::normal_distribution<double> placement(0.0, 0.05);
  const Eigen::Isometry3d T_world_bed = ExampleBedPose();
  const BedHeightMap grid(kExampleBed, 0.15);
  LoadingRun run;
  for (int pass = 0; pass < kPasses; ++pass) {
    Eigen::Vector2d target(0.5 * kExampleBed.length_m, 0.5 * kExampleBed.width_m);
    if (strategy == Strategy::kPlanner) {
      const BedHeightMap map =
          BedHeightMap::FromWorldPoints(kExampleBed, T_world_bed, sim.Scan(T_world_bed, scan, rng));
      target = planner.Plan(map, T_world_bed).p_bed_dump.head<2>();
    } else if (strategy == Strategy::kGreedyOracle) {
      target = GreedyOracleTarget(sim, planner);
    } else if (strategy == Strategy::kFixedPattern) {
      // The allowed area's corners and edge midpoints for the default 1.2 m x 1.0 m bucket.
      target = grid.CellCentre(pass % 3 == 0 ? 5 : (pass % 3 == 1 ? 15 : 26), pass < 3 ? 4 : 11);
    }
    run.dumps.push_back(target);
    sim.Pour(target + Eigen::Vector2d(placement(rng), placement(rng)), kBucketVolume);
    run.std_after_pass.push_back(TrueStd(sim));
  }
  const FillSummary final_fill = SummarizeFill(sim.Truth(), 0.0);
  run.max_height_m = final_fill.max_height_m;
  run.volume_m3 = sim.Volume();
  return run;
}

void Print(const char* name, const LoadingRun& run) {
  std::printf("[ fill     ] %-28s std after passes 1..%d [m]:", name, kPasses);
  for (const double s : run.std_after_pass) std::printf(" %.3f", s);
  std::printf("  max %.2f m  volume %.2f m3\n[ fill     ] %-28s dumps (x, y) [m]:",
              run.max_height_m, run.volume_m3, name);
  for (const Eigen::Vector2d& d : run.dumps) std::printf(" (%.2f, %.2f)", d.x(), d.y());
  std::printf("\n");
}

TEST(FillSimulation, PlannedDumpsFillTheBedEvenlyAndFarBetterThanCentreDumping) {
  const DumpPlanner planner;
  const LoadingRun centre = Load(Strategy::kCentre, planner, {}, 11);
  const LoadingRun planned = Load(Strategy::kPlanner, planner, {}, 11);
  const LoadingRun occluded = Load(Strategy::kPlanner, planner, {.occluded_y_m = 0.45}, 11);
  const LoadingRun blind = Load(Strategy::kPlanner, planner, {.occluded_y_m = 0.9}, 11);
  const LoadingRun oracle = Load(Strategy::kGreedyOracle, planner, {}, 11);
  const LoadingRun pattern = Load(Strategy::kFixedPattern, planner, {}, 11);
  Print("centre every time", centre);
  Print("template planner", planned);
  Print("planner, 0.45 m strip hidden", occluded);
  Print("planner, 0.9 m strip hidden", blind);
  Print("greedy oracle (true surface)", oracle);
  Print("fixed 2 x 3 pattern", pattern);

  // The heap model conserves soil: both runs put the same volume in the bed.
  EXPECT_NEAR(centre.volume_m3, kPasses * kBucketVolume, 1e-6);
  EXPECT_NEAR(planned.volume_m3, kPasses * kBucketVolume, 1e-6);

  const double planned_std = planned.std_after_pass.back();
  const double centre_std = centre.std_after_pass.back();
  // Bounds from the measured figures (docs/dump_planning.md), with a margin: over seeds 1 to 10
  // the planner's std after 6 passes is 0.225 to 0.254 m (next test).
  EXPECT_LT(planned_std, 0.27);
  EXPECT_LT(planned_std, 0.6 * centre_std);
  EXPECT_LT(occluded.std_after_pass.back(), 0.27);
  EXPECT_LT(occluded.std_after_pass.back(), 0.6 * centre_std);
  // With 3/8 of the bed never seen the mean fill hides the near side's lows: less even, still
  // far better than the centre.
  EXPECT_LT(blind.std_after_pass.back(), 0.75 * centre_std);
  // As even as a look-ahead that sees the true surface and simulates every pour.
  EXPECT_LT(planned_std, oracle.std_after_pass.back() + 0.02);
  // No load twice on the same spot: the planner moves with the fill.
  for (std::size_t a = 0; a < planned.dumps.size(); ++a) {
    for (std::size_t b = a + 1; b < planned.dumps.size(); ++b) {
      EXPECT_GT((planned.dumps[a] - planned.dumps[b]).norm(), 0.3) << a << ", " << b;
    }
  }
}

TEST(FillSimulation, TheFigureHoldsOverScanNoiseAndPlacementSeeds) {
  const DumpPlanner planner;
  double sum = 0;
  double lowest = std::numeric_limits<double>::infinity();
  double highest = 0;
  constexpr int kSeeds = 10;
  for (unsigned seed = 1; seed <= kSeeds; ++seed) {
    const double fill_std = Load(Strategy::kPlanner, planner, {}, seed).std_after_pass.back();
    sum += fill_std;
    lowest = std::min(lowest, fill_std);
    highest = std::max(highest, fill_std);
  }
  // Centre dumping does not depend on the scan; its placement scatter barely moves its std.
  const double centre_std = Load(Strategy::kCentre, planner, {}, 1).std_after_pass.back();
  std::printf(
      "[ fill     ] planner over seeds 1..%d: std after %d passes min %.3f mean %.3f max "
      "%.3f m (centre %.3f m)\n",
      kSeeds, kPasses, lowest, sum / kSeeds, highest, centre_std);
  EXPECT_LT(highest, 0.27);
  EXPECT_LT(sum / kSeeds, 0.55 * centre_std);
}

}  // namespace
}  // namespace autoshovel::planning
