#include "runtime/recording/replay_check.h"

#include <cmath>
#include <cstring>
#include <sstream>

#include "runtime/core/sha256.h"
#include "runtime/core/strings.h"

namespace autoshovel::recording {

std::string MapDigest(const perception::GridMap& map) {
  std::string bytes;
  auto append = [&bytes](const void* p, std::size_t n) {
    bytes.append(static_cast<const char*>(p), n);
  };
  const int size[2] = {map.size().x(), map.size().y()};
  const double geometry[3] = {map.resolution(), map.position().x(), map.position().y()};
  append(size, sizeof size);
  append(geometry, sizeof geometry);
  for (const std::string& name : map.layers()) {  // std::map order: by name
    bytes += name;
    bytes.push_back('\0');
    const Eigen::MatrixXf& layer = map[name];
    append(layer.data(), sizeof(float) * static_cast<std::size_t>(layer.size()));
  }
  return core::Sha256Hex(bytes);
}

std::string MapDigestRow(long update, const perception::GridMap& map) {
  return std::to_string(update) + "," + MapDigest(map);
}

std::string PredictionRow(int cycle, double time, double v1, double v2) {
  return std::to_string(cycle) + "," + core::FormatNumber(time) + "," + core::FormatNumber(v1) +
         "," + (std::isnan(v2) ? std::string() : core::FormatNumber(v2));
}

std::string SelectionRow(long update, int cycle, const planning::ShovelPointResult& selection,
                         const planning::ShovelCandidate* best) {
  std::string row = std::to_string(update) + "," + std::to_string(cycle) + "," +
                    std::to_string(selection.ranked.size()) + "," +
                    std::to_string(selection.feasible) + ",";
  if (best == nullptr) return row + ",,,";
  return row + core::FormatNumber(best->pose.xy.x()) + "," + core::FormatNumber(best->pose.xy.y()) +
         "," + core::FormatNumber(best->pose.entry_heading) + "," + core::FormatNumber(best->score);
}

Comparison CompareTables(const std::string& reference, const std::string& ours,
                         const std::string& what) {
  std::istringstream a(reference), b(ours);
  std::string ra, rb;
  Comparison c;
  long line = 0;
  while (true) {
    const bool more_a = static_cast<bool>(std::getline(a, ra));
    const bool more_b = static_cast<bool>(std::getline(b, rb));
    if (!more_a && !more_b) break;
    ++line;
    if (line == 1) continue;  // the header
    ++c.rows;
    if (more_a && more_b && ra == rb) {
      ++c.same;
    } else if (c.first_difference.empty()) {
      c.first_difference = what + " line " + std::to_string(line) + ": recording '" +
                           (more_a ? ra : "(none)") + "', replay '" + (more_b ? rb : "(none)") +
                           "'";
    }
  }
  return c;
}

}  // namespace autoshovel::recording
