// Generating expert demonstrations: random scenes (demo_scenes.h), the map Algorithm 2 would
// see (the simulator's truth rasterised: the demonstrations are about choosing, not perceiving),
// its candidates, and the simulated expert's pick among them (expert_model.h).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "identification/weights/demonstration_store.h"
#include "identification/weights/expert_model.h"
#include "runtime/model/description.h"
#include "runtime/planning/shovel_point_selection.h"

namespace autoshovel::identification {

struct DemonstrationGenerationOptions {
  int count = 482;  ///< the seed's number of expert scenarios
  std::uint64_t seed = 1;
  ExpertModel expert;
  double map_resolution = 0.3;  ///< ε, as the runtime map (Table 1) [m]
  int threads = 0;              ///< 0: every core; the result does not depend on it
  /// Called as scenes finish, from the worker threads one at a time: done, total.
  std::function<void(int, int)> progress;
};

/// `count` demonstrations, ids 0…count−1. A scene where the expert finds nothing to shovel (or
/// no candidate exists) is drawn again from the next seed of its slot, so the count is exact
/// and each slot is the same whatever the threads.
std::vector<Demonstration> GenerateDemonstrations(const model::MachineDescription& machine,
                                                  const planning::LoaderGeometry& loader,
                                                  const planning::ShovelPointConfig& config,
                                                  const DemonstrationGenerationOptions& options);

}  // namespace autoshovel::identification
