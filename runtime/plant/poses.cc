#include "runtime/plant/poses.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "runtime/machines/machine_code.h"

namespace autoshovel::plant {

std::vector<double> BucketOnFloor(const model::MachineDescription& machine, double tip_height) {
  if (machine.links.size() != 2 || machine.bucket.profile.size() < 2) {
    throw std::invalid_argument("BucketOnFloor: needs a two-link arm with a bucket profile (" +
                                machine.name + ")");
  }
  // The floor edge points back from the tip; level means it points along −x in frame M.
  const Eigen::Vector2d floor = machine.bucket.profile[1] - machine.bucket.profile[0];
  double phi_bucket = std::numbers::pi - std::atan2(floor.y(), floor.x());
  phi_bucket = std::remainder(phi_bucket, 2 * std::numbers::pi);
  const double l1 = machine.links[0].length, l2 = machine.links[1].length;
  const double sin_boom = (tip_height - machine.arm_pivot.y() - l2 * std::sin(phi_bucket)) / l1;
  if (std::abs(sin_boom) > 1) {
    throw std::invalid_argument("BucketOnFloor: " + machine.name + " cannot reach the floor");
  }
  const double boom = std::asin(sin_boom);
  return {boom, phi_bucket - boom};
}

ScenarioWithMachine LoadScenarioWithMachine(const std::string& scenario_name_or_path,
                                            const std::string& models_dir,
                                            const std::string& machine_name_or_path) {
  ScenarioWithMachine out;
  out.scenario = LoadScenario(ResolveScenario(scenario_name_or_path, models_dir));
  if (!machine_name_or_path.empty()) out.scenario.machine = machine_name_or_path;
  out.machine = model::LoadMachineDescription(
      model::ResolveMachineDescription(out.scenario.machine, models_dir));
  // Compiled in, else its machine library, else interpreted (runtime/machines/machine_code.h).
  out.functions = &machines::MachineFunctionsFor(out.machine);
  return out;
}

MachineState StartState(const Scenario& scenario, const model::MachineDescription& machine,
                        double advance) {
  MachineState start;
  start.heading = scenario.start.heading;
  start.hinge_xy = Eigen::Vector2d(scenario.start.x, scenario.start.y) +
                   advance * Eigen::Vector2d(std::cos(start.heading), std::sin(start.heading));
  if (machine.kind == model::MachineKind::kWheelLoader && machine.num_links() == 2) {
    start.q = BucketOnFloor(machine);
  } else {
    start.q.assign(machine.num_joints(), 0.0);
    for (std::size_t j = 0; j < machine.num_links(); ++j) {
      start.q[j] = machine.links[j].joint_min +
                   0.1 * (machine.links[j].joint_max - machine.links[j].joint_min);
    }
  }
  return start;
}

}  // namespace autoshovel::plant
