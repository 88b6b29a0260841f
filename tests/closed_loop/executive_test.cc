// The multi-rate executive: each task runs at its rate on the simulated clock, in order.
#include "runtime/app/executive.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

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

TEST(MultiRateExecutive, RefusesBadPeriods) {
  EXPECT_THROW(MultiRateExecutive(0.0), std::invalid_argument);
  MultiRateExecutive executive(0.01);
  EXPECT_THROW(executive.Add("too fast", 0.001, [](double) {}), std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::app
