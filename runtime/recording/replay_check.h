// What a replay is checked by: the map after every update (a SHA-256 of its layers) and every
// selection's outcome, as CSV rows written by the recording machine (reference/) and by
// `autoshovel replay` (its run folder) in the same form, numbers in shortest round-trip text.
#pragma once

#include <string>

#include "runtime/perception/grid_map.h"
#include "runtime/planning/shovel_point_selection.h"

namespace autoshovel::recording {

inline constexpr const char* kMapDigestsHeader = "update,map_sha256";
inline constexpr const char* kSelectionsHeader =
    "update,cycle,candidates,feasible,best_x,best_y,best_heading,best_score";

inline constexpr const char* kPredictionsHeader = "cycle,time,v1,v2";

/// `cycle,time,v1,v2` of one trigger decision (V2 empty when NaN: not predicted).
std::string PredictionRow(int cycle, double time, double v1, double v2);

/// SHA-256 over the map's size, resolution, position and every layer (name and float bytes,
/// in name order).
std::string MapDigest(const perception::GridMap& map);

/// `update,sha` (no newline).
std::string MapDigestRow(long update, const perception::GridMap& map);

/// `update,cycle,candidates,feasible,x,y,heading,score` of a selection; the best's fields are
/// empty when `best` is null.
std::string SelectionRow(long update, int cycle, const planning::ShovelPointResult& selection,
                         const planning::ShovelCandidate* best);

/// Two tables of the same header compared row by row (the header skipped): rows, rows alike, and
/// the first difference as `what line N: recording '…', replay '…'`.
struct Comparison {
  long rows = 0, same = 0;
  std::string first_difference;
};
Comparison CompareTables(const std::string& reference, const std::string& ours,
                         const std::string& what);

}  // namespace autoshovel::recording
