// Dubins paths (dubins_path.h) against closed-form lengths, and their geometry against their
// curvature bound.
#include "runtime/planning/dubins_path.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace autoshovel::planning {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(DubinsPath, ClosedFormLengths) {
  const double kappa = 0.2, r = 1 / kappa;
  // Straight ahead: a straight line.
  EXPECT_NEAR(ShortestDubinsPath({{0, 0}, 0}, {{10, 0}, 0}, kappa).length(), 10.0, 1e-9);
  // A quarter turn to the left onto the circle's end: a quarter of the circumference.
  EXPECT_NEAR(ShortestDubinsPath({{0, 0}, 0}, {{r, r}, kPi / 2}, kappa).length(), kPi * r / 2,
              1e-9);
  // A U-turn to the right: half the circumference.
  EXPECT_NEAR(ShortestDubinsPath({{0, 0}, 0}, {{0, -2 * r}, kPi}, kappa).length(), kPi * r, 1e-9);
  // A quarter turn then a straight: L then S of 3 m.
  const DubinsPath ls = ShortestDubinsPath({{0, 0}, 0}, {{r, r + 3}, kPi / 2}, kappa);
  EXPECT_NEAR(ls.length(), kPi * r / 2 + 3, 1e-9);
  // Straight, then a quarter turn right: 4 m then πr/2.
  EXPECT_NEAR(ShortestDubinsPath({{0, 0}, 0}, {{4 + r, -r}, -kPi / 2}, kappa).length(),
              4 + kPi * r / 2, 1e-9);
  // Same pose: nothing to drive.
  EXPECT_NEAR(ShortestDubinsPath({{1, 2}, 0.3}, {{1, 2}, 0.3}, kappa).length(), 0.0, 1e-9);
}

TEST(DubinsPath, EveryWordEndsAtTheGoalWithinTheCurvatureBound) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> xy(-20, 20), angle(-kPi, kPi);
  const double kappa = 0.215;
  int words = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Pose2 start{{xy(rng), xy(rng)}, angle(rng)}, goal{{xy(rng), xy(rng)}, angle(rng)};
    const std::vector<DubinsPath> paths = AllDubinsPaths(start, goal, kappa);
    ASSERT_FALSE(paths.empty());
    for (std::size_t k = 1; k < paths.size(); ++k) {
      EXPECT_LE(paths[0].length(), paths[k].length());
    }
    for (const DubinsPath& path : paths) {
      ++words;
      const Pose2 end = path.At(path.length());
      EXPECT_NEAR((end.xy - goal.xy).norm(), 0.0, 1e-6) << ToString(path.word);
      EXPECT_NEAR(std::remainder(end.heading - goal.heading, 2 * kPi), 0.0, 1e-6);
      const std::vector<PathSample> samples = SamplePath(path, 0.25);
      ASSERT_GE(samples.size(), 1u);
      EXPECT_NEAR(samples.back().s, path.length(), 1e-9);
      for (std::size_t k = 0; k < samples.size(); ++k) {
        EXPECT_LE(std::abs(samples[k].curvature), kappa + 1e-12);
        if (k == 0) continue;
        // The geometry honours the bound: heading change ≤ κmax Δs, chord ≤ Δs.
        const double ds = samples[k].s - samples[k - 1].s;
        const double dpsi = std::remainder(samples[k].heading - samples[k - 1].heading, 2 * kPi);
        EXPECT_LE(std::abs(dpsi), kappa * ds + 1e-9);
        EXPECT_LE((samples[k].xy - samples[k - 1].xy).norm(), ds + 1e-9);
        EXPECT_LE(ds, 0.25 + 1e-12);
      }
    }
  }
  EXPECT_GT(words, 600);  // most poses have four or more admissible words
}

TEST(DubinsPath, RejectsBadInput) {
  EXPECT_THROW(AllDubinsPaths({}, {{1, 0}, 0}, 0.0), std::invalid_argument);
  EXPECT_THROW(AllDubinsPaths({{NAN, 0}, 0}, {{1, 0}, 0}, 0.2), std::invalid_argument);
  EXPECT_THROW(SamplePath(ShortestDubinsPath({}, {{1, 0}, 0}, 0.2), 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::planning
