#include "runtime/plant/valve_command.h"

#include <algorithm>
#include <cmath>

namespace autoshovel::plant {

double ApplyDeadZone(double duty, double dead_zone) {
  const double magnitude = std::abs(duty);
  if (magnitude <= dead_zone) return 0.0;
  return std::copysign((magnitude - dead_zone) / (1.0 - dead_zone), duty);
}

double InterpolateOpeningCurve(const std::vector<model::OpeningPoint>& curve, double duty) {
  if (curve.empty() || duty <= curve.front().duty) return 0.0;
  if (duty >= curve.back().duty) return curve.back().opening;
  // The first point with a duty above `duty` (duties increase strictly: loader-checked).
  const auto upper =
      std::upper_bound(curve.begin(), curve.end(), duty,
                       [](double d, const model::OpeningPoint& point) { return d < point.duty; });
  const auto lower = upper - 1;
  const double s = (duty - lower->duty) / (upper->duty - lower->duty);
  return lower->opening + s * (upper->opening - lower->opening);
}

double ValveOpening(const model::Valve& valve, double pilot) {
  if (pilot > 0 && !valve.opening_curve_extend.empty()) {
    return InterpolateOpeningCurve(valve.opening_curve_extend, std::min(pilot, 1.0));
  }
  if (pilot < 0 && !valve.opening_curve_retract.empty()) {
    return -InterpolateOpeningCurve(valve.opening_curve_retract, std::min(-pilot, 1.0));
  }
  return ApplyDeadZone(std::clamp(pilot, -1.0, 1.0), valve.dead_zone);
}

void DelayedValveCommand::Command(double t, double duty) {
  const double value = raw() ? duty : ValveOpening(valve_, duty);
  const double last = history_.empty() ? initial_value_ : history_.back().value;
  if (value == last) return;  // no switching event: nothing reaches the valve differently
  // τ_p + τ_d: the pilot lag commutes with the pure delays (valve_command.h).
  const double effective = t + (valve_.pilot_delay + valve_.transport_delay);
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

double PilotSignal::Relax(double from, double input, double dt) const {
  if (time_constant_ <= 0) return input;
  return input + (from - input) * std::exp(-dt / time_constant_);
}

void PilotSignal::Command(double t, double duty) {
  const double last = pending_.empty() ? input_ : pending_.back().value;
  if (duty == last) return;
  const double effective = t + delay_;
  while (!pending_.empty() && pending_.back().time >= effective) pending_.pop_back();
  pending_.push_back({effective, duty});
}

double PilotSignal::At(double t) const {
  double s = t0_, pi = pi0_, input = input_;
  for (const Entry& entry : pending_) {
    if (entry.time > t) break;
    pi = Relax(pi, input, entry.time - s);
    s = entry.time;
    input = entry.value;
  }
  return Relax(pi, input, std::max(t - s, 0.0));
}

void PilotSignal::Prune(double t) {
  while (!pending_.empty() && pending_.front().time <= t) {
    pi0_ = Relax(pi0_, input_, pending_.front().time - t0_);
    t0_ = pending_.front().time;
    input_ = pending_.front().value;
    pending_.pop_front();
  }
}

}  // namespace autoshovel::plant
