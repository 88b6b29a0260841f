// The safety supervisor's hold rule, one for both jobs (docs/architecture.md): a reason to stop
// stops the machine at once; it goes on once the checks have found no reason for
// `resume_after`. The
// loader's path watch (shovel_job/path_watch.h) holds for the sensor watchdog and obstacles on
// its path, the excavator's load loop (truck_loading/) for its look-ahead; SafetySupervisor
// keeps the reason and counts stops and recoveries.
#pragma once

#include <string>

#include "runtime/app/safety_supervisor.h"

namespace autoshovel::app {

class StopHold {
 public:
  enum class Change { kNone, kStopped, kResumed };

  explicit StopHold(double resume_after) : resume_after_(resume_after) {}

  /// One check at `t` [s] with `reason` ("" when there is none): stops `supervisor` when a
  /// reason appears; resumes it once the checks have found none for `resume_after`, counted
  /// from the first clear check (the conservative reading: a 20 Hz check that sees the reason
  /// gone at t resumes at t + resume_after, not one tick earlier). Returns what changed.
  Change Update(double t, const std::string& reason, SafetySupervisor& supervisor) {
    if (!reason.empty()) {
      clear_since_ = kNever;
      if (supervisor.stopped()) return Change::kNone;
      supervisor.Stop(reason);
      return Change::kStopped;
    }
    if (!supervisor.stopped()) return Change::kNone;
    if (clear_since_ == kNever) clear_since_ = t;
    if (t - clear_since_ < resume_after_) return Change::kNone;
    supervisor.Resume();
    clear_since_ = kNever;
    return Change::kResumed;
  }

 private:
  static constexpr double kNever = -1e300;
  double resume_after_;
  double clear_since_ = kNever;  ///< the first check since the last reason that found none [s]
};

}  // namespace autoshovel::app
