// The coarse dig planner (excavator seed §4.2, Fig. 11–12): from the terrain map and the goal
// configuration of the terrain it plans the sequence of dig regions, each handed in turn to the
// refined planner. "The coarse planner ensures even performance over a large number of digs."
//
// Regions. The dig sector (a swing interval × a radius interval, base frame) is cut into
// `columns()` equal swing columns no wider than `region_swing_width`, and into height bands
// `region_height` tall stacked up from the goal floor (band k is [floor + k·h, floor + (k+1)·h]);
// as many bands as the highest known surface in the sector needs. Both are anchored to the
// sector and the floor, never to the current surface, so a region keeps its (column, band)
// identity while it is dug.
//
// Order (Fig. 12, the expert operator's strategy): "material is removed from left to right, and
// from the top of the face to the bottom". Left is the larger swing, the truck's side. The seed
// does not say in words which of the two is the outer loop; the default reads it as bands first,
// top to bottom, each band swept left to right (kTopDownThenLeftToRight), because that is the
// order under which every one of the seed's three reasons holds at every dig:
//   - "less force is required ... because it is not necessary then to work against the weight of
//     the material up above": with bands first, when band k is dug nothing is left above it
//     anywhere in the sector; with columns first, the bottom of a column is dug beside the full
//     height of the columns to its right;
//   - "clearing material away from the top minimizes the range shadows cast on the face" by the
//     cab-mounted scanner: the whole top comes off first, not one column's;
//   - "by digging from left to right, the implements do not need to be raised as high to clear
//     material when swinging to the truck": within a band, the regions swung over on the way to
//     the truck (those to the left) are already down to the current band, so the bucket, which
//     leaves the cut at about that height, needs no extra lift to clear them.
// The other reading, columns first (kLeftToRightThenTopDown), is selectable.
//
// Re-offering. The planner holds no per-dig state: NextRegion(map) returns the first region in
// that order that still holds material, measured on the map it is given. Call it after every
// dig with the new scan; a region is offered again until it is dug down to its band's bottom
// (cells thinner than `min_material_thickness` there are residue) and a region with less than
// `min_region_volume` in its band is skipped. The one state kept is the set of regions the caller
// marked exhausted (the refined planner found no feasible dig there), skipped from then on so
// that an unreachable remnant does not stall the sequence.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "runtime/control/excavator/height_grid.h"
#include "runtime/planning/dig/dig_region.h"

namespace autoshovel::planning {

enum class DigRegionOrder {
  kTopDownThenLeftToRight,  ///< bands from the top; within a band, columns from the left
  kLeftToRightThenTopDown,  ///< columns from the left; within a column, bands from the top
};

struct CoarseDigConfig {
  DigSector sector;
  /// Widest swing interval of one region [rad]: about the bucket width plus a dig's spread at
  /// mid radius (0.25 rad is 1.6 m at 6.5 m, a 1.3 m bucket and its spill).
  double region_swing_width = 0.25;
  /// Height of one band [m]: about the deepest cut a dig takes, so a band is one pass deep.
  double region_height = 1.0;
  /// Cells thinner than this in a band are residue, not material to dig [m]: about the map's
  /// height noise plus what a cut leaves uneven.
  double min_material_thickness = 0.1;
  /// A region holding less than this in its band is skipped [m^3] (a tenth of a 1.2 m^3 bucket).
  double min_region_volume = 0.1;
  DigRegionOrder order = DigRegionOrder::kTopDownThenLeftToRight;
};

/// Throws std::invalid_argument naming the field ("CoarseDigConfig.sector.radius_max: ...").
void Validate(const CoarseDigConfig& config);

class CoarseDigPlanner {
 public:
  /// Throws std::invalid_argument on an invalid config.
  explicit CoarseDigPlanner(const CoarseDigConfig& config);

  /// Every region that holds material on `map_base` (a terrain map in the excavator base frame),
  /// in dig order, exhausted ones included, each measured (DigRegion::volume, top_height, cells).
  std::vector<DigRegion> RegionsWithMaterial(const control::HeightGrid& map_base) const;

  /// The region to dig next on `map_base`: the first of RegionsWithMaterial not marked exhausted;
  /// nullopt when the sector is dug down to the goal floor (or all that is left is exhausted).
  std::optional<DigRegion> NextRegion(const control::HeightGrid& map_base) const;

  /// Skip `region` (same column and band) from now on.
  void MarkExhausted(const DigRegion& region);
  bool IsExhausted(const DigRegion& region) const;
  void ClearExhausted() { exhausted_.clear(); }

  /// The region (column, band) without measuring it; column in [0, columns()), band >= 0.
  DigRegion Region(int column, int band) const;
  /// How many bands the highest known surface in the sector of `map_base` needs (0: none above
  /// the floor, or nothing known).
  int BandCount(const control::HeightGrid& map_base) const;
  int columns() const { return columns_; }
  const CoarseDigConfig& config() const { return config_; }

 private:
  CoarseDigConfig config_;
  int columns_ = 1;
  double column_width_ = 0;  ///< [rad]
  std::vector<DigRegion> exhausted_;
};

}  // namespace autoshovel::planning
