// The five scores of the wheel-loader seed's §5 (Eq. 12–18) on hand-computed maps, the loader
// geometry, and Chen et al. (2024)'s indicators.
#include "runtime/planning/shovel_point_selection.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "generated/registry.h"
#include "runtime/model/description.h"
#include "runtime/perception/semantic_map.h"
#include "runtime/planning/chen2024_baseline.h"

namespace autoshovel::planning {
namespace {

using perception::CellClass;
using perception::GridMap;
using perception::Index;

constexpr double kPi = std::numbers::pi;
const std::string kModels = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";

// A level ground map (z = 0, class ground everywhere).
GridMap FlatMap(double resolution, double length, const Eigen::Vector2d& centre) {
  GridMap map(resolution, {length, length}, centre);
  map.Add("elevation", 0.0f);
  map.Add("class", static_cast<float>(CellClass::kGround));
  return map;
}

void SetPile(GridMap& map, const Eigen::Vector2d& xy, double height) {
  Index i;
  ASSERT_TRUE(map.IndexOf(xy, i));
  map.at("elevation", i) = static_cast<float>(height);
  map.at("class", i) = static_cast<float>(CellClass::kPile);
}

const Eigen::Vector3d kLevel(0, 0, 0);

// A loader of the XCMG's proportions, written out so the tests' numbers can be checked by hand.
LoaderGeometry XcmgLikeLoader() {
  LoaderGeometry loader;
  loader.hinge_to_front_axle = loader.hinge_to_rear_axle = 1.6;
  loader.max_articulation = 38 * kPi / 180;
  loader.track_width = 2.25;
  loader.wheel_radius = 0.8;
  loader.bucket_width = 3.0;
  loader.rated_capacity = 3.5;
  loader.tip_reach = 4.5;
  return loader;
}

TEST(LoaderGeometry, MaxCurvatureFromTheArticulationLimit) {
  const model::MachineDescription machine =
      model::LoadMachineDescription(model::ResolveMachineDescription("xcmg_968ev", kModels));
  const LoaderGeometry g = LoaderGeometryFrom(machine, *generated::FindMachine(machine.name));
  // l_f = l_r = 1.6 m, γmax = 38°: κmax = sin 38° / (1.6 cos 38° + 1.6) = 0.2152 1/m.
  const double gamma = 38 * kPi / 180;
  EXPECT_NEAR(g.MaxCurvature(), std::sin(gamma) / (1.6 * std::cos(gamma) + 1.6), 1e-12);
  EXPECT_NEAR(g.MaxCurvature(), 0.2152, 1e-4);
  EXPECT_NEAR(g.ArticulationFor(g.MaxCurvature()), gamma, 1e-12);
  EXPECT_NEAR(g.ArticulationFor(-0.1), -g.ArticulationFor(0.1), 1e-12);
  EXPECT_EQ(g.ArticulationFor(0.0), 0.0);
  // The tip reaches well beyond the front axle with the bucket on the floor.
  EXPECT_GT(g.tip_reach, g.hinge_to_front_axle + 1.0);
  EXPECT_LT(g.tip_reach, 8.0);
}

// Eq. (12)–(13): cells at (1, 1) [2 m high] and (1.5, −0.5) [1 m] of a 0.5 m grid, the bucket
// (3 m wide, 2 m deep) entering at the origin heading +x: T_c = (2·1 + 1·(−0.5))·0.25 m⁴.
TEST(ShovelScores, TorqueBalanceByHand) {
  GridMap map = FlatMap(0.5, 20, {0.25, 0.25});  // cell centres on multiples of 0.5 m
  SetPile(map, {1.0, 1.0}, 2.0);
  SetPile(map, {1.5, -0.5}, 1.0);
  EXPECT_NEAR(TorqueMoment(map, kLevel, {0, 0}, 0.0, 3.0, 2.0), 0.375, 1e-12);
  // Heading +y: (1, 1) lies 1 m to the right (λ = −1); (1.5, −0.5) is behind the bucket.
  EXPECT_NEAR(TorqueMoment(map, kLevel, {0, 0}, kPi / 2, 3.0, 2.0), -0.5, 1e-12);
  // Heights are taken above the ground plane: lift the plane by 0.5 m.
  EXPECT_NEAR(TorqueMoment(map, Eigen::Vector3d(0, 0, 0.5), {0, 0}, 0.0, 3.0, 2.0),
              (1.5 * 1.0 + 0.5 * -0.5) * 0.25, 1e-12);
  const double t_res = 2.625;  // V_rated · w / 4 for 3.5 m³, 3 m
  EXPECT_NEAR(TorqueScore(0.375, t_res), 1 - std::pow(0.375 / t_res, 2), 1e-12);
  EXPECT_EQ(TorqueScore(0.0, t_res), 1.0);
  EXPECT_EQ(TorqueScore(3.0, t_res), kMinusInfinity);
  EXPECT_EQ(TorqueScore(-3.0, t_res), kMinusInfinity);  // |T_c|: right-heavy is as bad
}

TEST(ShovelScores, SafetyDistanceEq14) {
  EXPECT_EQ(SafetyScore(2.0, 1.0), 1.0);
  EXPECT_NEAR(SafetyScore(0.4, 1.0), 0.4, 1e-12);
  EXPECT_EQ(SafetyScore(0.0, 1.0), kMinusInfinity);
  EXPECT_EQ(SafetyScore(-0.3, 1.0), kMinusInfinity);
}

// Eq. (15) on a 0.25 m grid: the 3 m bucket spans 12 cells across, four per section.
TEST(ShovelScores, ConcavityThreeSectionsByHand) {
  auto face = [](auto height) {
    GridMap map = FlatMap(0.25, 20, {0, 0});  // centres at ±0.125 + k·0.25
    for (perception::GridMapIterator it(map); !it.done(); ++it) {
      const Eigen::Vector2d p = map.PositionOf(*it);
      if (std::abs(p.x()) < 5 && std::abs(p.y()) < 5) {
        map.at("elevation", *it) = static_cast<float>(height(p.y()));
        map.at("class", *it) = static_cast<float>(CellClass::kPile);
      }
    }
    return map;
  };
  // Entering at (0.125, 0) heading +x, 1.875 m deep from half a cell behind the entry: x from
  // 0 to 2 m, 8 cells along, 4 across per section.
  const Eigen::Vector2d entry(0.125, 0);
  const GridMap flat = face([](double) { return 1.0; });
  const SectionVolumes v = ConcavityVolumes(flat, kLevel, entry, 0.0, 3.0, 1.875);
  EXPECT_NEAR(v.left, 8 * 4 * 0.0625, 1e-12);  // 2 m³ each
  EXPECT_NEAR(v.middle, 2.0, 1e-12);
  EXPECT_NEAR(v.right, 2.0, 1e-12);
  EXPECT_EQ(ConcavityScore(v), 1.0);  // a flat face: V_m = max(V_l, V_r), convex by "≥"
  const GridMap ridge = face([](double y) { return 2.0 - std::abs(y); });
  EXPECT_EQ(ConcavityScore(ConcavityVolumes(ridge, kLevel, entry, 0.0, 3.0, 1.875)), 1.0);
  const GridMap gully = face([](double y) { return 0.5 + std::abs(y); });
  const SectionVolumes g = ConcavityVolumes(gully, kLevel, entry, 0.0, 3.0, 1.875);
  EXPECT_LT(g.middle, g.left);
  EXPECT_EQ(ConcavityScore(g), 0.0);  // concave: the seed scores it 0
  // Only one side higher than the middle is enough to be concave.
  EXPECT_EQ(ConcavityScore({1.0, 0.9, 0.2}), 0.0);
  // Within the map-noise tolerance a face is flat, hence convex; beyond it, concave.
  EXPECT_EQ(ConcavityScore({1.0, 0.96, 0.2}, 0.05), 1.0);
  EXPECT_EQ(ConcavityScore({1.0, 0.94, 0.2}, 0.05), 0.0);
  EXPECT_EQ(ConcavityScore({0.2, 0.96, 1.0}, 0.05), 1.0);
  EXPECT_EQ(ConcavityScore({1.0, 0.96, 0.2}), 0.0);  // the seed's exact "≥"
}

// Cells count by their share of area in Ω: on the main job's 0.3 m grid, the 1 m sections of a
// 3 m bucket do not fall on cell edges. A level face 1 m high must give three equal sections
// and Ω's exact area, wherever the entry lies and whatever the heading; counted by centres,
// the sections held 3 or 4 cells each and a straight pile front was "concave" everywhere.
TEST(ShovelScores, ConcavitySectionsCountCellsByArea) {
  GridMap map = FlatMap(0.3, 20, {0, 0});
  for (perception::GridMapIterator it(map); !it.done(); ++it) {
    map.at("elevation", *it) = 1.0f;
    map.at("class", *it) = static_cast<float>(CellClass::kPile);
  }
  const double width = 3.0, length = 2.0;
  for (const Eigen::Vector2d& entry :
       {Eigen::Vector2d(0.15, 0.15), Eigen::Vector2d(0.07, -0.21), Eigen::Vector2d(-0.4, 0.33)}) {
    for (const double heading : {0.0, 0.3, kPi / 2, -2.0}) {
      const SectionVolumes v = ConcavityVolumes(map, kLevel, entry, heading, width, length);
      const double section = width / 3 * (length + 0.15);  // from half a cell behind the entry
      EXPECT_NEAR(v.left, section, 1e-9) << entry.transpose() << " at " << heading;
      EXPECT_NEAR(v.middle, section, 1e-9) << entry.transpose() << " at " << heading;
      EXPECT_NEAR(v.right, section, 1e-9) << entry.transpose() << " at " << heading;
      // A level face is balanced: Eq. (12)'s first moment vanishes.
      EXPECT_NEAR(TorqueMoment(map, kLevel, entry, heading, width, length), 0.0, 1e-9);
    }
  }
}

TEST(ShovelScores, EfficiencyEntryAngleAndWeights) {
  EXPECT_EQ(EfficiencyScore(10, 10, 20), 1.0);
  EXPECT_EQ(EfficiencyScore(20, 10, 20), 0.0);
  EXPECT_NEAR(EfficiencyScore(15, 10, 20), 0.5, 1e-12);
  EXPECT_EQ(EfficiencyScore(12, 12, 12), 1.0);
  EXPECT_EQ(EntryAngleScore(0.0, 0.2), 1.0);
  EXPECT_NEAR(EntryAngleScore(-0.1, 0.2), 0.5, 1e-12);
  EXPECT_NEAR(EntryAngleScore(0.2, 0.2), 0.0, 1e-12);
  ShovelPointConfig config;
  ScoreBreakdown s;
  s.s_t = s.s_s = s.s_c = s.s_e = s.s_a = 1.0;
  EXPECT_NEAR(WeightedScore(s, config), 1.0, 1e-12);  // Table 1's weights sum to one
  s.s_t = 0.5, s.s_c = 0.0;
  EXPECT_NEAR(WeightedScore(s, config), 1.0 - 0.29 * 0.5 - 0.13, 1e-12);
  s.s_s = kMinusInfinity;
  EXPECT_EQ(WeightedScore(s, config), kMinusInfinity);
}

TEST(ShovelScores, EntryCurvatureIsTheMeanOverTheWindow) {
  // A 4 m straight then 2 m of left arc at 0.2 1/m: over the last 3 m, (1·0 + 2·0.2)/3.
  DubinsPath path;
  path.word = DubinsWord::kLSL;
  path.radius = 5;
  path.lengths = {0.0, 4.0, 2.0};
  const std::vector<PathSample> samples = SamplePath(path, 0.25);
  EXPECT_NEAR(EntryCurvature(samples, 3.0), 0.4 / 3, 1e-9);
  EXPECT_NEAR(EntryCurvature(samples, 1.0), 0.2, 1e-9);
  EXPECT_NEAR(EntryCurvature(samples, 100.0), 0.4 / 6, 1e-9);
}

TEST(ShovelScores, ObstacleDistanceFieldAndSweptDistance) {
  GridMap map = FlatMap(0.3, 30, {0.15, 0.15});  // centres on multiples of 0.3 m
  Index obstacle;
  ASSERT_TRUE(map.IndexOf({6.0, 3.0}, obstacle));
  map.at("class", obstacle) = static_cast<float>(CellClass::kObstacle);
  const Eigen::MatrixXf field = ObstacleDistanceField(map);
  Index i;
  ASSERT_TRUE(map.IndexOf({0.0, 3.0}, i));
  EXPECT_NEAR(field(i.x(), i.y()), 6.0, 1e-5);
  ASSERT_TRUE(map.IndexOf({3.0, -1.0 + 0.0}, i));
  EXPECT_NEAR(field(i.x(), i.y()), (map.PositionOf(i) - map.PositionOf(obstacle)).norm(), 1e-5);
  // A loader driving along y = 0 past it: the body's side (half width hw) passes 3 m − hw from
  // the obstacle cell's centre, less the half cell the obstacle fills.
  const LoaderGeometry loader = XcmgLikeLoader();
  DubinsPath straight = ShortestDubinsPath({{-10, 0}, 0}, {{20, 0}, 0}, 0.2);
  const double d = SweptObstacleDistance(map, field, SamplePath(straight, 0.25), loader);
  const double exact = 3.0 - loader.HalfWidth() - 0.15;
  EXPECT_LE(d, exact + 1e-6);  // conservative
  EXPECT_GT(d, exact - 0.15);  // by less than half a cell
  // Without obstacles, +inf everywhere.
  const GridMap empty = FlatMap(0.3, 10, {0, 0});
  EXPECT_TRUE(std::isinf(ObstacleDistanceField(empty)(3, 3)));
}

// Eq. (14)'s A covers the scoop too: driving on into the pile brings the whole body alongside
// an obstacle beside the lane, unless an obstacle straight ahead ends the crowd first (the
// main job's look-ahead stops it `crowd_stop_distance` short), so what lies past there is
// never reached.
TEST(ShovelScores, ScoopSideClearanceDrivesOnUntilTheCrowdWouldStop) {
  GridMap map = FlatMap(0.3, 39, {0.15, 0.15});
  Index beside, ahead;
  ASSERT_TRUE(map.IndexOf({8.1, 3.0}, beside));
  ASSERT_NEAR(map.PositionOf(beside).y(), 3.0, 1e-9);
  map.at("class", beside) = static_cast<float>(CellClass::kObstacle);
  const LoaderGeometry loader = XcmgLikeLoader();
  const Eigen::MatrixXf field = ObstacleDistanceField(map);
  // Contact with the front axle at the origin heading +x: hinge at −1.6, front edge at 3.2.
  const Pose2 contact{{0, 0}, 0};
  const double exact_beside = 3.0 - loader.HalfWidth() - 0.15;
  // Without driving on, the cell is 4.8 m ahead of the front edge's end, far beyond d_res.
  EXPECT_TRUE(std::isinf(ScoopSideClearance(map, field, contact, loader, 0.0, 0.25, 0.0)));
  // Driving 6 m on with nothing ahead: the front edge reaches x = 9.2, so the side passes the
  // cell at x = 8.1, 3 − hw from its centre.
  const double d6 = ScoopSideClearance(map, field, contact, loader, 6.0, 0.25, 1.45);
  EXPECT_LE(d6, exact_beside + 1e-6);
  EXPECT_GT(d6, exact_beside - 0.15);
  // A wall straight ahead across the lane, its face at x = 6.2: the crowd stops with the front
  // edge's middle 1.45 m from it (front edge at x ≤ 4.75 + one step), well short of x = 8.1.
  for (double y = -2.1; y <= 2.1; y += 0.3) {
    ASSERT_TRUE(map.IndexOf({6.35, y}, ahead));
    map.at("class", ahead) = static_cast<float>(CellClass::kObstacle);
  }
  const Eigen::MatrixXf field2 = ObstacleDistanceField(map);
  const double stop = 1.45, spacing = 0.25;
  const double d = ScoopSideClearance(map, field2, contact, loader, 6.0, spacing, stop);
  // The wall decides: the last step driven kept at least `stop` to it (less the field's
  // half-cell conservatism), the next would not have, so no more than `stop` + a step.
  EXPECT_GT(d, stop - 0.15);
  EXPECT_LE(d, stop + spacing + 1e-6);
  EXPECT_GT(d, exact_beside);
  // Without the stop the body would run into that wall, as SweptObstacleDistance says too.
  EXPECT_LE(ScoopSideClearance(map, field2, contact, loader, 6.0, spacing, 0.0), 0.0);
  std::vector<PathSample> straight;
  for (int k = 0; k <= 24; ++k) straight.push_back({0.25 * k, {0.25 * k, 0.0}, 0.0, 0.0});
  EXPECT_LE(SweptObstacleDistance(map, field2, straight, loader), 0.0);
}

// The body is a rectangle up to its corners: an obstacle off the front corner, diagonally
// ahead, is as far as the corner, not as far as a rounded nose would be.
TEST(ShovelScores, SweptDistanceCoversTheFrontCorners) {
  GridMap map = FlatMap(0.1, 30, {0.05, 0.05});
  const LoaderGeometry loader = XcmgLikeLoader();
  const double hw = loader.HalfWidth();
  // One pose: front axle at the origin heading +x, so the hinge is at x = −1.6 and the front
  // corner at (−1.6 + 4.5 + 0.3, hw). A cell 0.6 m beyond the corner on both axes.
  const Eigen::Vector2d corner(-1.6 + loader.tip_reach + loader.body_margin, hw);
  Index obstacle;
  ASSERT_TRUE(map.IndexOf(corner + Eigen::Vector2d(0.6, 0.6), obstacle));
  map.at("class", obstacle) = static_cast<float>(CellClass::kObstacle);
  const Eigen::MatrixXf field = ObstacleDistanceField(map);
  const std::vector<PathSample> pose = {{0.0, {0, 0}, 0.0, 0.0}};
  const double exact = (map.PositionOf(obstacle) - corner).norm() - 0.05;
  const double d = SweptObstacleDistance(map, field, pose, loader);
  EXPECT_LE(d, exact + 1e-6);  // never beyond the true clearance of the corner
  EXPECT_GT(d, exact - 0.2);   // conservative by less than the discs' overshoot and a cell
}

// Chen et al. (2024) baseline: a plane rising 0.5 m per metre towards +x.
TEST(Chen2024Baseline, IndicatorsOnAPlaneAndARidge) {
  GridMap map = FlatMap(0.25, 20, {0, 0});
  for (perception::GridMapIterator it(map); !it.done(); ++it) {
    const Eigen::Vector2d p = map.PositionOf(*it);
    map.at("elevation", *it) = static_cast<float>(3.0 + 0.5 * p.x());
    map.at("class", *it) = static_cast<float>(CellClass::kPile);
  }
  CandidatePose pose;
  pose.entry_heading = 0;
  Chen2024Indicators c = Chen2024IndicatorsAt(map, kLevel, pose, {-10, 0});
  EXPECT_NEAR(c.inclination, 1.0, 1e-6);
  EXPECT_NEAR(c.slope, std::atan(0.5), 1e-6);
  EXPECT_NEAR(c.convexity, 0.0, 1e-6);
  EXPECT_NEAR(c.distance, 10.0, 1e-12);
  pose.entry_heading = kPi / 2;  // along the contour lines
  EXPECT_NEAR(Chen2024IndicatorsAt(map, kLevel, pose, {-10, 0}).inclination, 0.0, 1e-6);
  // A ridge along x (h = 3 − 0.4 y²): convexity across the bucket 0.8 1/m.
  for (perception::GridMapIterator it(map); !it.done(); ++it) {
    const Eigen::Vector2d p = map.PositionOf(*it);
    map.at("elevation", *it) = static_cast<float>(3.0 - 0.4 * p.y() * p.y());
  }
  pose.entry_heading = 0;
  EXPECT_NEAR(Chen2024IndicatorsAt(map, kLevel, pose, {-10, 0}).convexity, 0.8, 1e-4);
}

TEST(ShovelPointConfig, ValidateNamesTheProblem) {
  ShovelPointConfig config;
  EXPECT_EQ(config.Validate(), "");
  config.safety_distance = 0;
  EXPECT_NE(config.Validate().find("d_res"), std::string::npos);
  config = {};
  config.k_e = -1;
  EXPECT_NE(config.Validate().find("k_e"), std::string::npos);
  config = {};
  config.entry_angle_offsets = {2.0};
  EXPECT_NE(config.Validate().find("entry_angle_offsets"), std::string::npos);
  config = {};
  config.scoop_advance = std::nan("");
  EXPECT_NE(config.Validate().find("scoop_advance"), std::string::npos);
  config = {};
  config.concavity_tolerance = std::nan("");
  EXPECT_NE(config.Validate().find("concavity_tolerance"), std::string::npos);
}

}  // namespace
}  // namespace autoshovel::planning
