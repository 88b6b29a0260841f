// The safety margin the cycle kept, measured on the simulation's truth (not the machine's
// knowledge): the machine's outline against the yard's obstacles and the people a fault put
// there, at 20 Hz; each time it comes closer than the safety distance counts once.
#pragma once

#include <cmath>
#include <vector>

#include "runtime/app/shovel_job/cycle_log.h"
#include "runtime/perception/machine_footprint.h"
#include "runtime/plant/machine_state.h"
#include "runtime/plant/world.h"

namespace autoshovel::app {

class ClearanceRecord {
 public:
  explicit ClearanceRecord(double safety_distance) : safety_distance_(safety_distance) {}

  /// `path_error`: the largest cross-track error so far (for the log) [m].
  void Update(const perception::MachineFootprint& footprint,
              const std::vector<plant::OrientedBox>& obstacles, const plant::MachineState& s,
              double path_error, double t0, const CycleLog& log);

  double min_clearance() const { return min_clearance_; }  ///< [m]
  int violations() const { return violations_; }

 private:
  double safety_distance_;
  double min_clearance_ = INFINITY;
  int violations_ = 0;
  bool in_violation_ = false;
};

}  // namespace autoshovel::app
