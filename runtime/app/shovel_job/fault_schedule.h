// Which of the run's faults (plant/fault_spec.h) strike the cycle now: the scenario's and the
// run's own, each active over its window of one cycle's clock.
#pragma once

#include <vector>

#include "runtime/plant/fault_spec.h"

namespace autoshovel::app {

class FaultSchedule {
 public:
  /// `t0`: the machine clock at the cycle's start [s]. `faults` must outlive the schedule.
  FaultSchedule(const std::vector<plant::FaultSpec>& faults, int cycle, double t0)
      : faults_(faults), cycle_(cycle), t0_(t0) {}

  /// The first fault of `kind` active at machine time `time`, or null.
  const plant::FaultSpec* Active(plant::FaultKind kind, double time) const;
  /// Whether a fault of `kind` strikes this cycle at all.
  bool InCycle(plant::FaultKind kind) const;

  const std::vector<plant::FaultSpec>& faults() const { return faults_; }
  int cycle() const { return cycle_; }
  double t0() const { return t0_; }

 private:
  const std::vector<plant::FaultSpec>& faults_;
  int cycle_;
  double t0_;
};

}  // namespace autoshovel::app
