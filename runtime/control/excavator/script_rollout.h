// Running the loading script and the joint models forward together (excavator seed §4.4–4.5):
// the script is evaluated at its own rate (LoadingScript::kPeriod, 10 Hz) on the predicted joint
// positions and its command is issued to the predicted machine, which integrates in between.
// The look-ahead (§4.5) has to foresee both the machine and what the script will command it to
// do on the predicted states; the script parameters' left-hand sides are found with the same
// rollout (§4.4).
#pragma once

#include <functional>

#include "runtime/control/excavator/excavator_simulator.h"
#include "runtime/control/excavator/loading_script.h"

namespace autoshovel::control {

/// Advances `machine` and `script` (the caller's copies) by up to `duration` [s]. The first
/// script evaluation is `first_evaluation` [s] from now (0: at once; the look-ahead passes the
/// time left to the real script's next tick), then one per period; between evaluations the
/// machine advances in steps of LoadingScript::kPeriod / round(kPeriod / integration step).
/// `visit(elapsed)` is called once before anything moves (elapsed 0) and after every step; the
/// rollout ends early when it returns false. A script output that is a stop is issued as a stop.
/// Returns the elapsed time at the end.
double RollOut(ExcavatorSimulator& machine, LoadingScript& script, double duration,
               double first_evaluation, const std::function<bool(double elapsed)>& visit);

}  // namespace autoshovel::control
