// Deterministic cycle records and scratch folders for the results tests.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "runtime/results/results_db.h"

namespace autoshovel::results::testing {

/// The folder holding every ScratchDir of this test process.
inline std::filesystem::path ScratchRoot() {
  return std::filesystem::path(::testing::TempDir()) /
         ("autoshovel_results_" + std::to_string(::getpid()));
}

/// Removes ScratchRoot() after the tests when they all passed (kept for a look otherwise).
class RemoveScratchWhenPassed : public ::testing::Environment {
 public:
  void TearDown() override {
    if (!::testing::UnitTest::GetInstance()->Failed()) std::filesystem::remove_all(ScratchRoot());
  }
};

/// A fresh, empty folder for one test, removed first if a previous run left it.
inline std::filesystem::path ScratchDir(const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path dir =
      ScratchRoot() / (std::string(info->test_suite_name()) + "." + info->name() +
                       (name.empty() ? "" : "." + name));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline RunInfo TestRun(const std::string& run_id = "run-1") {
  RunInfo run;
  run.run_id = run_id;
  run.scenario = "yard_small";
  run.machine = "loader_20t";
  run.seed = 42;
  run.cycles_planned = 10;
  run.start_time_utc = "2025-06-01T12:00:00.000Z";
  run.git_describe = "v0.1.0-12-gabcdef";
  return run;
}

/// Sample k of cycle c: every value a function of (c, k), awkward enough to catch rounding.
inline CycleSample TestSample(int c, int k) {
  CycleSample s;
  s.t = 0.05 * k + c / 3.0;
  s.v1 = std::sqrt(1.0 + k) / 7.0;
  s.v1v2 = s.v1 + 1e-300 * (c + 1);
  s.triggered = k > 40;
  s.predicted_tip_x = 1.0 / (3.0 + k) + c;
  s.predicted_tip_z = -0.1 * k + M_PI;
  s.actual_tip_x = std::exp(-0.01 * k) * 2.5;
  s.actual_tip_z = 1e10 / (k + 7) - c;
  return s;
}

inline CycleRecord TestRecord(int c, int samples) {
  CycleRecord r;
  r.cycle = c;
  r.scenario = "yard_small";
  r.machine = "loader_20t";
  r.bin = "pile_" + std::to_string(c % 2);
  r.material = c % 2 == 0 ? "gravel" : "river_sand";
  r.strategy = c % 3 == 0 ? "pressure_stairway3" : "prediction";
  r.atomic_actions = "lift,tilt,lift";
  r.trigger_time_s = 2.0 + c / 7.0;
  r.fill_rate = 0.9 + 0.01 * c;
  r.payload_m3 = 3.0 * r.fill_rate;
  r.time_s = {1.5 + c, 2.25, 1.0 / 3.0, 0.7, 1.9, 8.0 + c};
  r.energy_kj = {40.0, 120.5 + c, 80.125, 10.0, 35.0, 300.0 + c};
  r.safety_margin_m = 1.25 - 0.01 * c;
  r.safety_violations = 0;
  r.completed = true;
  for (int k = 0; k < samples; ++k) r.samples.push_back(TestSample(c, k));
  return r;
}

/// Equal, with NaN equal to NaN.
inline bool Same(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

inline void ExpectSameRecord(const CycleRecord& a, const CycleRecord& b) {
  EXPECT_EQ(a.cycle, b.cycle);
  EXPECT_EQ(a.scenario, b.scenario);
  EXPECT_EQ(a.machine, b.machine);
  EXPECT_EQ(a.bin, b.bin);
  EXPECT_EQ(a.material, b.material);
  EXPECT_EQ(a.strategy, b.strategy);
  EXPECT_EQ(a.atomic_actions, b.atomic_actions);
  EXPECT_TRUE(Same(a.trigger_time_s, b.trigger_time_s));
  EXPECT_TRUE(Same(a.fill_rate, b.fill_rate));
  EXPECT_TRUE(Same(a.payload_m3, b.payload_m3));
  for (const auto& [x, y] : {std::pair{a.time_s, b.time_s}, std::pair{a.energy_kj, b.energy_kj}}) {
    EXPECT_TRUE(Same(x.approach, y.approach));
    EXPECT_TRUE(Same(x.crowd, y.crowd));
    EXPECT_TRUE(Same(x.scoop, y.scoop));
    EXPECT_TRUE(Same(x.level, y.level));
    EXPECT_TRUE(Same(x.retreat, y.retreat));
    EXPECT_TRUE(Same(x.total, y.total));
  }
  EXPECT_TRUE(Same(a.safety_margin_m, b.safety_margin_m));
  EXPECT_EQ(a.safety_violations, b.safety_violations);
  EXPECT_EQ(a.completed, b.completed);
  ASSERT_EQ(a.samples.size(), b.samples.size());
  for (std::size_t k = 0; k < a.samples.size(); ++k) {
    const CycleSample& s = a.samples[k];
    const CycleSample& t = b.samples[k];
    EXPECT_TRUE(Same(s.t, t.t) && Same(s.v1, t.v1) && Same(s.v1v2, t.v1v2) &&
                s.triggered == t.triggered && Same(s.predicted_tip_x, t.predicted_tip_x) &&
                Same(s.predicted_tip_z, t.predicted_tip_z) &&
                Same(s.actual_tip_x, t.actual_tip_x) && Same(s.actual_tip_z, t.actual_tip_z))
        << "sample " << k;
  }
}

}  // namespace autoshovel::results::testing
