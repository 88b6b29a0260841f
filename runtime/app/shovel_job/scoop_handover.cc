#include "runtime/app/shovel_job/scoop_handover.h"

#include <cmath>
#include <optional>

#include "runtime/optimal/warm_scoop_solver.h"

namespace autoshovel::app {

prediction::HeightGrid HeightGridOf(const perception::GridMap& map) {
  prediction::HeightGrid grid;
  grid.resolution = map.resolution();
  grid.nx = map.size().x();
  grid.ny = map.size().y();
  grid.origin = map.position() - 0.5 * map.length();
  grid.height.assign(static_cast<std::size_t>(grid.nx) * grid.ny, NAN);
  const Eigen::MatrixXf& elevation = map["elevation"];
  for (int iy = 0; iy < grid.ny; ++iy) {
    for (int ix = 0; ix < grid.nx; ++ix) {
      perception::Index index;
      if (!map.IndexOf(grid.CellCenter(ix, iy), index)) continue;
      grid.height[static_cast<std::size_t>(iy) * grid.nx + ix] = elevation(index.x(), index.y());
    }
  }
  return grid;
}

namespace {

// ScoopPolicy::kOptimal's planner: the optimal-control scoop (runtime/optimal) on the pile the
// map saw, to V_t within `max_time`, warm-started from the run's last plan.
std::optional<control::PlannedScoop> PlanOptimalScoop(optimal::WarmScoopSolver& solver,
                                                      const model::MachineDescription& machine,
                                                      const model::Material& material,
                                                      const control::ScoopPlanRequest& request,
                                                      double max_time, std::string* why) {
  optimal::ContactProblem problem;
  problem.speed = request.speed;
  problem.q = {request.q_boom, request.q_bucket};
  problem.payload_volume = request.payload_volume;
  problem.profile_spacing = request.profile_spacing;
  problem.profile_heights = request.profile_heights;
  problem.target_volume = request.target_volume;
  problem.max_time = max_time;
  const std::optional<optimal::ScoopOcpSolution> solution =
      solver.Solve(machine, material, problem, why);
  if (!solution || !solution->ok) return std::nullopt;
  control::PlannedScoop plan;
  plan.time = solution->time_at;
  for (const auto& x : solution->state) {
    plan.speed.push_back(x[optimal::kV]);
    plan.q_boom.push_back(x[optimal::kQ]);
    plan.q_bucket.push_back(x[optimal::kQ + 1]);
  }
  plan.energy = solution->energy;
  plan.volume = solution->volume;
  plan.solve_seconds = solution->solve_seconds;
  return plan;
}

}  // namespace

std::string StartScoopCycle(const ScoopHandoverInputs& in, const Eigen::Vector2d& goal_xy,
                            const perception::GridMap& map, const FaultSchedule& faults,
                            control::ScoopMachine& machine_io, ScoopHandover& handover,
                            const CycleLog& log) {
  const ShovelRunOptions& o = in.options;
  // The material is that of the site's pile nearest the shovel point: the yard's inventory
  // (which material lies in which bin) is known to the station; the map's classes do not tell
  // materials.
  double nearest = INFINITY;
  for (const plant::Pile& p : in.piles) {
    const double d = (p.center - goal_xy).norm();
    if (in.in_site(p.center) && d < nearest) nearest = d, handover.pile = &p;
  }
  if (handover.pile == nullptr) {
    return "no pile of the scenario lies in " + in.site_name;
  }
  std::string material_name = handover.pile->material;
  for (const plant::FaultSpec& f : faults.faults()) {
    if (f.kind == plant::FaultKind::kMaterialMistyped && f.InCycle(faults.cycle())) {
      log.Say("inventory reports " + f.reported + " for " + handover.pile->material + " (fault, " +
              f.where + ")");
      material_name = f.reported;
    }
  }
  const model::Material* material = in.machine.FindMaterial(material_name);
  if (material == nullptr) {
    return "machine '" + in.machine.name + "' has no material '" + material_name + "'";
  }
  handover.material = material;
  const double target_volume = in.scoop_options.target_fill * in.machine.bucket.rated_capacity;
  if (o.trigger == TriggerChoice::kPredicted) {
    handover.trigger = std::make_unique<control::PredictedVolumeTrigger>(target_volume);
  } else if (o.trigger == TriggerChoice::kPerception) {
    handover.trigger = std::make_unique<control::PerceptionTrigger>(target_volume);
  } else {
    handover.trigger = std::make_unique<control::BoomPressureTrigger>(o.pressure_threshold);
  }
  handover.pre_contact = HeightGridOf(map);
  handover.scoop = std::make_unique<control::ScoopCycle>(
      in.machine, in.functions, handover.pre_contact, *material, *handover.trigger, &in.predictor,
      in.scoop_options);
  if (o.policy == control::ScoopPolicy::kOptimal) {
    optimal::WarmScoopSolver* solver = &in.optimal_solver;
    const model::MachineDescription* machine = &in.machine;
    const double max_time = o.optimal_max_time;
    handover.scoop->SetPlanner([solver, machine, material, max_time](
                                   const control::ScoopPlanRequest& request, std::string* why) {
      return PlanOptimalScoop(*solver, *machine, *material, request, max_time, why);
    });
  }
  handover.scoop->Start(machine_io);
  log.Say("attack (" + std::string(control::ToString(o.policy)) + ", trigger " +
          ToString(o.trigger) + ") on " + material->name);
  return "";
}

}  // namespace autoshovel::app
