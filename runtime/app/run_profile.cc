#include "runtime/app/run_profile.h"

#include <cstdio>

#include "runtime/core/strings.h"

namespace autoshovel::app {

void RunProfile::Add(const std::string& name, double seconds, long calls, int depth) {
  for (ProfileEntry& e : entries_) {
    if (e.name == name) {
      e.seconds += seconds;
      e.calls += calls;
      return;
    }
  }
  entries_.push_back({name, calls, seconds, depth});
}

void RunProfile::Merge(const RunProfile& other) {
  for (const ProfileEntry& e : other.entries_) Add(e.name, e.seconds, e.calls, e.depth);
}

std::string RunProfile::Table(double total_seconds) const {
  std::string out =
      "  task / component                                        calls    total s   ms/call   "
      "share\n";
  for (const ProfileEntry& e : entries_) {
    char line[200];
    const std::string name = std::string(e.depth > 0 ? "    " : "") + e.name;
    std::snprintf(line, sizeof line, "  %-52s %8ld %10.2f %9.3f %6.1f %%\n", name.c_str(), e.calls,
                  e.seconds, e.calls > 0 ? 1e3 * e.seconds / static_cast<double>(e.calls) : 0.0,
                  total_seconds > 0 ? 100 * e.seconds / total_seconds : 0.0);
    out += line;
  }
  return out;
}

std::string RunProfile::Csv() const {
  std::string out = "entry,depth,calls,seconds\n";
  for (const ProfileEntry& e : entries_) {
    out += e.name + "," + std::to_string(e.depth) + "," + std::to_string(e.calls) + "," +
           core::FormatNumber(e.seconds) + "\n";
  }
  return out;
}

}  // namespace autoshovel::app
