// The refined planner's candidate actions in one dig region (excavator seed §4.2: "the refined
// planner searches through compact task parameters within the bounds specified by the coarse
// planner"): a grid over swing × radius × depth × drag length. Entry swings are the centres of
// `swing_samples` equal slices of the region's swing interval (3 slices of a 0.25 rad region are
// 0.75 m wide at 9 m, narrower than the 1.3 m bucket, so the slices' edges are dug too); entry
// radii are evenly spaced over the region's radius interval, both ends included (a drag only
// reaches material inside its entry radius, so the outer edge must be an entry), no more than
// `radius_step` apart. The entry height is the map's surface there. Depths and drag lengths are
// evenly spaced over their configured bounds, both ends included.
//
// The bounds the coarse planner specifies are the region's: a cut is taken only into the
// region's material and never below the region's band bottom (z_min, which is never below the
// goal floor), so the bands come off in the Fig. 12 order. At an entry point where the deepest
// allowed cut is shallower than a depth sample, that sample becomes the cut down to the band
// bottom; deeper samples there would repeat it and are rejected as such.
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/control/excavator/height_grid.h"
#include "runtime/planning/dig/dig_action.h"
#include "runtime/planning/dig/dig_region.h"

namespace autoshovel::planning {

struct DigGridConfig {
  int swing_samples = 3;     ///< entry swings across the region (>= 1)
  double radius_step = 0.5;  ///< largest spacing of entry radii [m] (> 0)
  double depth_min = 0.2;    ///< [m] (> 0)
  double depth_max = 0.8;    ///< [m] (>= depth_min)
  int depth_samples = 4;     ///< (>= 1; 1: depth_min only)
  double drag_min = 1.0;     ///< [m] (> 0)
  double drag_max = 3.0;     ///< [m] (>= drag_min)
  int drag_samples = 5;      ///< (>= 1; 1: drag_min only)
  /// Cuts shallower than this are not worth a dig [m] (>= 0): set it to the coarse planner's
  /// min_material_thickness so that what the coarse planner counts as material can be cut.
  double min_cut_depth = 0.1;
};

/// Throws std::invalid_argument naming the field (prefixed with `what`).
void Validate(const DigGridConfig& config, const std::string& what);

/// Why a grid point is not a candidate before any geometric check.
enum class DigGridRejection {
  kNone,
  kUnknownSurface,  ///< the map is unknown (NaN) or absent at the entry point
  kNoMaterial,      ///< the surface there is not min_cut_depth above the band bottom
  kRepeatedCut,     ///< a shallower depth sample already cuts to the band bottom there
};

struct DigGridPoint {
  std::array<int, 4> index{};  ///< swing, radius, depth, drag sample
  DigAction action;            ///< entry height from the map, depth clipped to the band bottom
  DigGridRejection rejection = DigGridRejection::kNone;
  std::string why;  ///< for a rejection
};

/// Samples per dimension (swing, radius, depth, drag) for `region`.
std::array<int, 4> DigGridExtent(const DigGridConfig& config, const DigRegion& region);

/// Every grid point, swing slowest and drag fastest (index order), on `map_base`.
std::vector<DigGridPoint> EnumerateDigGrid(const DigGridConfig& config, const DigRegion& region,
                                           const control::HeightGrid& map_base);

}  // namespace autoshovel::planning
