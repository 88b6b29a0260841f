// Eq. (19) on hand-made grids and V2 = V21 + V22 for a known penetration (volume_estimation.h).
#include "runtime/prediction/volume_estimation.h"

#include <gtest/gtest.h>

#include <cmath>

#include "generated/registry.h"
#include "runtime/plant/poses.h"

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

}  // namespace
}  // namespace autoshovel::prediction
