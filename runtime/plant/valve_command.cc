#include "runtime/plant/valve_command.h"

#include <cmath>

namespace autoshovel::plant {

double ApplyDeadZone(double duty, double dead_zone) {
  const double magnitude = std::abs(duty);
  if (magnitude <= dead_zone) return 0.0;
  return std::copysign((magnitude - dead_zone) / (1.0 - dead_zone), duty);
}

void DelayedValveCommand::Command(double t, double duty) {
  const double value = ApplyDeadZone(duty, dead_zone_);
  const double last = history_.empty() ? initial_value_ : history_.back().value;
  if (value == last) return;  // no switching event: nothing reaches the spool differently
  const double effective = t + transport_delay_;
  // Commands are issued in time order, so effective instants are too (constant delay); a delay
  // shortened at run time could break the order: a later command then overrides earlier ones.
  while (!history_.empty() && history_.back().effective_time >= effective) history_.pop_back();
  history_.push_back({effective, value});
}

double DelayedValveCommand::EffectiveAt(double t) const {
  double value = initial_value_;
  for (const Entry& entry : history_) {
    if (entry.effective_time > t) break;
    value = entry.value;
  }
  return value;
}

double DelayedValveCommand::NextSwitchAfter(double t) const {
  for (const Entry& entry : history_) {
    if (entry.effective_time > t) return entry.effective_time;
  }
  return std::numeric_limits<double>::infinity();
}

void DelayedValveCommand::Prune(double t) {
  while (!history_.empty() && history_.front().effective_time <= t) {
    initial_value_ = history_.front().value;
    history_.pop_front();
  }
}

}  // namespace autoshovel::plant
