#include "runtime/optimal/warm_scoop_solver.h"

#include <algorithm>
#include <stdexcept>

namespace autoshovel::optimal {

std::optional<ScoopOcpSolution> WarmScoopSolver::Solve(const model::MachineDescription& machine,
                                                       const model::Material& material,
                                                       const ContactProblem& problem,
                                                       std::string* why) {
  if (!(problem.max_time > 0) || !(problem.target_volume >= 0)) {
    *why = "optimal scoop: needs a time bound > 0 and a target volume >= 0";
    return std::nullopt;
  }
  std::unique_ptr<ScoopModel> model;
  try {
    model = std::make_unique<ScoopModel>(
        machine, material,
        PileProfile(problem.profile_start, problem.profile_spacing, problem.profile_heights));
  } catch (const std::invalid_argument& e) {
    *why = e.what();
    return std::nullopt;
  }
  ScoopOcpOptions options;
  options.target_volume = std::min(problem.target_volume, 0.97 * model->heaped_capacity());
  options.max_time = problem.max_time;
  options.min_time = std::min(1.0, 0.5 * problem.max_time);
  if (!ocp_) {
    ocp_ = std::make_unique<ScoopOcp>(*model, options);
  } else {
    ocp_->set_model(*model);
    ocp_->set_options(options);
  }
  model_ = std::move(model);
  ScoopStart start;
  start.speed = std::max(problem.speed, 0.0);
  start.q = problem.q;
  start.volume = std::min(problem.payload_volume, options.target_volume);
  ScoopOcpSolution solution = ocp_->Solve(start);
  if (!solution.ok) *why = solution.status + " (worst: " + solution.worst_constraint + ")";
  return solution;
}

}  // namespace autoshovel::optimal
