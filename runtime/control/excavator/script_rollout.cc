#include "runtime/control/excavator/script_rollout.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace autoshovel::control {

double RollOut(ExcavatorSimulator& machine, LoadingScript& script, double duration,
               double first_evaluation, const std::function<bool(double elapsed)>& visit) {
  if (!(std::isfinite(duration) && duration >= 0) ||
      !(std::isfinite(first_evaluation) && first_evaluation >= 0)) {
    throw std::invalid_argument("RollOut: duration and first_evaluation must be >= 0");
  }
  // Whole steps per script period, so that evaluations fall exactly on step boundaries.
  const int steps_per_period = std::max(
      1, static_cast<int>(std::lround(LoadingScript::kPeriod / machine.integration_step())));
  const double dt = LoadingScript::kPeriod / steps_per_period;
  const long total_steps = std::lround(duration / dt);
  long next_evaluation = std::lround(first_evaluation / dt);
  if (!visit(0.0)) return 0.0;
  for (long step = 0; step < total_steps; ++step) {
    if (step == next_evaluation) {
      machine.Command(script.Step(machine.state().q).command);
      next_evaluation += steps_per_period;
    }
    machine.Advance(dt);
    const double elapsed = (step + 1) * dt;
    if (!visit(elapsed)) return elapsed;
  }
  return total_steps * dt;
}

}  // namespace autoshovel::control
