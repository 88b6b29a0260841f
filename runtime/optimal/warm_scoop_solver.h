// The optimal scoop from a contact state on a sampled pile, with one solver kept across calls so
// that each solve warm-starts from the last: what `compare table5` (the bound beside every
// strategy) and `run --policy optimal` (the plan at contact) both ask.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "runtime/model/description.h"
#include "runtime/optimal/scoop_ocp.h"

namespace autoshovel::optimal {

/// The machine at contact, the pile ahead and what is asked of the scoop.
struct ContactProblem {
  double speed = 0;           ///< [m/s]
  std::array<double, 2> q{};  ///< boom, bucket [rad]
  double payload_volume = 0;  ///< already in the bucket [m³]
  /// Heights along the heading from the hinge [m], every `profile_spacing` from
  /// `profile_start` [m] (PileProfile).
  double profile_start = 0, profile_spacing = 0.05;
  std::vector<double> profile_heights;
  /// Wanted in the bucket [m³]: capped at 97 % of the rated capacity, over which the smooth
  /// intake closes (scoop_model.h).
  double target_volume = 0;
  double max_time = 6;  ///< contact to the end of the scooping motion [s]
};

class WarmScoopSolver {
 public:
  /// The solution (`ok` says whether Ipopt converged; `why` then says why not), or nullopt
  /// with `why` when no model can be built for this machine, material and profile.
  std::optional<ScoopOcpSolution> Solve(const model::MachineDescription& machine,
                                        const model::Material& material,
                                        const ContactProblem& problem, std::string* why);

 private:
  std::unique_ptr<ScoopModel> model_;  // the pile last solved on (the solver refers to it)
  std::unique_ptr<ScoopOcp> ocp_;
};

}  // namespace autoshovel::optimal
