#include "runtime/planning/dump/fill_summary.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace autoshovel::planning {

FillSummary SummarizeFill(const BedHeightMap& map, double level_m) {
  if (!std::isfinite(level_m)) throw std::invalid_argument("SummarizeFill: level must be finite");
  FillSummary summary;
  summary.level_m = level_m;
  summary.known_cells = map.known_count();
  summary.known_fraction =
      static_cast<double>(summary.known_cells) / (map.cells_x() * map.cells_y());
  if (summary.known_cells == 0) return summary;

  double sum = 0;
  int above = 0;
  summary.min_height_m = std::numeric_limits<double>::infinity();
  summary.max_height_m = -std::numeric_limits<double>::infinity();
  for (int ix = 0; ix < map.cells_x(); ++ix) {
    for (int iy = 0; iy < map.cells_y(); ++iy) {
      if (!map.known(ix, iy)) continue;
      const double h = map.height(ix, iy);
      sum += h;
      summary.min_height_m = std::min(summary.min_height_m, h);
      summary.max_height_m = std::max(summary.max_height_m, h);
      if (h > level_m) ++above;
    }
  }
  summary.mean_height_m = sum / summary.known_cells;
  // Two passes: the variance of heights a few centimetres apart around half a metre would lose
  // most of its digits in the one-pass E[h²] − E[h]² form.
  double squares = 0;
  for (int ix = 0; ix < map.cells_x(); ++ix) {
    for (int iy = 0; iy < map.cells_y(); ++iy) {
      if (!map.known(ix, iy)) continue;
      const double d = map.height(ix, iy) - summary.mean_height_m;
      squares += d * d;
    }
  }
  summary.std_height_m = std::sqrt(squares / summary.known_cells);
  summary.fraction_above_level = static_cast<double>(above) / summary.known_cells;
  return summary;
}

}  // namespace autoshovel::planning
