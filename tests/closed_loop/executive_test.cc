// The multi-rate executive: each task runs at its rate on the simulated clock, in order.
#include "runtime/app/executive.h"

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "runtime/app/run_profile.h"

namespace autoshovel::app {
namespace {

// Over 10 simulated seconds: 100 Hz → 1000 calls, 20 Hz → 200, 7 Hz → 70 (1/7 s is not a
// multiple of 10 ms: the schedule must not drift, so exactly 70, each within 5 ms of k/7 s).
TEST(MultiRateExecutive, RunsEachTaskAtItsRateWithoutDrift) {
  MultiRateExecutive executive(0.01);
  std::vector<double> map_times;
  std::vector<std::string> order;
  executive.Add("control", 0.01, [&](double) { order.push_back("c"); });
  executive.Add("decisions", 1.0 / 20, [&](double) { order.push_back("d"); });
  executive.Add("map", 1.0 / 7, [&](double t) { map_times.push_back(t); });
  for (int i = 0; i < 1000; ++i) executive.Step();
  EXPECT_EQ(executive.Calls("control"), 1000);
  EXPECT_EQ(executive.Calls("decisions"), 200);
  EXPECT_EQ(executive.Calls("map"), 70);
  ASSERT_EQ(map_times.size(), 70u);
  for (std::size_t k = 0; k < map_times.size(); ++k) {
    EXPECT_NEAR(map_times[k], static_cast<double>(k) / 7.0, 0.005 + 1e-9) << k;
  }
  // Tasks due at the same instant run in the order added.
  ASSERT_GE(order.size(), 2u);
  EXPECT_EQ(order[0], "c");
  EXPECT_EQ(order[1], "d");
  EXPECT_NEAR(executive.now(), 10.0, 1e-9);
}

// The profile (run --profile): each task's wall time is its own, and it never moves the
// schedule. A task that sleeps 2 ms per call has at least calls × 2 ms; one that does nothing
// has far less.
TEST(MultiRateExecutive, TimesEachTaskWithoutChangingItsSchedule) {
  MultiRateExecutive executive(0.01);
  executive.Add("idle", 0.01, [](double) {});
  executive.Add("busy", 0.05,
                [](double) { std::this_thread::sleep_for(std::chrono::milliseconds(2)); });
  for (int i = 0; i < 100; ++i) executive.Step();
  EXPECT_EQ(executive.Calls("busy"), 20);
  EXPECT_GE(executive.Seconds("busy"), 20 * 0.002);
  EXPECT_LT(executive.Seconds("idle"), executive.Seconds("busy"));
  EXPECT_EQ(executive.Seconds("no such task"), 0.0);
}

TEST(RunProfile, AddsMergesAndKeepsItsOrder) {
  RunProfile a, b;
  a.Add("task map", 1.0, 7);
  a.Add("sensor simulation", 0.75, 7, 1);
  b.Add("sensor simulation", 0.25, 3, 1);
  b.Add("plant integration", 2.0, 100);
  a.Merge(b);
  ASSERT_EQ(a.entries().size(), 3u);
  EXPECT_EQ(a.entries()[1].name, "sensor simulation");
  EXPECT_EQ(a.entries()[1].calls, 10);
  EXPECT_DOUBLE_EQ(a.entries()[1].seconds, 1.0);
  EXPECT_EQ(a.entries()[1].depth, 1);
  EXPECT_EQ(a.entries()[2].name, "plant integration");
  const std::string table = a.Table(4.0);
  // 1 s of 4 s, 100 ms per call for the component (10 calls).
  EXPECT_NE(table.find("25.0 %"), std::string::npos) << table;
  EXPECT_NE(table.find("100.000"), std::string::npos) << table;
  EXPECT_EQ(a.Csv().substr(0, 26), "entry,depth,calls,seconds\n");
}

TEST(MultiRateExecutive, RefusesBadPeriods) {
  EXPECT_THROW(MultiRateExecutive(0.0), std::invalid_argument);
  MultiRateExecutive executive(0.01);
  EXPECT_THROW(executive.Add("too fast", 0.001, [](double) {}), std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::app
