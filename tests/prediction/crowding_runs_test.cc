// Crowding runs on a dug face (a revisit, crowding_runs.h): the spec is the fresh run's with a
// cut added, the face the loader meets lies further in, and what the cut left stands no steeper
// than the material's angle of repose.
#include "identification/predictor/crowding_runs.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "generated/registry.h"

namespace autoshovel::predictor {
namespace {

model::MachineDescription Loader() {
  return model::LoadMachineDescription(model::ResolveMachineDescription(
      "xcmg_968ev", std::string(AUTOSHOVEL_SOURCE_DIR) + "/models"));
}

// The pushing scoop's regime (crowding_runs.h), as penetration_svr_push was trained.
CrowdingRunOptions PushingScoop() {
  CrowdingRunOptions options;
  options.scoop_deceleration = 0.3;
  options.min_speed = options.max_speed = 1.0;
  return options;
}

TEST(CrowdingRuns, DugFaceIsTheFreshPileCutBackToRepose) {
  const model::MachineDescription machine = Loader();
  const generated::MachineFunctions* functions = generated::FindMachine(machine.name);
  ASSERT_NE(functions, nullptr);
  CrowdingRunOptions fresh_options, dug_options;
  dug_options.dug_face_fraction = 1.0;

  // The first tall cone of seed 1: its face is the clearest to measure.
  int index = 0;
  while (!(DrawSpec(machine, fresh_options, 1, index).shape == "cone" &&
           DrawSpec(machine, fresh_options, 1, index).height > 2.5)) {
    ASSERT_LT(++index, 200);
  }
  const CrowdingRunSpec fresh = DrawSpec(machine, fresh_options, 1, index);
  const CrowdingRunSpec dug = DrawSpec(machine, dug_options, 1, index);
  EXPECT_EQ(fresh.dug_depth, 0.0);
  EXPECT_GE(dug.dug_depth, dug_options.min_dug_depth);
  EXPECT_LE(dug.dug_depth, dug_options.max_dug_depth);
  // Drawn after every other field: the fresh run's spec is unchanged (the shipped model's runs).
  EXPECT_EQ(dug.seed, fresh.seed);
  EXPECT_EQ(dug.shape, fresh.shape);
  EXPECT_EQ(dug.material, fresh.material);
  EXPECT_EQ(dug.height, fresh.height);
  EXPECT_EQ(dug.approach_speed, fresh.approach_speed);
  EXPECT_EQ(dug.trigger_volume, fresh.trigger_volume);

  const CrowdingRun fresh_run = RunCrowding(machine, *functions, fresh_options, fresh);
  const CrowdingRun dug_run = RunCrowding(machine, *functions, dug_options, dug);
  ASSERT_TRUE(fresh_run.ok) << fresh_run.failure;
  ASSERT_TRUE(dug_run.ok) << dug_run.failure;
  const double fresh_contact = fresh_run.past_path.front().x();
  const double dug_contact = dug_run.past_path.front().x();
  std::printf(
      "cut %.2f m: first contact at x = %.2f m (fresh %.2f m), payload %.2f m^3 (fresh "
      "%.2f m^3)\n",
      dug.dug_depth, dug_contact, fresh_contact, dug_run.payload, fresh_run.payload);
  // The face the bucket meets is the cut's: its foot stands where the cut ended.
  EXPECT_NEAR(dug_contact - fresh_contact, dug.dug_depth, 0.3);

  // No neighbour pair steeper than repose where the cut was (the pre-contact map the run kept).
  const prediction::HeightGrid& map = dug_run.map;
  const model::Material* material = machine.FindMaterial(dug.material);
  ASSERT_NE(material, nullptr);
  const double max_step = map.resolution * std::tan(material->angle_of_repose) + 2e-3;
  double steepest = 0;
  for (int iy = 0; iy + 1 < map.ny; ++iy) {
    for (int ix = 0; ix + 1 < map.nx; ++ix) {
      const Eigen::Vector2d c = map.CellCenter(ix, iy);
      if (std::abs(c.y()) > 0.5 * machine.bucket.width + 0.5) continue;
      steepest = std::max({steepest, std::abs(map.at(ix + 1, iy) - map.at(ix, iy)),
                           std::abs(map.at(ix, iy + 1) - map.at(ix, iy))});
    }
  }
  EXPECT_LE(steepest, max_step);
}

// A run under the pushing scoop records its travel after the trigger: from 0, every
// travel_sample_period, up to the penetration it reports (the largest travel), starting at the
// speed the features saw.
TEST(CrowdingRuns, RecordTheTravelAfterTheTrigger) {
  const model::MachineDescription machine = Loader();
  const generated::MachineFunctions* functions = generated::FindMachine(machine.name);
  ASSERT_NE(functions, nullptr);
  const CrowdingRunOptions options = PushingScoop();
  const CrowdingRun run =
      RunCrowding(machine, *functions, options, DrawSpec(machine, options, 1, 0));
  ASSERT_TRUE(run.ok) << run.failure;
  const std::vector<double>& s = run.travel_after_trigger;
  ASSERT_GE(s.size(), 10u);
  EXPECT_NEAR(s.front(), 0.0, 1e-12);
  // Sampled every 50 ms: the largest sample misses the stop by what the machine creeps in one.
  EXPECT_NEAR(*std::max_element(s.begin(), s.end()), run.penetration, 1e-3);
  // The machine at the trigger moves at the speed the features report.
  EXPECT_NEAR((s[1] - s[0]) / options.travel_sample_period, run.features.speed, 0.1);
}

// Why V2 needs a travel curve per pile (docs/scooping_control.md): on a tall gravel cone under
// the pushing scoop the machine loses speed as the curl loads the lip, and from 1 s on it is
// well behind a constant deceleration over the same penetration; it still ends at d.
TEST(CrowdingRuns, TallGravelConeLagsTheConstantDeceleration) {
  const model::MachineDescription machine = Loader();
  const generated::MachineFunctions* functions = generated::FindMachine(machine.name);
  ASSERT_NE(functions, nullptr);
  const CrowdingRunOptions options = PushingScoop();
  CrowdingRunSpec spec;
  spec.seed = 7;
  spec.shape = "cone";
  spec.material = "big_gravel";
  spec.height = 3.0;
  spec.approach_speed = 1.0;
  spec.trigger_volume = 0.1;
  const CrowdingRun run = RunCrowding(machine, *functions, options, spec);
  ASSERT_TRUE(run.ok) << run.failure;
  const double v = run.at_trigger.speed, d = run.penetration;
  std::printf("tall gravel cone: v %.2f m/s, d %.3f m, travel at 0.5..3 s:", v, d);
  for (int k = 1; k <= 6; ++k) std::printf(" %.2f", TravelAt(run, 0.5 * k));
  std::printf("\n");
  for (double t : {1.0, 1.5, 2.0, 2.5}) {
    const double constant = v * t - v * v * t * t / (4 * d);
    EXPECT_LT(TravelAt(run, t), constant - 0.05) << "t " << t;
  }
  EXPECT_NEAR(TravelAt(run, 10.0), d, 1e-3);
}

}  // namespace
}  // namespace autoshovel::predictor
