// How evenly the truck bed is filled (excavator seed §4.3: "loaded evenly and completely"): the
// distribution of the seen cells' heights, for the run report and for judging a dump strategy.
#pragma once

#include "runtime/planning/dump/bed_height_map.h"

namespace autoshovel::planning {

struct FillSummary {
  int known_cells = 0;              ///< cells with data
  double known_fraction = 0;        ///< known_cells / all cells
  double mean_height_m = 0;         ///< over the known cells [m]
  double std_height_m = 0;          ///< population standard deviation [m]; 0 = perfectly even
  double min_height_m = 0;          ///< [m]
  double max_height_m = 0;          ///< [m]
  double level_m = 0;               ///< the level asked for [m]
  double fraction_above_level = 0;  ///< known cells strictly higher than level_m, / known_cells
};

/// Summary of `map`'s known cells, with the fraction of them above `level_m` (e.g. the rim
/// height, for spill risk). No known cell gives all zeros (no NaN). Throws std::invalid_argument
/// for a non-finite level.
FillSummary SummarizeFill(const BedHeightMap& map, double level_m);

}  // namespace autoshovel::planning
