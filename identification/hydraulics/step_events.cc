#include "identification/hydraulics/step_events.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace autoshovel::identification {

namespace {

constexpr std::size_t kNone = static_cast<std::size_t>(-1);

int Sign(double x) { return x > 0 ? 1 : (x < 0 ? -1 : 0); }

// Central difference over ±half_window seconds (fewer samples at the ends).
std::vector<double> Rate(const std::vector<double>& t, const std::vector<double>& q,
                         double half_window) {
  const std::size_t n = t.size();
  std::vector<double> rate(n, 0.0);
  if (n < 2) return rate;
  std::size_t lo = 0, hi = 0;
  for (std::size_t i = 0; i < n; ++i) {
    while (lo < i && t[i] - t[lo] > half_window) ++lo;
    if (hi < i) hi = i;
    while (hi + 1 < n && t[hi + 1] - t[i] <= half_window) ++hi;
    const std::size_t a = (lo == i && i > 0) ? i - 1 : lo;
    const std::size_t b = (hi == i && i + 1 < n) ? i + 1 : hi;
    rate[i] = (q[b] - q[a]) / (t[b] - t[a]);
  }
  return rate;
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0;
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

}  // namespace

LogEvents DetectStepEvents(const HydraulicLog& log, const StepEventOptions& options) {
  LogEvents events;
  const std::size_t n = log.size();
  events.rate = Rate(log.time, log.joint_angle, 0.05);
  // Over ±0.25 s: the jitter of a joint pressed against its stop averages out.
  const std::vector<double> slow_rate = Rate(log.time, log.joint_angle, 0.25);
  events.stalled.assign(n, 0);
  events.excluded.assign(n, 0);
  if (n == 0) return events;

  // Steps: maximal runs of one command sign beyond `command_on`.
  for (std::size_t i = 0; i < n;) {
    const int sign = std::abs(log.command[i]) > options.command_on ? Sign(log.command[i]) : 0;
    std::size_t j = i + 1;
    while (j < n &&
           (std::abs(log.command[j]) > options.command_on ? Sign(log.command[j]) : 0) == sign) {
      ++j;
    }
    if (sign != 0) {
      CommandStep step;
      step.on = i;
      step.off = j;
      for (std::size_t k = i; k < j; ++k) {
        if (std::abs(log.command[k]) > std::abs(step.level)) step.level = log.command[k];
      }
      events.steps.push_back(step);
    }
    i = j;
  }

  // Driving pressure: the higher chamber, which at a stall is the one at relief.
  events.has_pressure = !log.pressure_a.empty() || !log.pressure_b.empty();
  std::vector<double> drive(n, 0.0);
  if (events.has_pressure) {
    for (std::size_t i = 0; i < n; ++i) {
      const double a = log.pressure_a.empty() ? 0.0 : log.pressure_a[i];
      const double b = log.pressure_b.empty() ? 0.0 : log.pressure_b[i];
      drive[i] = std::max(a, b);
    }
    double highest = 0;
    for (const CommandStep& step : events.steps) {
      for (std::size_t k = step.on; k < step.off; ++k) highest = std::max(highest, drive[k]);
    }
    events.stall_pressure = options.relief > 0 ? options.relief : highest;
  }
  const double pressure_floor =
      events.stall_pressure - std::max(options.min_stall_pressure_band,
                                       options.stall_pressure_band * events.stall_pressure);

  for (CommandStep& step : events.steps) {
    // The way the joint moves under this command: the description's sense (extending the
    // cylinder may lower the angle, as on most sticks).
    const int sign = Sign(step.level) * options.joint_sense;
    const double start = log.joint_angle[step.on];
    // Furthest angle reached in the command's direction, and the motion onset.
    double furthest = start;
    for (std::size_t k = step.on; k < step.off; ++k) {
      const double q = log.joint_angle[k];
      if (sign * (q - furthest) > 0) furthest = q;
      if (step.onset == kNone && sign * (q - start) >= options.onset_angle) step.onset = k;
    }
    // A stall's pressure also stands clear above the one the joint moved with (from the onset
    // to where it first came within the band of its furthest angle): a slow step that never
    // reaches its stop has its own moving pressure as the highest of its file, and would
    // otherwise read as stalled over its last degrees of travel.
    double moving_floor = -std::numeric_limits<double>::infinity();
    if (events.has_pressure && step.onset != kNone) {
      std::vector<double> moving;
      std::size_t k = step.onset;
      for (; k < step.off && sign * (furthest - log.joint_angle[k]) > options.stall_angle_band;
           ++k) {
        moving.push_back(drive[k]);
      }
      if (!moving.empty() && log.time[k - 1] - log.time[step.onset] >= 0.2) {
        moving_floor = Median(moving) + (events.stall_pressure - pressure_floor);
      }
    }
    // Stall candidates: command on, at the far end of travel, pressure near relief.
    std::vector<char> candidate(step.off - step.on, 0);
    for (std::size_t k = step.on; k < step.off; ++k) {
      const bool at_end = sign * (furthest - log.joint_angle[k]) <= options.stall_angle_band;
      const bool moved = step.onset != kNone && k >= step.onset;
      const bool pressed = events.has_pressure
                               ? drive[k] >= pressure_floor && drive[k] >= moving_floor
                               : std::abs(slow_rate[k]) <= 3 * options.rest_rate;
      candidate[k - step.on] = at_end && moved && pressed;
    }
    // Without pressure, a stall must last; with it, relief is evidence enough.
    const double min_duration = events.has_pressure ? 0.0 : options.min_stall_duration;
    for (std::size_t k = step.on; k < step.off;) {
      if (!candidate[k - step.on]) {
        ++k;
        continue;
      }
      std::size_t e = k;
      while (e < step.off && candidate[e - step.on]) ++e;
      if (log.time[e - 1] - log.time[k] >= min_duration) {
        // Back over the samples at rest at that angle before the pressure rose.
        std::size_t b = k;
        const double held = log.joint_angle[k];
        while (b > step.on && std::abs(log.joint_angle[b - 1] - held) <= options.stall_rest_band) {
          --b;
        }
        for (std::size_t s = b; s < e; ++s) events.stalled[s] = 1;
        // On past the command's end while the joint stays pressed at that angle: the valve
        // closes over its delay and lags, and a model free of the stop would move the joint
        // on. Bounded by the settling time and by the next step, whose rest it keeps.
        if (e == step.off) {
          const double until = log.time[e - 1] + options.post_stall_settle;
          const std::size_t next_on = [&] {
            for (const CommandStep& other : events.steps) {
              if (other.on >= step.off) return other.on;
            }
            return n;
          }();
          for (std::size_t s = e; s < next_on && log.time[s] <= until &&
                                  std::abs(log.joint_angle[s] - held) <= options.stall_angle_band;
               ++s) {
            events.stalled[s] = 1;
          }
        }
      }
      k = e;
    }
  }

  std::vector<double> stalled_pressure;
  for (std::size_t i = 0; i < n; ++i) {
    const double q = log.joint_angle[i];
    const double t = log.time[i];
    const bool outside = q < options.joint_min || q > options.joint_max ||
                         t < options.window_begin || t > options.window_end;
    events.excluded[i] = events.stalled[i] || outside;
    if (events.stalled[i]) {
      ++events.stalled_samples;
      if (events.has_pressure) stalled_pressure.push_back(drive[i]);
    }
  }
  events.relief_seen = Median(stalled_pressure);
  for (std::size_t i = 0; i < n;) {
    if (events.excluded[i]) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < n && !events.excluded[j]) ++j;
    if (j - i >= options.min_segment) events.segments.emplace_back(i, j);
    i = j;
  }
  return events;
}

std::vector<SignMismatch> FindSignMismatches(const HydraulicLog& log, const LogEvents& events,
                                             const StepEventOptions& options) {
  std::vector<SignMismatch> mismatches;
  // Steps long enough for the joint to follow (a chirp's short half-waves find the joint still
  // moving the previous way), judged by the net change over the step, beyond what a joint
  // settling on a stop may move.
  const double threshold = std::max(4 * options.onset_angle, 0.02);
  for (std::size_t s = 0; s < events.steps.size(); ++s) {
    const CommandStep& step = events.steps[s];
    const std::size_t last = step.off - 1;
    if (log.time[last] - log.time[step.on] < options.sign_check_duration) continue;
    const double change = log.joint_angle[last] - log.joint_angle[step.on];
    if (std::abs(change) > threshold && Sign(change) != Sign(step.level) * options.joint_sense) {
      mismatches.push_back({s, step.level, change});
    }
  }
  return mismatches;
}

}  // namespace autoshovel::identification
