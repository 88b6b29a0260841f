// Truck recognition end to end (excavator seed §4.1) on simulated pans of the left scanner:
// three truck sizes at random poses with range noise and dropouts, scenes without a truck, and
// bad input. The recogniser sees only the scanlines; the truth stays in the test.
//
// The figures in docs/truck_recognition.md are the summary lines these tests print:
//   ./build-truck/truck_recognition_tests --gtest_filter='TruckRecognition*'
#include "runtime/perception/truck/truck_recognition.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "truck_test_scenes.h"

namespace autoshovel::perception {
namespace {

using truck_sim::MakeNegativeScene;
using truck_sim::MakeTruckScene;
using truck_sim::NegativeKind;
using truck_sim::Rng;
using truck_sim::SceneOptions;
using truck_sim::TestScene;
using truck_sim::TruckSpec;
using truck_sim::TruckTruth;

// Acceptance (the issue's): position within 10 cm, yaw within 2°, in every trial. Dimensions:
// in the sweep below (2700 truck scenes) the largest errors were about 0.13 m in length (an
// unseen tailgate adds its thickness; scanline spacing at the ends), 0.03 m in width (nominal
// wall thickness) and 0.05 m in rim, wall and floor height; the bounds sit just above those.
constexpr double kMaxPositionError = 0.10;  // [m]
constexpr double kMaxYawErrorDeg = 2.0;
constexpr double kMaxLengthError = 0.15;  // [m]
constexpr double kMaxWidthError = 0.05;   // [m]
constexpr double kMaxRimError = 0.06;     // [m]
constexpr double kMaxHeightError = 0.08;  // wall and floor heights, when the floor is seen [m]
constexpr double kMaxCornerError = 0.15;  // [m]

struct Errors {
  double position = 0;  // plan distance of the bed centre [m]
  double yaw_deg = 0;
  double length = 0;
  double width = 0;
  double rim = 0;
  double corner = 0;  // largest of the four
};

Errors Compare(const TruckRecognitionResult& r, const TruckTruth& t) {
  Errors e;
  e.position =
      (r.T_world_bed.translation().head<2>() - t.T_world_bed.translation().head<2>()).norm();
  e.yaw_deg = std::abs(std::remainder(r.YawRad() - t.yaw_rad, 2 * std::numbers::pi)) * 180 /
              std::numbers::pi;
  e.length = std::abs(r.dimensions.length - t.length);
  e.width = std::abs(r.dimensions.width - t.width);
  e.rim = std::abs(r.T_world_bed.translation().z() - t.rim_height);
  for (int i = 0; i < 4; ++i) {
    e.corner = std::max(e.corner, (r.p_world_corners[i] - t.p_world_corners[i]).norm());
  }
  return e;
}

struct Timer {
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  double Ms() const {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
  }
};

// Runs `trials` random scenes of one truck size, checks every result against the acceptance
// bounds and prints one summary line.
void RunSizeTrials(const TruckSpec& spec, unsigned seed, int trials) {
  const TruckRecognizer recognizer;
  Rng rng(seed);
  int found = 0;
  int floor_seen = 0;
  Errors max;
  Errors sum;
  double ms_sum = 0;
  double ms_max = 0;
  long nodes_sum = 0;
  long nodes_max = 0;
  int complete_max = 0;
  for (int trial = 0; trial < trials; ++trial) {
    const TestScene scene = MakeTruckScene(spec, rng);
    const std::vector<Scanline> scan = SimulateScan(scene.scene, scene.scanner, rng);
    const Timer timer;
    const TruckRecognitionResult r = recognizer.Recognize(scan);
    const double ms = timer.Ms();
    ms_sum += ms;
    ms_max = std::max(ms_max, ms);
    nodes_sum += r.tree_nodes;
    nodes_max = std::max(nodes_max, r.tree_nodes);
    complete_max = std::max(complete_max, r.interpretations_complete);
    const TruckTruth& t = *scene.truth;
    SCOPED_TRACE(spec.name + ", seed " + std::to_string(seed) + ", trial " + std::to_string(trial));
    EXPECT_TRUE(r.found) << r.reason;
    if (!r.found) continue;
    ++found;
    const Errors e = Compare(r, t);
    EXPECT_LE(e.position, kMaxPositionError);
    EXPECT_LE(e.yaw_deg, kMaxYawErrorDeg);
    EXPECT_LE(e.length, kMaxLengthError);
    EXPECT_LE(e.width, kMaxWidthError);
    EXPECT_LE(e.rim, kMaxRimError);
    EXPECT_LE(e.corner, kMaxCornerError);
    EXPECT_NEAR(r.dimensions.rim_height, t.rim_height, kMaxRimError);
    if (std::isfinite(r.dimensions.wall_height)) {
      ++floor_seen;
      EXPECT_NEAR(r.dimensions.wall_height, t.wall_height, kMaxHeightError);
      EXPECT_NEAR(r.dimensions.floor_height, t.floor_height, kMaxHeightError);
    }
    EXPECT_GE(r.interpretation[BedFace::kNearSide], 0);
    EXPECT_GE(r.interpretation[BedFace::kFarSide], 0);
    for (const auto& [m, v] : {std::pair{&max.position, e.position},
                               {&max.yaw_deg, e.yaw_deg},
                               {&max.length, e.length},
                               {&max.width, e.width},
                               {&max.rim, e.rim},
                               {&max.corner, e.corner}}) {
      *m = std::max(*m, v);
    }
    sum.position += e.position;
    sum.yaw_deg += e.yaw_deg;
    sum.length += e.length;
  }
  const double n = std::max(found, 1);
  std::printf(
      "[ summary  ] %s (seed %u): found %d/%d; position error mean %.3f max %.3f m; yaw error "
      "mean %.2f max %.2f deg; length error mean %.3f max %.3f m; width max %.3f m; rim max "
      "%.3f m; corner max %.3f m; floor seen %d/%d; %.1f ms per recognition (max %.1f); tree "
      "nodes mean %.0f max %ld; complete interpretations per scene max %d\n",
      spec.name.c_str(), seed, found, trials, sum.position / n, max.position, sum.yaw_deg / n,
      max.yaw_deg, sum.length / n, max.length, max.width, max.rim, max.corner, floor_seen, trials,
      ms_sum / trials, ms_max, static_cast<double>(nodes_sum) / trials, nodes_max, complete_max);
}

// Runs `trials` random scenes without a truck, expects "no truck" in each and prints a summary.
void RunNegativeTrials(NegativeKind kind, unsigned seed, int trials) {
  const TruckRecognizer recognizer;
  Rng rng(seed);
  int found = 0;
  int reached_verification = 0;
  for (int trial = 0; trial < trials; ++trial) {
    const TestScene scene = MakeNegativeScene(kind, rng);
    const TruckRecognitionResult r =
        recognizer.Recognize(SimulateScan(scene.scene, scene.scanner, rng));
    EXPECT_FALSE(r.found) << NegativeKindName(kind) << ", seed " << seed << ", trial " << trial;
    EXPECT_FALSE(r.reason.empty());
    found += r.found;
    reached_verification += r.interpretations_complete > 0;
  }
  std::printf(
      "[ summary  ] %s (seed %u): truck reported in %d/%d scenes; %d of them reached "
      "verification\n",
      std::string(NegativeKindName(kind)).c_str(), seed, found, trials, reached_verification);
}

struct SizeCase {
  const char* name;
  TruckSpec (*spec)();
  unsigned seed;
};

constexpr SizeCase kSizes[] = {{"Tipper15t", &truck_sim::Tipper15t, 101},
                               {"Tipper20t", &truck_sim::Tipper20t, 202},
                               {"Hauler38t", &truck_sim::Hauler38t, 303}};

class TruckRecognitionSizes : public ::testing::TestWithParam<SizeCase> {};

TEST_P(TruckRecognitionSizes, FindsTheBedAtRandomPosesWithNoise) {
  RunSizeTrials(GetParam().spec(), GetParam().seed, 60);
}

INSTANTIATE_TEST_SUITE_P(, TruckRecognitionSizes, ::testing::ValuesIn(kSizes),
                         [](const auto& test_info) { return std::string(test_info.param.name); });

class TruckRecognitionNegatives : public ::testing::TestWithParam<NegativeKind> {};

TEST_P(TruckRecognitionNegatives, ReportsNoTruckWhereThereIsNone) {
  RunNegativeTrials(GetParam(), 1000 + static_cast<unsigned>(GetParam()), 30);
}

INSTANTIATE_TEST_SUITE_P(, TruckRecognitionNegatives,
                         ::testing::ValuesIn(truck_sim::kAllNegativeKinds),
                         [](const auto& test_info) {
                           std::string name(NegativeKindName(test_info.param));
                           std::erase(name, ' ');
                           return name;
                         });

// The long run behind the bounds above (about a minute; disabled, so not part of ctest). Run it
// with --gtest_also_run_disabled_tests --gtest_filter='TruckRecognitionSweep.*'.
TEST(TruckRecognitionSweep, DISABLED_ThreeSeedsOfThreeHundredScenes) {
  for (unsigned seed : {11u, 12u, 13u}) {
    for (const SizeCase& size : kSizes) RunSizeTrials(size.spec(), seed * 10 + size.seed, 300);
    for (NegativeKind kind : truck_sim::kAllNegativeKinds) {
      RunNegativeTrials(kind, seed * 100 + static_cast<unsigned>(kind), 300);
    }
  }
  // Beyond the design point, reported rather than checked: 1.5° between scanlines (a 30°/s pan
  // at 20 mirror revolutions per second) and 0.6° between beams.
  SceneOptions coarse;
  coarse.pan_step_deg = 1.5;
  coarse.elevation_step_deg = 0.6;
  const TruckRecognizer recognizer;
  for (const SizeCase& size : kSizes) {
    Rng rng(size.seed + 7);
    int found = 0;
    int within = 0;
    for (int trial = 0; trial < 100; ++trial) {
      const TestScene scene = MakeTruckScene(size.spec(), rng, coarse);
      const TruckRecognitionResult r =
          recognizer.Recognize(SimulateScan(scene.scene, scene.scanner, rng));
      if (!r.found) continue;
      ++found;
      const Errors e = Compare(r, *scene.truth);
      within += e.position <= kMaxPositionError && e.yaw_deg <= kMaxYawErrorDeg;
    }
    std::printf(
        "[ summary  ] %s, 1.5 deg pan and 0.6 deg beam steps: found %d/100, %d of them "
        "within 10 cm and 2 deg\n",
        size.name, found, within);
  }
}

TEST(TruckRecognition, LowScannerSaysNoTruckRatherThanAWrongOne) {
  // Scanner 3.5–4 m up, the hauler's rim 3.5 m: the far wall and floor are mostly out of sight.
  // Recognition may fail; it must not report a wrong bed.
  constexpr int kTrials = 30;
  SceneOptions options;
  options.sensor_height_min = 3.5;
  options.sensor_height_max = 4.0;
  const TruckRecognizer recognizer;
  Rng rng(404);
  int found = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    const TestScene scene = MakeTruckScene(truck_sim::Hauler38t(), rng, options);
    const TruckRecognitionResult r =
        recognizer.Recognize(SimulateScan(scene.scene, scene.scanner, rng));
    if (!r.found) continue;
    ++found;
    const Errors e = Compare(r, *scene.truth);
    EXPECT_LE(e.position, kMaxPositionError) << "trial " << trial;
    EXPECT_LE(e.yaw_deg, kMaxYawErrorDeg) << "trial " << trial;
  }
  std::printf("[ summary  ] 38 t hauler, scanner 3.5-4.0 m: found %d/%d, all of them right\n",
              found, kTrials);
}

TEST(TruckRecognition, CoarserPanStepsStillGiveTheBedWithinTheBounds) {
  // 1° between scanlines instead of 0.6° (a faster pan): fewer returns on each face and coarser
  // end positions. A truck may now be missed, rarely; whatever is reported must be right.
  constexpr int kTrials = 30;
  SceneOptions options;
  options.pan_step_deg = 1.0;
  const TruckRecognizer recognizer;
  Rng rng(505);
  for (const SizeCase& size : kSizes) {
    const TruckSpec spec = size.spec();
    int found = 0;
    double max_position = 0;
    for (int trial = 0; trial < kTrials; ++trial) {
      const TestScene scene = MakeTruckScene(spec, rng, options);
      const TruckRecognitionResult r =
          recognizer.Recognize(SimulateScan(scene.scene, scene.scanner, rng));
      if (!r.found) continue;
      ++found;
      const Errors e = Compare(r, *scene.truth);
      EXPECT_LE(e.position, kMaxPositionError) << spec.name << " trial " << trial;
      EXPECT_LE(e.yaw_deg, kMaxYawErrorDeg) << spec.name << " trial " << trial;
      max_position = std::max(max_position, e.position);
    }
    EXPECT_GE(found, kTrials - 2) << spec.name;
    std::printf("[ summary  ] %s, 1.0 deg pan steps: found %d/%d, position error max %.3f m\n",
                spec.name.c_str(), found, kTrials, max_position);
  }
}

TEST(TruckRecognition, BedFramesFollowTheCorners) {
  Rng rng(7);
  const TestScene scene = MakeTruckScene(truck_sim::Tipper20t(), rng);
  const TruckRecognitionResult r =
      TruckRecognizer().Recognize(SimulateScan(scene.scene, scene.scanner, rng));
  ASSERT_TRUE(r.found) << r.reason;
  const double L = r.dimensions.length;
  const double W = r.dimensions.width;
  // Corners: front-left, front-right, rear-right, rear-left in the bed frame.
  EXPECT_LT(
      (r.T_world_bed.inverse() * r.p_world_corners[0] - Eigen::Vector3d(L / 2, W / 2, 0)).norm(),
      1e-9);
  // The dump planner's frame: the rear-right corner, the opening spans [0, L] × [0, W].
  EXPECT_LT((r.T_world_bed_corner().translation() - r.p_world_corners[2]).norm(), 1e-9);
  EXPECT_LT((r.T_world_bed_corner() * Eigen::Vector3d(L, W, 0) - r.p_world_corners[0]).norm(),
            1e-9);
  EXPECT_NEAR(r.T_world_bed.linear().col(2).z(), 1.0, 1e-12);
  EXPECT_GT(r.support_points, 0);
  EXPECT_GT(r.tree_nodes, 0);
}

TEST(TruckRecognition, CorruptReturnsAreSkipped) {
  // Returns flagged valid but NaN or infinite (a driver fault) and a run of dropouts must not
  // reach any fit.
  Rng rng(8);
  const TestScene scene = MakeTruckScene(truck_sim::Tipper15t(), rng);
  std::vector<Scanline> scan = SimulateScan(scene.scene, scene.scanner, rng);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < scan.size(); ++i) {
    std::vector<ScanPoint>& points = scan[i].points;
    points[(7 * i) % points.size()] = {Eigen::Vector3d(nan, 1, 1), true};
    points[(13 * i + 5) % points.size()] = {Eigen::Vector3d(1, inf, 1), true};
  }
  const TruckRecognitionResult r = TruckRecognizer().Recognize(scan);
  ASSERT_TRUE(r.found) << r.reason;
  EXPECT_TRUE(r.T_world_bed.matrix().allFinite());
  const Errors e = Compare(r, *scene.truth);
  EXPECT_LE(e.position, kMaxPositionError);
  EXPECT_LE(e.yaw_deg, kMaxYawErrorDeg);
}

TEST(TruckRecognition, EmptyOrBadInput) {
  const TruckRecognizer recognizer;
  const TruckRecognitionResult empty = recognizer.Recognize({});
  EXPECT_FALSE(empty.found);
  EXPECT_FALSE(empty.reason.empty());
  EXPECT_EQ(empty.num_segments, 0);

  Scanline line;
  line.p_world_sensor = Eigen::Vector3d(0, std::numeric_limits<double>::infinity(), 4);
  line.points.push_back({Eigen::Vector3d(5, 0, 0), true});
  EXPECT_THROW(recognizer.Recognize({line}), std::invalid_argument);

  TruckRecognitionParams params;
  params.model.inner_length = {8, 3};
  EXPECT_THROW(TruckRecognizer{params}, std::invalid_argument);
  params = {};
  params.verification.max_ground_contact = 2;
  EXPECT_THROW(TruckRecognizer{params}, std::invalid_argument);
  params = {};
  params.tree.max_nodes = 0;
  EXPECT_THROW(TruckRecognizer{params}, std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::perception
