// Algorithm 2 on the simulated yards (maps rasterised from the simulator's truth, so that the
// tests are about selection, not perception), the obstacle checks against the true obstacle
// boxes, determinism, and the Fig. 19 picture through RunSelect.
#include "runtime/sim/select_command.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <sstream>

#include "generated/registry.h"
#include "runtime/model/description.h"
#include "runtime/perception/semantic_map.h"
#include "runtime/planning/chen2024_baseline.h"
#include "runtime/planning/shovel_point_selection.h"
#include "runtime/plant/scenario.h"

namespace autoshovel::planning {
namespace {

using perception::CellClass;

const std::string kModels = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";

struct Yard {
  plant::Scenario scenario;
  model::MachineDescription machine;
  LoaderGeometry loader;
  perception::GridMap map;
  std::vector<perception::ExtractedPile> piles;
  Pose2 start;
  Eigen::Vector3d plane = Eigen::Vector3d::Zero();

  explicit Yard(const std::string& name) {
    scenario = plant::LoadScenario(plant::ResolveScenario(name, kModels));
    machine =
        model::LoadMachineDescription(model::ResolveMachineDescription(scenario.machine, kModels));
    loader = LoaderGeometryFrom(machine, *generated::FindMachine(machine.name));
    map = sim::TruthMap(scenario);
    piles = perception::ExtractPiles(map, plane);
    start = {{scenario.start.x, scenario.start.y}, scenario.start.heading};
  }
  ShovelPointResult Select(const ShovelPointConfig& config = {}) const {
    return SelectShovelPoints(map, piles, plane, start, loader, config);
  }
};

// Distance from a world point to an obstacle box's footprint (0 inside).
double DistanceToBox(const plant::OrientedBox& box, const Eigen::Vector2d& xy) {
  const Eigen::Vector2d d = xy - box.center.head<2>();
  const double c = std::cos(box.yaw), s = std::sin(box.yaw);
  const double along = std::max(std::abs(c * d.x() + s * d.y()) - box.half_extents.x(), 0.0);
  const double across = std::max(std::abs(-s * d.x() + c * d.y()) - box.half_extents.y(), 0.0);
  return std::hypot(along, across);
}

// Independent of the planner's discs and distance field: the least distance between the true
// obstacle boxes and the loader's bare body (no margin) along the path: points every 0.1 m on
// the outlines of the front frame (hinge to tip) and the rear frame (to the counterweight).
double TrueClearance(const Yard& yard, const ShovelCandidate& c) {
  const LoaderGeometry& g = yard.loader;
  const double hw = g.HalfWidth() - g.body_margin;
  double clearance = 1e9;
  for (const PathSample& p : SamplePath(c.path, 0.25)) {
    const double gamma = g.ArticulationFor(p.curvature);
    const Eigen::Vector2d uf(std::cos(p.heading), std::sin(p.heading));
    const Eigen::Vector2d ur(std::cos(p.heading - gamma), std::sin(p.heading - gamma));
    const Eigen::Vector2d hinge = p.xy - g.hinge_to_front_axle * uf;
    auto outline = [&](const Eigen::Vector2d& u, double from, double to) {
      const Eigen::Vector2d v(-u.y(), u.x());
      for (double a = from; a <= to + 1e-9; a += 0.1) {
        for (const double l : {-hw, hw}) {
          for (const plant::OrientedBox& box : yard.scenario.world.obstacles) {
            clearance = std::min(clearance, DistanceToBox(box, hinge + a * u + l * v));
          }
        }
      }
      for (double l = -hw; l <= hw + 1e-9; l += 0.1) {
        for (const double a : {from, to}) {
          for (const plant::OrientedBox& box : yard.scenario.world.obstacles) {
            clearance = std::min(clearance, DistanceToBox(box, hinge + a * u + l * v));
          }
        }
      }
    };
    outline(uf, 0.0, g.tip_reach);
    outline(ur, -(g.hinge_to_rear_axle + g.rear_overhang), 0.0);
  }
  return clearance;
}

TEST(ShovelPointSelection, ConePileBestFacesTheLoader) {
  const Yard yard("cone_pile");
  ASSERT_EQ(yard.piles.size(), 1u);
  const ShovelPointResult result = yard.Select();
  ASSERT_EQ(result.status, SelectionStatus::kSelected) << result.message;
  const ShovelCandidate& best = *result.best();
  const Eigen::Vector2d apex(25, 20), loader(12, 20);
  std::printf(
      "cone: %s; best (%.2f, %.2f) heading %.1f deg, F %.3f (s_t %.3f s_s %.2f s_c %.0f "
      "s_e %.2f s_a %.2f), path %.2f m %s\n",
      result.message.c_str(), best.pose.xy.x(), best.pose.xy.y(),
      best.pose.entry_heading * 180 / std::numbers::pi, best.score, best.scores.s_t,
      best.scores.s_s, best.scores.s_c, best.scores.s_e, best.scores.s_a, best.scores.path_length,
      std::string(ToString(best.path.word)).c_str());
  // On the loader's side of the cone, heading into it from there.
  EXPECT_LT((best.pose.xy - loader).norm(), (apex - loader).norm());
  EXPECT_LT(best.pose.xy.x(), apex.x() - 2.0);
  EXPECT_GT(std::cos(best.pose.entry_heading), 0.7);
  // The ranking is sorted and Eq. (18) holds for every feasible candidate.
  for (std::size_t k = 0; k < result.ranked.size(); ++k) {
    const ShovelCandidate& c = result.ranked[k];
    if (k > 0 && c.feasible) {
      EXPECT_LE(c.score, result.ranked[k - 1].score);
    }
    if (!c.feasible) continue;
    EXPECT_NEAR(c.score, WeightedScore(c.scores, ShovelPointConfig{}), 1e-12);
    EXPECT_GE(c.scores.s_e, 0.0);
    EXPECT_LE(c.scores.s_e, 1.0);
    EXPECT_GE(c.scores.s_a, 0.0);
    // The path ends where the bucket tip meets the pile, heading δ_m.
    const Pose2 end = c.path.At(c.path.length());
    EXPECT_NEAR((end.xy - c.front_axle_goal.xy).norm(), 0.0, 1e-6);
  }
  // The shortest approach of all is on the loader's side.
  const ShovelCandidate* shortest = nullptr;
  for (const ShovelCandidate& c : result.ranked) {
    if (c.feasible && (!shortest || c.scores.path_length < shortest->scores.path_length)) {
      shortest = &c;
    }
  }
  ASSERT_NE(shortest, nullptr);
  EXPECT_LT(shortest->pose.xy.x(), apex.x() - 2.0);
  EXPECT_EQ(shortest->scores.s_e, 1.0);
}

// A wall between the loader and the cone: candidates whose body would touch it are infeasible;
// one within d_res scores d_min/d_res.
TEST(ShovelPointSelection, ObstaclesVetoOrPenaliseCandidates) {
  Yard yard("cone_pile");
  const ShovelPointResult before = yard.Select();
  ASSERT_EQ(before.status, SelectionStatus::kSelected);
  const ShovelCandidate best = *before.best();
  // An obstacle cell beside the bucket of the best candidate at the end of its path (1 m
  // behind the tip, 1.2 m left of the centre line: inside the 1.8 m half width).
  const Eigen::Vector2d u(std::cos(best.pose.entry_heading), std::sin(best.pose.entry_heading));
  perception::Index i;
  ASSERT_TRUE(yard.map.IndexOf(best.pose.xy - 1.0 * u + 1.2 * Eigen::Vector2d(-u.y(), u.x()), i));
  yard.map.at("class", i) = static_cast<float>(CellClass::kObstacle);
  const ShovelPointResult after = yard.Select();
  ASSERT_EQ(after.status, SelectionStatus::kSelected) << after.message;
  bool found = false;
  for (const ShovelCandidate& c : after.ranked) {
    if ((c.pose.xy - best.pose.xy).norm() < 1e-9 &&
        std::abs(c.pose.entry_heading - best.pose.entry_heading) < 1e-12) {
      found = true;
      EXPECT_FALSE(c.feasible);
      EXPECT_EQ(c.scores.s_s, kMinusInfinity);
      EXPECT_EQ(c.score, kMinusInfinity);
      EXPECT_EQ(c.infeasible, "path collides with an obstacle");
    }
    // Feasible candidates keep clear of the new obstacle; near ones are scored down.
    if (c.feasible) {
      EXPECT_GT(c.scores.min_obstacle_distance, 0.0);
      if (c.scores.min_obstacle_distance < 1.0) {
        EXPECT_NEAR(c.scores.s_s, c.scores.min_obstacle_distance, 1e-12);
      }
    }
  }
  EXPECT_TRUE(found);
  EXPECT_NE((after.best()->pose.xy - best.pose.xy).norm() +
                std::abs(after.best()->pose.entry_heading - best.pose.entry_heading),
            0.0);
}

void ExpectClearOfObstacles(const Yard& yard, const ShovelPointResult& result,
                            const std::string& name) {
  ASSERT_EQ(result.status, SelectionStatus::kSelected) << name << ": " << result.message;
  const ShovelCandidate& best = *result.best();
  for (int k = 0; k < 20 && k < static_cast<int>(result.ranked.size()); ++k) {
    const ShovelCandidate& c = result.ranked[k];
    if (!c.feasible) break;
    EXPECT_GT(TrueClearance(yard, c), 0.0) << name << " rank " << k + 1;
  }
  // The best's approach keeps the safety distance d_res from every true obstacle box (its body
  // outline bare; the planner's carries a 0.3 m margin, so slightly below d_res still means
  // clear). Its s_s also counts the scoop beyond the contact (Eq. 14's A), which the true
  // clearance below does not.
  EXPECT_GT(best.scores.approach_obstacle_distance, 0.7) << name;
  EXPECT_LE(best.scores.min_obstacle_distance, best.scores.approach_obstacle_distance) << name;
  const double clearance = TrueClearance(yard, best);
  std::printf(
      "%s: %s; best (%.2f, %.2f) heading %.1f deg F %.3f, path %.1f m, clearance %.2f "
      "m (planner d_min %.2f m, approach %.2f m)\n",
      name.c_str(), result.message.c_str(), best.pose.xy.x(), best.pose.xy.y(),
      best.pose.entry_heading * 180 / std::numbers::pi, best.score, best.scores.path_length,
      clearance, best.scores.min_obstacle_distance, best.scores.approach_obstacle_distance);
  EXPECT_GE(clearance, 1.0) << name;  // d_res
}

TEST(ShovelPointSelection, PileBehindLoaderPathsKeepClear) {
  const Yard yard("pile_behind_loader");
  const ShovelPointResult result = yard.Select();
  ExpectClearOfObstacles(yard, result, "pile_behind_loader");
  // The parked loader blocks the direct way: candidates whose shortest path crosses it are
  // either rerouted or infeasible, never feasible through it.
  int vetoed = 0;
  for (const ShovelCandidate& c : result.ranked) vetoed += !c.feasible;
  EXPECT_GT(vetoed, 0);
}

TEST(ShovelPointSelection, MixingStationPathsKeepClear) {
  const Yard yard("mixing_station");
  EXPECT_GE(yard.piles.size(), 6u);
  ExpectClearOfObstacles(yard, yard.Select(), "mixing_station");
}

TEST(ShovelPointSelection, Deterministic) {
  const Yard yard("irregular_pile");
  const ShovelPointResult a = yard.Select(), b = yard.Select();
  ASSERT_EQ(a.ranked.size(), b.ranked.size());
  for (std::size_t k = 0; k < a.ranked.size(); ++k) {
    EXPECT_EQ(a.ranked[k].pose.xy, b.ranked[k].pose.xy);
    EXPECT_EQ(a.ranked[k].pose.entry_heading, b.ranked[k].pose.entry_heading);
    if (a.ranked[k].feasible) {
      EXPECT_EQ(a.ranked[k].score, b.ranked[k].score);
    }
  }
  const auto candidates = GenerateCandidates(yard.map, yard.piles, {});
  const auto c1 = RankChen2024(yard.map, yard.plane, candidates, yard.start.xy);
  const auto c2 = RankChen2024(yard.map, yard.plane, candidates, yard.start.xy);
  ASSERT_EQ(c1.size(), c2.size());
  for (std::size_t k = 0; k < c1.size(); ++k) EXPECT_EQ(c1[k].score, c2[k].score);
}

TEST(ShovelPointSelection, CandidatesAlongTheFrontAtTheSpacing) {
  const Yard yard("cone_pile");
  ShovelPointConfig config;
  config.candidate_spacing = 2.0;
  config.entry_angle_offsets = {0.0};
  const std::vector<CandidatePose> sparse = GenerateCandidates(yard.map, yard.piles, config);
  config.candidate_spacing = 1.0;
  const std::vector<CandidatePose> dense = GenerateCandidates(yard.map, yard.piles, config);
  // The cone's rim is about 2π · 3.8 m long.
  EXPECT_NEAR(static_cast<double>(dense.size()), 2 * std::numbers::pi * 3.8, 6.0);
  EXPECT_NEAR(static_cast<double>(sparse.size()), dense.size() / 2.0, 3.0);
  // The inward normal points at the apex on a cone.
  for (const CandidatePose& c : dense) {
    const Eigen::Vector2d to_apex = (Eigen::Vector2d(25, 20) - c.xy).normalized();
    EXPECT_GT(to_apex.dot(Eigen::Vector2d(std::cos(c.normal_heading), std::sin(c.normal_heading))),
              0.9);
  }
}

TEST(SelectCommand, WritesTheCandidatePicture) {
  sim::SelectOptions options;
  options.scenario = "cone_pile";
  options.models_dir = kModels;
  options.truth_labels = true;  // the perceived map, with the simulator's labels
  options.frames = 2;
  options.png = ::testing::TempDir() + "/shovel_points_cone.png";
  std::filesystem::remove(options.png);
  std::ostringstream out, err;
  EXPECT_EQ(sim::RunSelect(options, out, err), 0) << err.str();
  std::printf("%s", out.str().c_str());
  EXPECT_NE(out.str().find("Eq. (18): selected"), std::string::npos);
  EXPECT_NE(out.str().find("Chen et al. 2024 best"), std::string::npos);
  ASSERT_TRUE(std::filesystem::exists(options.png));
  EXPECT_GT(std::filesystem::file_size(options.png), 1000u);
  // Bad input: one message, exit status 2.
  options.scenario = "no_such_yard";
  std::ostringstream out2, err2;
  EXPECT_EQ(sim::RunSelect(options, out2, err2), 2);
  EXPECT_FALSE(err2.str().empty());
}

}  // namespace
}  // namespace autoshovel::planning
