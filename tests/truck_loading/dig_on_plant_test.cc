// Digs on the plant: the joint servos follow the dig path of DigMotion on the simulated 25 t
// excavator, and the bucket comes out of the face with material, conserved between the face
// and the bucket.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "generated/registry.h"
#include "runtime/app/truck_loading/excavator_on_plant.h"
#include "runtime/control/excavator/dig_motion.h"
#include "runtime/control/excavator/excavator_kinematics.h"
#include "runtime/control/excavator/joint_model.h"
#include "runtime/control/excavator/joint_servo.h"
#include "runtime/model/description.h"
#include "runtime/plant/plant.h"
#include "runtime/plant/scenario.h"

namespace autoshovel::app {
namespace {

const std::string kModels = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";

struct DigRun {
  control::DigPhase phase = control::DigPhase::kApproach;
  std::string failure;
  double payload = 0;       // m³
  double face_removed = 0;  // m³
  double energy = 0;        // J
  double duration = 0;      // s, from the approach pose
  int stalls = 0;
};

DigRun Dig(const control::DigStroke& stroke_in) {
  plant::Scenario scenario = plant::LoadScenario(kModels + "/scenarios/truck_loading.yaml");
  const model::MachineDescription machine =
      model::LoadMachineDescription(model::ResolveMachineDescription("excavator_25t", kModels));
  const generated::MachineFunctions* functions = generated::FindMachine("excavator_25t");
  EXPECT_NE(functions, nullptr);
  const control::ExcavatorKinematics kinematics(machine, *functions);
  const control::ExcavatorModelDerivation models = control::DeriveJointModels(
      machine, *functions, control::DefaultReferencePose(), machine.bucket.rated_load);
  control::DigStroke stroke = stroke_in;
  const Eigen::Vector2d p_entry =
      stroke.radius * Eigen::Vector2d(std::cos(stroke.swing), std::sin(stroke.swing));
  stroke.entry_height = scenario.world.terrain.HeightAt(p_entry.x(), p_entry.y());
  control::DigMotion dig(kinematics, stroke);
  const std::optional<control::JointVector> q0 = dig.ApproachPose();
  EXPECT_TRUE(q0.has_value());
  plant::MachineState start;
  start.q.assign(q0->data(), q0->data() + 4);
  plant::Plant plant(machine, *functions, scenario.world, start);
  control::ExcavatorJointServo servo(machine, *functions, models.models);
  ExcavatorOnPlant excavator(plant, servo);
  const double volume0 = scenario.world.terrain.MaterialVolume();
  DigRun run;
  while (!dig.done() && !dig.failed() && plant.time() < 40) {
    const control::ExcavatorState s = excavator.Sense();
    const control::ExcavatorCommand command = dig.Step(s, plant.time());
    excavator.Command(command);
    excavator.Advance(0.01);
  }
  run.phase = dig.phase();
  run.failure = dig.failure();
  run.payload = plant.bucket().payload_volume();
  run.face_removed = volume0 - scenario.world.terrain.MaterialVolume();
  run.energy = plant.energy().hydraulic;
  run.duration = plant.time();
  run.stalls = dig.stalls();
  return run;
}

TEST(DigOnPlant, FillsTheBucketFromTheFace) {
  // Entering beyond the crest (r = 7.6 m) and dragging towards the machine through it: the cut
  // is 0.4 m deep at entry and grows to ~1 m under the crest.
  const DigRun run =
      Dig({.swing = 0.0, .radius = 9.0, .entry_height = 0, .depth = 0.4, .drag_length = 2.5});
  std::printf("dig: %s %s payload %.3f m3 removed %.3f m3 energy %.1f kJ time %.2f s stalls %d\n",
              control::ToString(run.phase), run.failure.c_str(), run.payload, run.face_removed,
              run.energy / 1e3, run.duration, run.stalls);
  EXPECT_EQ(run.phase, control::DigPhase::kDone) << run.failure;
  EXPECT_GT(run.payload, 0.8);  // of a 1.2 m³ heaped bucket
  EXPECT_LE(run.payload, 1.2 + 1e-6);
  // What left the face is in the bucket or was spilled back onto the terrain (conservation: terrain
  // + bucket is constant).
  EXPECT_NEAR(run.payload, run.face_removed, 1e-6);
}

}  // namespace
}  // namespace autoshovel::app
