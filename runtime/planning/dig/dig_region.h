// The dig sector and the dig regions the coarse planner cuts it into (excavator seed §4.2,
// Fig. 12). Everything is in the excavator base frame: a region is a polar box, a swing interval
// × a radius interval around the swing axis, and a height band.
#pragma once

#include <string>

namespace autoshovel::planning {

/// The part of the terrain the excavator is to dig from where it stands, and the goal
/// configuration of the terrain: a level floor below which nothing is dug.
struct DigSector {
  double swing_min = -0.6;    ///< right edge of the sector, ψ [rad], in [-π, π]
  double swing_max = 0.6;     ///< left edge (the truck side), ψ [rad], > swing_min, <= π
  double radius_min = 4.0;    ///< nearest dig radius from the swing axis [m], > 0
  double radius_max = 9.0;    ///< farthest dig radius [m], > radius_min
  double floor_height = 0.0;  ///< goal: the terrain is dug down to this height, base z [m]
};

/// Throws std::invalid_argument naming the field (prefixed with `what`, e.g. "sector").
void Validate(const DigSector& sector, const std::string& what);

/// One box of Fig. 12. `column` counts from the left (column 0 holds the largest swings, nearest
/// the truck); `band` counts up from the goal floor (band 0 is the lowest). Both are fixed by the
/// sector and the region size, so a region keeps its identity while it is dug.
struct DigRegion {
  int column = 0;
  int band = 0;
  double swing_min = 0;   ///< [rad]
  double swing_max = 0;   ///< [rad]
  double radius_min = 0;  ///< [m]
  double radius_max = 0;  ///< [m]
  double z_min = 0;       ///< bottom of the band, never below the goal floor [m]
  double z_max = 0;       ///< top of the band [m]
  /// Measured on the map the region was offered for: the material inside the band (known cells
  /// only) [m^3], the highest known surface in the region's footprint [m], and how many of the
  /// footprint's cells are known / unknown (NaN).
  double volume = 0;
  double top_height = 0;
  int known_cells = 0;
  int unknown_cells = 0;
};

/// Same column and band.
inline bool SameRegion(const DigRegion& a, const DigRegion& b) {
  return a.column == b.column && a.band == b.band;
}

}  // namespace autoshovel::planning
