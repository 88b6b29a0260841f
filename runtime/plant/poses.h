// Named arm poses of a machine, computed from its description rather than written as numbers.
#pragma once

#include <vector>

#include "generated/registry.h"
#include "runtime/model/description.h"
#include "runtime/plant/machine_state.h"
#include "runtime/plant/scenario.h"

namespace autoshovel::plant {

/// Joint positions [q_boom, q_bucket] that put a two-link loader arm's bucket on the floor: the
/// floor of the bucket (the profile's first edge, from the tip) level and the tip `tip_height`
/// above the ground (Eq. 2 solved for the boom). Throws std::invalid_argument for an arm that is
/// not two links or cannot reach that low.
std::vector<double> BucketOnFloor(const model::MachineDescription& machine,
                                  double tip_height = 0.05);

/// A scenario with its machine: the description named by the scenario and its generated code.
struct ScenarioWithMachine {
  Scenario scenario;
  model::MachineDescription machine;
  const generated::MachineFunctions* functions = nullptr;  ///< never null
};

/// Loads a scenario (name under `<models_dir>/scenarios` or a path) and its machine, or the
/// machine `machine_name_or_path` instead when it is not empty. The machine's functions come
/// from machines::MachineFunctionsFor (compiled in, its machine library, or interpreted). Throws
/// core::InputError for bad files and std::runtime_error (machines::MachineCodeError) when the
/// machine has no code it may run (naming the command that builds it).
ScenarioWithMachine LoadScenarioWithMachine(const std::string& scenario_name_or_path,
                                            const std::string& models_dir,
                                            const std::string& machine_name_or_path = "");

/// The scenario's start pose moved `advance` metres ahead along its heading, with the arm as
/// when approaching a pile: a loader's bucket on the floor (BucketOnFloor), other arms low in
/// their range (10 % from the bottom of each joint).
MachineState StartState(const Scenario& scenario, const model::MachineDescription& machine,
                        double advance = 0.0);

}  // namespace autoshovel::plant
