// The progress lines of one cycle of the main job: "[cycle N] text" on the run's progress stream.
#pragma once

#include <ostream>
#include <string>

#include "runtime/core/strings.h"

namespace autoshovel::app {

class CycleLog {
 public:
  /// `progress` may be null (silent); `index` counts cycles from 0 and is printed from 1.
  CycleLog(std::ostream* progress, int index) : progress_(progress), index_(index) {}
  void Say(const std::string& text) const {
    if (progress_ != nullptr) *progress_ << "[cycle " << index_ + 1 << "] " << text << "\n";
  }

 private:
  std::ostream* progress_;
  int index_;
};

using core::Fixed;

}  // namespace autoshovel::app
