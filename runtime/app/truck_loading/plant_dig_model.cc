#include "runtime/app/truck_loading/plant_dig_model.h"

#include <cmath>

#include "runtime/app/truck_loading/excavator_on_plant.h"

namespace autoshovel::app {

control::DigStroke ToStroke(const planning::DigAction& action) {
  return {.swing = action.swing,
          .radius = action.radius,
          .entry_height = action.entry_height,
          .depth = action.depth,
          .drag_length = action.drag_length};
}

DigExecution ExecuteDig(plant::Plant& plant, control::ExcavatorJointServo& servo,
                        const control::ExcavatorKinematics& kinematics, control::DigMotion& motion,
                        double control_period) {
  ExcavatorOnPlant excavator(plant, servo);
  DigExecution out;
  const double t0 = plant.time();
  const double e0 = plant.energy().hydraulic;
  double next_sample = t0;
  while (!motion.done() && !motion.failed()) {
    const control::ExcavatorState s = excavator.Sense();
    if (plant.time() >= next_sample - 1e-9) {
      out.tip_path_base.push_back(kinematics.TipPosition(s.q));
      next_sample += 0.1;
    }
    excavator.Command(motion.Step(s, plant.time()));
    excavator.Advance(control_period);
  }
  out.done = motion.done();
  out.failure = motion.failure();
  out.volume = plant.bucket().payload_volume();
  out.energy = plant.energy().hydraulic - e0;
  out.duration = plant.time() - t0;
  out.stalls = motion.stalls();
  out.end_state = excavator.Sense();
  out.tip_path_base.push_back(kinematics.TipPosition(out.end_state.q));
  return out;
}

PlantDigModel::PlantDigModel(const model::MachineDescription& machine,
                             const generated::MachineFunctions& functions,
                             const control::ExcavatorKinematics& kinematics,
                             const control::ExcavatorJointModels& models, const plant::World& world,
                             const control::DigMotionSettings& dig_settings)
    : machine_(machine),
      functions_(functions),
      kinematics_(kinematics),
      models_(models),
      world_(world),
      dig_settings_(dig_settings) {}

planning::DigPrediction PlantDigModel::Predict(const planning::DigAction& action) {
  ++evaluations_;
  planning::DigPrediction out;
  control::DigMotion motion(kinematics_, ToStroke(action), dig_settings_);
  const std::optional<control::JointVector> q0 = motion.ApproachPose();
  if (!q0) {
    out.why = "approach pose out of reach";
    return out;
  }
  plant::World world = world_;
  plant::MachineState start;
  start.q.assign(q0->data(), q0->data() + control::kNumExcavatorJoints);
  plant::Plant plant(machine_, functions_, world, start);
  control::ExcavatorJointServo servo(machine_, functions_, models_);
  const DigExecution run = ExecuteDig(plant, servo, kinematics_, motion);
  out.executed = run.done;
  out.why = run.failure;
  out.volume = run.volume;
  out.energy = run.energy;
  out.duration = run.duration;
  out.tip_path = run.tip_path_base;
  return out;
}

}  // namespace autoshovel::app
