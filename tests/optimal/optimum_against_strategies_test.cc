// The optimal scoop against the strategies in the closed loop: from a strategy's own contact on
// the same pile, at its fill and within its time, the optimum never costs more than the
// strategy did (issue 41, item 6).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "runtime/app/shovel_run.h"
#include "runtime/optimal/scoop_ocp.h"

namespace autoshovel::optimal {
namespace {

struct Case {
  const char* bin;
  control::ScoopPolicy policy;
};

class OptimumAgainstStrategy : public ::testing::TestWithParam<Case> {};

TEST_P(OptimumAgainstStrategy, NeverCostsMoreAtEqualFillAndTime) {
  app::ShovelRunOptions o;
  o.scenario = "mixing_station";
  o.bins = {GetParam().bin};
  o.models_dir = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";
  o.truth_labels = true;
  o.cycles = 1;
  o.figures = false;
  o.policy = GetParam().policy;
  o.seed = 1;
  app::ShovelJob job(o);
  const app::CycleOutcome out = job.RunCycle(0, {}, nullptr);
  ASSERT_TRUE(out.record.completed) << out.failure;
  const app::ContactSnapshot& c = out.contact;
  ASSERT_TRUE(c.valid);
  const model::Material* material = job.machine().FindMaterial(c.material);
  ASSERT_NE(material, nullptr);
  const ScoopModel model(job.machine(), *material,
                         PileProfile(c.profile_start, c.profile_spacing, c.profile_heights));
  ScoopOcpOptions options;
  options.target_volume = std::min(out.record.payload_m3, 0.97 * model.heaped_capacity());
  options.max_time = out.record.time_s.crowd + out.record.time_s.scoop;
  ScoopOcp ocp(model, options);
  ScoopStart start;
  start.speed = c.speed;
  start.q = c.q;
  start.volume = c.payload_volume;
  const ScoopOcpSolution best = ocp.Solve(start);
  const double strategy_kj = out.record.energy_kj.crowd + out.record.energy_kj.scoop;
  std::printf(
      "[optimum] %s %s: strategy %.1f kJ in %.2f s (%.2f m3); optimum %.1f kJ in %.2f s "
      "(%.2f m3), %d iterations, %.1f s\n",
      GetParam().bin, out.record.strategy.c_str(), strategy_kj, options.max_time,
      out.record.payload_m3, best.energy / 1e3, best.time, best.volume, best.iterations,
      best.solve_seconds);
  ASSERT_TRUE(best.ok) << best.status << "; worst: " << best.worst_constraint;
  EXPECT_GE(best.volume, options.target_volume - 1e-6);
  EXPECT_LE(best.time, options.max_time + 1e-6);
  EXPECT_LE(best.energy / 1e3, strategy_kj);
}

INSTANTIATE_TEST_SUITE_P(MixingStation, OptimumAgainstStrategy,
                         ::testing::Values(Case{"bin_1", control::ScoopPolicy::kJustInOut},
                                           Case{"bin_4", control::ScoopPolicy::kAutoSelection}),
                         [](const auto& param_info) {
                           return std::string(param_info.param.bin) +
                                  (param_info.param.policy == control::ScoopPolicy::kJustInOut
                                       ? "_just_in_out"
                                       : "_auto");
                         });

}  // namespace
}  // namespace autoshovel::optimal

namespace autoshovel::optimal {
namespace {

// ScoopPolicy::kOptimal in the closed loop: the plan made at contact on the map's pile, tracked
// by the speed and joint PIDs through the valves' delays in the plant. The plant is not the
// smooth model (its terrain is a height grid that relaxes, its valves lag, its bucket spills).
// What holds: the cycle completes safely as "optimal" and the bucket ends with at least 80 %
// of the planned volume (measured at 630bcc5: 3.42 m³ against 3.40 planned; after a change of
// rounding order only, the optimiser settles in a neighbouring optimum and the plant ends with
// 2.87 m³). What does not yet: the plant's energy is 2–2.6 times the plan's (583 against
// 299 kJ, then 808 against 310 kJ), so it is printed, not held (docs/optimal_scoop.md).
TEST(OptimalPolicy, TrackedPlanDeliversWhatItPlanned) {
  app::ShovelRunOptions o;
  o.scenario = "mixing_station";
  o.bins = {"bin_1"};
  o.models_dir = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";
  o.truth_labels = true;
  o.cycles = 1;
  o.figures = false;
  o.policy = control::ScoopPolicy::kOptimal;
  o.seed = 1;
  app::ShovelJob job(o);
  const app::CycleOutcome out = job.RunCycle(0, {}, nullptr);
  ASSERT_TRUE(out.record.completed) << out.failure;
  const control::ScoopResult& r = out.scoop;
  EXPECT_EQ(out.record.strategy, "optimal");
  ASSERT_TRUE(std::isfinite(r.planned_energy));
  const double delivered_kj = out.record.energy_kj.crowd + out.record.energy_kj.scoop;
  std::printf(
      "[optimal policy] planned %.1f kJ, %.2f m3 (solve %.1f s); plant %.1f kJ, "
      "%.2f m3 after the scoop, %.2f m3 at the end, %.2f s contact to scoop end\n",
      r.planned_energy / 1e3, r.planned_volume, r.plan_solve_seconds, delivered_kj,
      r.payload_after_scoop, out.record.payload_m3,
      out.record.time_s.crowd + out.record.time_s.scoop);
  EXPECT_GE(out.record.payload_m3, 0.8 * r.planned_volume);
  EXPECT_GT(delivered_kj, 0.0);
  EXPECT_EQ(out.record.safety_violations, 0);
}

}  // namespace
}  // namespace autoshovel::optimal
