// One closed-loop cycle for the tests: the options every test starts from (simulator labels, one
// cycle, no figures) and a run that prints its row.
#pragma once

#include <cstdio>
#include <string>

#include "runtime/app/shovel_run.h"

namespace autoshovel::app {

inline ShovelRunOptions TestCycleOptions(const std::string& scenario) {
  ShovelRunOptions o;
  o.scenario = scenario;
  o.models_dir = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";
  o.truth_labels = true;
  o.cycles = 1;
  o.figures = false;
  return o;
}

inline CycleOutcome RunTestCycle(const ShovelRunOptions& options) {
  ShovelJob job(options);
  CycleOutcome out = job.RunCycle(0, {}, nullptr);
  const results::CycleRecord& r = out.record;
  std::printf(
      "[cycle] %s/%s: %s %s, %s (%s), fill %.3f, trigger %.2f s after contact, "
      "clearance %.2f m, %d violation(s), cycle %.1f s, %.0f kJ; %d safe stop(s), %d "
      "recover(ies), travel after a stop %.2f m from %.2f m/s\n",
      r.scenario.c_str(), r.bin.c_str(), r.completed ? "completed" : out.failure.c_str(),
      r.material.c_str(), r.strategy.c_str(), r.atomic_actions.c_str(), r.fill_rate,
      out.scoop.trigger_after_contact, r.safety_margin_m, r.safety_violations, r.time_s.total,
      r.energy_kj.total, out.safe_stops, out.recoveries, out.stop_travel_m, out.speed_at_stop);
  return out;
}

}  // namespace autoshovel::app
