// A multi-rate executive on the simulated clock (DESIGN.md "Rates": low-level control 100 Hz,
// state machine 20 Hz, map and shovel point selection 7 Hz). Tasks run when their next due time
// has come, in the order they were added, then the clock moves on by the base period: with the
// same inputs every run calls the same tasks at the same simulated instants, whatever the wall
// clock does. (The scoop cycle's own 20 Hz decisions are counted in its control ticks,
// ScoopCycleOptions::decision_every.)
#pragma once

#include <chrono>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace autoshovel::app {

class MultiRateExecutive {
 public:
  /// `base_period` [s]: the fastest task's period; the clock advances by it each Step().
  explicit MultiRateExecutive(double base_period, double start_time = 0)
      : base_period_(base_period), now_(start_time) {
    if (!(base_period > 0) || !std::isfinite(base_period)) {
      throw std::invalid_argument("executive: base period must be > 0 s");
    }
  }

  /// Adds a task run every `period` [s] (≥ the base period), first at the current time.
  void Add(std::string name, double period, std::function<void(double now)> task) {
    if (!(period >= base_period_ - 1e-12) || !std::isfinite(period)) {
      throw std::invalid_argument("executive: task '" + name + "' period below the base period");
    }
    tasks_.push_back({std::move(name), period, now_, std::move(task), 0, 0.0});
  }

  /// Runs the tasks due now, then advances the clock by the base period.
  void Step() {
    for (Task& task : tasks_) {
      // Half a base period of slack: 1/7 s is not a multiple of 10 ms; the task runs at the
      // first base tick at or after its due time, and its schedule does not drift.
      if (now_ + 0.5 * base_period_ >= task.due) {
        const auto w0 = std::chrono::steady_clock::now();
        task.run(now_);
        task.seconds +=
            std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
        ++task.calls;
        task.due += task.period;
      }
    }
    now_ += base_period_;
  }

  double now() const { return now_; }
  /// Calls of the task named `name` so far (0 if none by that name).
  long Calls(const std::string& name) const {
    for (const Task& task : tasks_) {
      if (task.name == name) return task.calls;
    }
    return 0;
  }
  /// Wall time spent in the task named `name` so far [s] (0 if none by that name): the profile
  /// (`run --profile`). The schedule never depends on it.
  double Seconds(const std::string& name) const {
    for (const Task& task : tasks_) {
      if (task.name == name) return task.seconds;
    }
    return 0;
  }

 private:
  struct Task {
    std::string name;
    double period;
    double due;
    std::function<void(double)> run;
    long calls;
    double seconds;  ///< wall time in `run` [s]
  };
  double base_period_;
  double now_;
  std::vector<Task> tasks_;
};

}  // namespace autoshovel::app
