#include "runtime/app/shovel_job/fault_schedule.h"

#include <algorithm>

namespace autoshovel::app {

const plant::FaultSpec* FaultSchedule::Active(plant::FaultKind kind, double time) const {
  for (const plant::FaultSpec& f : faults_) {
    if (f.kind == kind && f.ActiveAt(cycle_, time - t0_)) return &f;
  }
  return nullptr;
}

bool FaultSchedule::InCycle(plant::FaultKind kind) const {
  return std::any_of(faults_.begin(), faults_.end(), [&](const plant::FaultSpec& f) {
    return f.kind == kind && f.InCycle(cycle_);
  });
}

}  // namespace autoshovel::app
