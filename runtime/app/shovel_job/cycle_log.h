// The progress lines of one cycle of the main job: "[cycle N] text" on the run's progress stream.
#pragma once

#include <cstdio>
#include <ostream>
#include <string>

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

/// `value` with `digits` decimals, as printf's "%.*f" writes it.
inline std::string Fixed(double value, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, value);
  return text;
}

}  // namespace autoshovel::app
