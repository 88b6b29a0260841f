// The excavator's joint servos on the plant: a step of each joint reaches its target and holds
// it; a stop and a non-finite measurement close every valve.
#include "runtime/control/excavator/joint_servo.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "generated/registry.h"
#include "runtime/app/truck_loading/excavator_on_plant.h"
#include "runtime/control/excavator/joint_model.h"
#include "runtime/model/description.h"
#include "runtime/plant/plant.h"

namespace autoshovel::app {
namespace {

const std::string kModels = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";

struct Machine {
  model::MachineDescription description =
      model::LoadMachineDescription(model::ResolveMachineDescription("excavator_25t", kModels));
  const generated::MachineFunctions* functions = generated::FindMachine("excavator_25t");
  control::ExcavatorModelDerivation models =
      control::DeriveJointModels(description, *functions, control::DefaultReferencePose(), 0.0);
};

TEST(ExcavatorJointServo, StopAndNonFiniteStateCloseEveryValve) {
  const Machine m;
  control::ExcavatorJointServo servo(m.description, *m.functions, m.models.models);
  control::ExcavatorState state;
  state.q = control::DefaultReferencePose();
  control::ExcavatorCommand command;
  command.position = state.q + control::JointVector::Constant(0.3);
  bool any_open = false;
  for (double u : servo.Update(command, state)) any_open = any_open || u != 0.0;
  EXPECT_TRUE(any_open);
  command.stop = true;
  for (double u : servo.Update(command, state)) EXPECT_EQ(u, 0.0);
  command.stop = false;
  state.qd[1] = std::numeric_limits<double>::quiet_NaN();
  for (double u : servo.Update(command, state)) EXPECT_EQ(u, 0.0);
}

// Each joint alone, from the reference pose, a step the size of a loading pass's moves: an arm
// joint arrives within 0.01 rad and overshoots by less than 0.03 rad; the swing's 90° overshoots
// by less than 0.12 rad and settles within 0.06 rad. The swing is looser because, braked by a
// closed valve, it rebounds on the oil trapped at relief pressure (the plant models no leakage
// and no anti-rebound valve), a slow ±0.05 rad oscillation the servo damps only weakly.
TEST(ExcavatorJointServo, StepsReachTheirTargetsOnThePlant) {
  const Machine m;
  const double steps[4] = {0.25, -0.4, 0.6, 1.5708};
  const double arrive[4] = {0.01, 0.01, 0.01, 0.06};
  const double overshoot_limit[4] = {0.03, 0.03, 0.03, 0.12};
  for (int j = 0; j < 4; ++j) {
    plant::World world = plant::EmptyYard(m.description, 40.0);
    plant::MachineState start;
    const control::JointVector q0 = control::DefaultReferencePose();
    start.q.assign(q0.data(), q0.data() + 4);
    plant::Plant plant(m.description, *m.functions, world, start);
    control::ExcavatorJointServo servo(m.description, *m.functions, m.models.models);
    ExcavatorOnPlant excavator(plant, servo);
    control::ExcavatorCommand command;
    command.position = q0;
    command.position[j] += steps[j];
    double overshoot = 0;
    while (plant.time() < 12.0) {
      excavator.Command(command);
      excavator.Advance(0.01);
      const double q = excavator.Sense().q[j];
      overshoot = std::max(overshoot, (q - command.position[j]) * (steps[j] > 0 ? 1 : -1));
    }
    const double error = std::abs(excavator.Sense().q[j] - command.position[j]);
    EXPECT_LT(error, arrive[j]) << "joint " << j;
    EXPECT_LT(overshoot, overshoot_limit[j]) << "joint " << j;
    std::printf("joint %d: step %.2f rad, final error %.4f rad, overshoot %.4f rad\n", j, steps[j],
                error, overshoot);
  }
}

}  // namespace
}  // namespace autoshovel::app
