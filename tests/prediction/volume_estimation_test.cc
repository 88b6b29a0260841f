// Eq. (19) on hand-made grids and V2 = V21 + V22 for a known penetration (volume_estimation.h).
#include "runtime/prediction/volume_estimation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "generated/registry.h"
#include "runtime/plant/plant.h"
#include "runtime/plant/poses.h"
#include "tests/plant/plant_test_support.h"

namespace autoshovel::prediction {
namespace {

model::MachineDescription Loader() {
  return model::LoadMachineDescription(model::ResolveMachineDescription(
      "xcmg_968ev", std::string(AUTOSHOVEL_SOURCE_DIR) + "/models"));
}

// A 10 m × 10 m floor at 0.1 m with a box of material `height` high over x ∈ [x0, x1),
// y ∈ [−2.5, 2.5): cell edges fall on the box edges, cell centres never on the strip's border.
HeightGrid BoxGrid(double x0, double x1, double height) {
  HeightGrid grid;
  grid.resolution = 0.1;
  grid.origin = Eigen::Vector2d(-5, -5);
  grid.nx = grid.ny = 100;
  grid.height.assign(100 * 100, 0.0);
  for (int iy = 0; iy < grid.ny; ++iy) {
    for (int ix = 0; ix < grid.nx; ++ix) {
      const Eigen::Vector2d c = grid.CellCenter(ix, iy);
      if (c.x() > x0 && c.x() < x1 && std::abs(c.y()) < 2.5) {
        grid.height[static_cast<std::size_t>(iy) * grid.nx + ix] = height;
      }
    }
  }
  return grid;
}

TEST(Eq19Volume, BoxUnderAStraightPathGivesItsVolume) {
  const HeightGrid grid = BoxGrid(0.0, 2.0, 1.2);
  // Bucket 3 m wide on the floor along y = 0 through the whole box: 1.2 m × 3 m × 2 m.
  const SweptVolume v = Eq19Volume(grid, {{-1, 0, 0}, {3, 0, 0}}, 3.0);
  EXPECT_NEAR(v.volume, 1.2 * 3.0 * 2.0, 1e-9);
  EXPECT_EQ(v.unknown_cells, 0);
  // The same path in many short steps counts every cell once.
  std::vector<Eigen::Vector3d> fine;
  for (int k = 0; k <= 400; ++k) fine.emplace_back(-1 + 0.01 * k, 0, 0);
  EXPECT_NEAR(Eq19Volume(grid, fine, 3.0).volume, 7.2, 1e-9);
  // Teeth 0.2 m above the floor leave the material below them; a path stopping half way in
  // takes half.
  EXPECT_NEAR(Eq19Volume(grid, {{-1, 0, 0.2}, {3, 0, 0.2}}, 3.0).volume, 1.0 * 3.0 * 2.0, 1e-9);
  EXPECT_NEAR(Eq19Volume(grid, {{-1, 0, 0}, {1, 0, 0}}, 3.0).volume, 1.2 * 3.0 * 1.0, 1e-9);
  // Teeth above the surface take nothing.
  EXPECT_EQ(Eq19Volume(grid, {{-1, 0, 1.5}, {3, 0, 1.5}}, 3.0).volume, 0.0);
}

TEST(Eq19Volume, DiagonalPathAgreesWithinTheDiscretisation) {
  const HeightGrid grid = BoxGrid(-4.0, 4.0, 1.0);  // 8 m × 5 m
  const double c = std::cos(0.3), s = std::sin(0.3);
  const SweptVolume v = Eq19Volume(grid, {{-c, -s, 0}, {c, s, 0}}, 2.0);
  // A 2 m × 2 m strip; the cells whose centres fall inside it cover that area to about one
  // cell row along its border (perimeter × ε / 2).
  EXPECT_NEAR(v.volume, 4.0, 8.0 * 0.1 / 2);
}

TEST(Eq19Volume, UnknownCellsAreSkippedAndCounted) {
  HeightGrid grid = BoxGrid(0.0, 2.0, 1.0);
  grid.height[static_cast<std::size_t>(50) * grid.nx + 55] = std::nan("");
  const SweptVolume v = Eq19Volume(grid, {{-1, 0, 0}, {3, 0, 0}}, 3.0);
  EXPECT_EQ(v.unknown_cells, 1);
  EXPECT_NEAR(v.volume, 6.0 - 0.01, 1e-9);
  EXPECT_THROW(Eq19Volume(grid, {{0, 0, 0}, {1, 0, 0}}, 0.0), std::invalid_argument);
}

TEST(FutureVolume, ConstantPenetrationWithTheArmHeldSweepsTheBox) {
  const model::MachineDescription machine = Loader();
  const std::vector<double> q = plant::BucketOnFloor(machine);
  const Eigen::Vector2d tip = TipInBase(machine, q[0], q[1]);
  EXPECT_NEAR(tip.y(), 0.05, 1e-9);  // Eq. (2) agrees with the plant's pose
  const HeightGrid grid = BoxGrid(0.0, 4.9, 1.05);
  MachineAtTrigger m;
  m.hinge_xy = Eigen::Vector2d(0.5 - tip.x(), 0.0);  // teeth 0.5 m into the box
  m.heading = 0;
  m.speed = 1.0;
  m.q = q;
  ScoopPlan plan;  // the arm never moves: the teeth run along the floor for the whole travel
  plan.delay = 0.6;
  const double d = 1.0;
  const FutureVolume v = PredictFutureVolume(machine, grid, {}, m, d, plan);
  const double w = machine.bucket.width, h = 1.05 - 0.05;
  EXPECT_NEAR(v.total(), h * w * d, h * w * 0.1);  // within one cell column
  // V21: the travel during the delay, s = v t − v² t² / (4 d).
  const double s_delay = 0.6 - 0.36 / 4;
  EXPECT_NEAR(v.v21, h * w * s_delay, h * w * 0.1);
  // With the V1 path before it, nothing already counted is counted again.
  const std::vector<Eigen::Vector3d> past = {{0.0, 0, 0.05}, {0.5, 0, 0.05}};
  const FutureVolume after = PredictFutureVolume(machine, grid, past, m, d, plan);
  EXPECT_NEAR(after.total(), v.total(), h * w * 0.1);
  EXPECT_NEAR(Eq19Volume(grid, past, w).volume, h * w * 0.5, h * w * 0.1);
}

TEST(FutureVolume, CurlingTheBucketTakesLessThanHoldingItAndDelayFromTheDescription) {
  const model::MachineDescription machine = Loader();
  const generated::MachineFunctions* functions = generated::FindMachine(machine.name);
  ASSERT_NE(functions, nullptr);
  const std::vector<double> q = plant::BucketOnFloor(machine);
  const ScoopPlan plan = ScoopPlanFromMachine(machine, *functions, q, 1.0, 1.0, 1.0, 0.3);
  const model::Valve& tilt = machine.hydraulics.actuators[machine.ActuatorOfJoint(1)].valve;
  EXPECT_DOUBLE_EQ(plan.delay, tilt.transport_delay + tilt.spool_time_constant);
  EXPECT_GT(plan.bucket_rate, 0.1);
  EXPECT_LT(plan.bucket_rate, 3.0);
  const HeightGrid grid = BoxGrid(0.0, 4.9, 2.0);
  MachineAtTrigger m;
  m.hinge_xy = Eigen::Vector2d(0.5 - TipInBase(machine, q[0], q[1]).x(), 0.0);
  m.speed = 1.0;
  m.q = q;
  ScoopPlan held = plan;
  held.bucket_curl = held.boom_lift = 0;
  const FutureVolume curled = PredictFutureVolume(machine, grid, {}, m, 2.0, plan);
  const FutureVolume straight = PredictFutureVolume(machine, grid, {}, m, 2.0, held);
  EXPECT_NEAR(curled.v21, straight.v21, 1e-9);
  EXPECT_LT(curled.v22, straight.v22);
  EXPECT_GT(curled.v22, 0.0);
  EXPECT_THROW(PredictFutureVolume(machine, grid, {}, m, std::nan(""), plan),
               std::invalid_argument);
  ScoopPlan bad = plan;
  bad.delay = -1;
  EXPECT_NE(bad.Invalid(), "");
}

// The predicted travel curve (ScoopPlan::travel_at): knots on the constant deceleration give
// its path to the chord error; knots that lag (the machine slows early) put the teeth behind it
// at every knot, and from the last knot the machine brakes to rest at d.
TEST(FutureVolume, TravelCurveShapesThePathWithinTheSamePenetration) {
  const model::MachineDescription machine = Loader();
  const std::vector<double> q = plant::BucketOnFloor(machine);
  const HeightGrid grid = BoxGrid(0.0, 4.9, 1.05);
  MachineAtTrigger m;
  m.hinge_xy = Eigen::Vector2d(0.5 - TipInBase(machine, q[0], q[1]).x(), 0.0);
  m.speed = 1.0;
  m.q = q;
  ScoopPlan plan;  // the arm held: the path is the travel alone
  plan.delay = 0.6;
  const double d = 2.0;
  const FutureVolume constant = PredictFutureVolume(machine, grid, {}, m, d, plan);
  auto travel_at = [&](const FutureVolume& v, double t) {
    return v.path[static_cast<std::size_t>(std::lround(t / plan.time_step))].x() - v.path[0].x();
  };

  ScoopPlan sampled = plan;
  for (int k = 1; k <= 16; ++k) {
    const double t = 0.25 * k;  // s = t − t²/8 up to t = 4 s, where it reaches d = 2 m
    sampled.travel_times.push_back(t);
    sampled.travel_at.push_back(t - t * t / 8);
  }
  ASSERT_EQ(sampled.Invalid(), "");
  const FutureVolume same = PredictFutureVolume(machine, grid, {}, m, d, sampled);
  for (double t = 0; t <= 4.0; t += 0.1) {
    // Chords of a parabola 0.25 s apart: at most Δt²/8·|s''| = 0.0625/8·0.25 ≈ 2e-3 m off.
    EXPECT_NEAR(travel_at(same, t), travel_at(constant, t), 2.5e-3) << "t " << t;
  }
  EXPECT_NEAR(same.total(), constant.total(), 0.02);

  ScoopPlan lagging = plan;
  lagging.travel_times = {0.5, 1.0, 1.5, 2.0};
  lagging.travel_at = {0.45, 0.80, 1.07, 1.32};  // the tall gravel cone's crowding run
  const FutureVolume behind = PredictFutureVolume(machine, grid, {}, m, d, lagging);
  for (std::size_t k = 0; k < lagging.travel_times.size(); ++k) {
    EXPECT_NEAR(travel_at(behind, lagging.travel_times[k]), lagging.travel_at[k], 1e-9);
    if (k == 0) continue;  // from 1 s on the cone's machine is 0.07–0.18 m behind
    EXPECT_LT(travel_at(behind, lagging.travel_times[k]),
              travel_at(constant, lagging.travel_times[k]) - 0.05);
  }
  // From 2 s at the last chord's 0.5 m/s, braking to rest over the 0.68 m left: 2.72 s more.
  EXPECT_NEAR(travel_at(behind, 3.0), 1.32 + 0.5 - 0.25 / (4 * 0.68), 1e-6);
  EXPECT_NEAR(behind.path.back().x() - behind.path[0].x(), d, 1e-9);
  EXPECT_NEAR(behind.total(), constant.total(), 0.1 * 1.0 * machine.bucket.width);

  // A knot past d counts as d; one behind its predecessor as the predecessor.
  ScoopPlan odd = plan;
  odd.travel_times = {0.5, 1.0, 1.5};
  odd.travel_at = {0.6, 0.5, 2.4};
  const FutureVolume clamped = PredictFutureVolume(machine, grid, {}, m, d, odd);
  EXPECT_NEAR(travel_at(clamped, 1.0), 0.6, 1e-9);
  EXPECT_NEAR(travel_at(clamped, 1.5), d, 1e-9);
  EXPECT_NEAR(clamped.path.back().x() - clamped.path[0].x(), d, 1e-9);

  ScoopPlan bad = lagging;
  bad.travel_times[2] = bad.travel_times[1];  // not increasing
  EXPECT_NE(bad.Invalid(), "");
  bad = lagging;
  bad.travel_at.pop_back();
  EXPECT_NE(bad.Invalid(), "");
  bad = lagging;
  bad.travel_at[1] = std::nan("");
  EXPECT_NE(bad.Invalid(), "");
  EXPECT_THROW(PredictFutureVolume(machine, grid, {}, m, d, bad), std::invalid_argument);
}

// The curl V2 assumes against the plant's: the tilt valve fully open from the attack pose (the
// bucket just off the floor, empty), until the bucket joint has racked back as far as the scoop
// cycle curls it. The rate along the stroke follows the lever arm; the rate at the trigger alone
// misses how the arm's geometry speeds the curl up as it goes.
TEST(PlanCurl, RateAlongTheStrokeMatchesThePlantsCurl) {
  const model::MachineDescription machine = Loader();
  const generated::MachineFunctions* functions = generated::FindMachine(machine.name);
  ASSERT_NE(functions, nullptr);
  std::vector<double> q = plant::BucketOnFloor(machine);
  q[0] += 0.1;  // off the floor: no ground contact to slow the curl
  const double curl = machine.links[1].joint_max - 0.1 - q[1];  // ScoopCycleOptions' margin
  ASSERT_GT(curl, 0.5);
  const ScoopPlan plan = ScoopPlanFromMachine(machine, *functions, q, 1.0, 1.0, curl, 0.3);
  ASSERT_EQ(plan.bucket_rate_along_curl.size(), 17u);
  EXPECT_DOUBLE_EQ(plan.bucket_rate_along_curl.front(), plan.bucket_rate);
  const CurlSchedule schedule = PlanCurl(plan);
  const double constant_rate_time = plan.delay + curl / plan.bucket_rate;

  plant::World world = plant::testing::FlatYard(machine, 20.0, 0.1);
  plant::Plant machine_plant(machine, *functions, world,
                             plant::testing::LoaderAt(machine, 0.0, q[0], q[1]));
  core::ActuatorCommand command;
  command.valve.assign(machine.hydraulics.actuators.size(), 0.0);
  command.valve[static_cast<std::size_t>(machine.ActuatorOfJoint(1))] = 1.0;
  double plant_time = NAN;
  while (machine_plant.time() < 8.0) {
    ASSERT_TRUE(machine_plant.SetCommand(command));
    machine_plant.Advance(0.01);
    if (machine_plant.state().q[1] >= q[1] + curl) {
      plant_time = machine_plant.time();
      break;
    }
  }
  ASSERT_TRUE(std::isfinite(plant_time)) << "the plant never curled " << curl << " rad";
  std::printf(
      "curl of %.3f rad: plant %.3f s, along the stroke %.3f s, at the trigger's rate %.3f s\n",
      curl, plant_time, schedule.t_curled, constant_rate_time);
  EXPECT_NEAR(schedule.t_curled, plant_time, 0.1 * plant_time);
  EXPECT_LT(std::abs(schedule.t_curled - plant_time), std::abs(constant_rate_time - plant_time));
  // The schedule is still through the delay, monotone, and ends at the full curl.
  const std::size_t in_delay = static_cast<std::size_t>(plan.delay / plan.time_step);
  EXPECT_EQ(schedule.curl[in_delay], 0.0);
  for (std::size_t k = 1; k < schedule.curl.size(); ++k) {
    ASSERT_GE(schedule.curl[k], schedule.curl[k - 1]);
  }
  EXPECT_DOUBLE_EQ(schedule.curl.back(), curl);
  ScoopPlan bad = plan;
  bad.bucket_rate_along_curl[3] = NAN;
  EXPECT_NE(bad.Invalid().find("bucket_rate_along_curl[3]"), std::string::npos);
}

}  // namespace
}  // namespace autoshovel::prediction
