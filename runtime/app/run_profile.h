// Where a run's wall time goes (`autoshovel run --profile`, docs/performance.md): the executive's
// tasks and, inside them, the components, each with its calls and wall seconds. Entries keep
// the order they were first added; a nested entry's time is also in its parent's.
#pragma once

#include <chrono>
#include <string>
#include <vector>

namespace autoshovel::app {

struct ProfileEntry {
  std::string name;
  long calls = 0;
  double seconds = 0;  ///< wall time [s]
  int depth = 0;       ///< 0: an executive task or the cycle's frame; 1: a component inside one
};

class RunProfile {
 public:
  /// Adds `seconds` over `calls` to the entry `name` (created at `depth` on first use).
  void Add(const std::string& name, double seconds, long calls = 1, int depth = 0);
  /// Adds every entry of `other`.
  void Merge(const RunProfile& other);
  const std::vector<ProfileEntry>& entries() const { return entries_; }

  /// A text table: calls, total, per call, share of `total_seconds` (the run's wall time).
  std::string Table(double total_seconds) const;
  /// `entry,depth,calls,seconds` rows with a header.
  std::string Csv() const;

 private:
  std::vector<ProfileEntry> entries_;
};

/// Wall seconds since construction (std::chrono::steady_clock).
class WallTimer {
 public:
  WallTimer() : start_(std::chrono::steady_clock::now()) {}
  double Seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

}  // namespace autoshovel::app
