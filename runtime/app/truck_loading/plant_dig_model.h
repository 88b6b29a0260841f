// The refined dig planner's forward model on the plant (excavator seed §4.2, Fig. 13: "a forward
// model that simulates the result of choosing an action"): each candidate dig is executed on a
// copy of the simulated yard by a fresh plant, from the approach pose above its entry point,
// with the same dig motion and joint servos the machine then uses, so the planner scores what
// the machine will actually do (volume taken, hydraulic energy, time). The copy is thrown away.
//
// Honest limits: the forward model knows the true terrain and the true machine; on a real
// machine it would be the identified plant (hydraulic delays from `identify hydraulics`) and the
// scanned terrain, and a prediction error would show as a gap between predicted and dug volume,
// which the job reports per pass.
#pragma once

#include <vector>

#include "generated/machine_functions.h"
#include "runtime/control/excavator/dig_motion.h"
#include "runtime/control/excavator/excavator_kinematics.h"
#include "runtime/control/excavator/joint_model.h"
#include "runtime/control/excavator/joint_servo.h"
#include "runtime/model/description.h"
#include "runtime/planning/dig/dig_action.h"
#include "runtime/plant/plant.h"
#include "runtime/plant/world.h"

namespace autoshovel::app {

/// DigStroke of the control layer from the planner's action (the same five numbers).
control::DigStroke ToStroke(const planning::DigAction& action);

struct DigExecution {
  bool done = false;
  std::string failure;
  double volume = 0;    ///< payload at the end [m³]
  double energy = 0;    ///< hydraulic energy [J]
  double duration = 0;  ///< from the approach pose to the end of the lift [s]
  int stalls = 0;
  std::vector<Eigen::Vector3d> tip_path_base;  ///< every 0.1 s
  control::ExcavatorState end_state;
};

/// Runs `motion` on `plant` through `servo` at `control_period` until it is done, fails, or
/// `motion`'s own time limit. The plant's phase is left as the caller set it.
DigExecution ExecuteDig(plant::Plant& plant, control::ExcavatorJointServo& servo,
                        const control::ExcavatorKinematics& kinematics, control::DigMotion& motion,
                        double control_period = 0.01);

class PlantDigModel final : public planning::DigForwardModel {
 public:
  /// Keeps references to everything (they must outlive it). `world` is copied per prediction.
  PlantDigModel(const model::MachineDescription& machine,
                const generated::MachineFunctions& functions,
                const control::ExcavatorKinematics& kinematics,
                const control::ExcavatorJointModels& models, const plant::World& world,
                const control::DigMotionSettings& dig_settings = {});

  planning::DigPrediction Predict(const planning::DigAction& action) override;

  int evaluations() const { return evaluations_; }

 private:
  const model::MachineDescription& machine_;
  const generated::MachineFunctions& functions_;
  const control::ExcavatorKinematics& kinematics_;
  const control::ExcavatorJointModels& models_;
  const plant::World& world_;
  control::DigMotionSettings dig_settings_;
  int evaluations_ = 0;
};

}  // namespace autoshovel::app
