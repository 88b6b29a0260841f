// How much material a dig region holds on a terrain map (excavator seed §4.2: the coarse planner
// works on "a terrain map (a 2-D grid of height values)" and the goal configuration of the
// terrain). A cell belongs to a region when its centre lies in the region's swing and radius
// intervals (both closed, so a centre exactly on a shared edge counts in both neighbours). Its
// material in the region is the part of its column between the band's bottom and top. NaN (and any
// other non-finite) cells are unknown: they hold no material and are no surface; they are counted
// apart so that a caller can tell an empty region from an unseen one.
#pragma once

#include <functional>

#include "runtime/control/excavator/height_grid.h"
#include "runtime/planning/dig/dig_region.h"

namespace autoshovel::planning {

struct RegionMaterial {
  double volume = 0;      ///< Σ over known cells of their thickness in the band × cell area [m^3]
  double top_height = 0;  ///< highest known surface in the footprint [m]; NaN when none is known
  int known_cells = 0;
  int unknown_cells = 0;
};

/// The material of `region`'s footprint in [z_min, z_max] on `map_base` (base frame). Cells whose
/// thickness in the band does not exceed `min_thickness` [m] add nothing to the volume: that is
/// the residue a dig leaves, not a dig's worth.
RegionMaterial MeasureMaterial(const control::HeightGrid& map_base, const DigRegion& region,
                               double min_thickness);

/// Calls `visit(ix, iy, height)` for every cell of `map_base` whose centre lies in the polar box
/// swing ∈ [swing_min, swing_max], radius ∈ [radius_min, radius_max] (height may be NaN).
void ForEachCellInPolarBox(const control::HeightGrid& map_base, double swing_min, double swing_max,
                           double radius_min, double radius_max,
                           const std::function<void(int, int, double)>& visit);

}  // namespace autoshovel::planning
