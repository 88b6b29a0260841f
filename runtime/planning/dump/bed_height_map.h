// The truck-bed terrain map of the dump planner (excavator seed §4.3): a 2-D grid of soil heights
// over the opening of the truck bed, 15 cm cells by default, filled from the 3-D points the
// scanner returns while the excavator swings back from the truck. Truck recognition (§4.1) gives
// the bed's corner points, hence the bed frame and its size; every point whose plan position
// falls outside the bed (the cab, the walls' outside, the ground) is dropped here, as §4.3 asks.
//
// Bed frame: origin at one corner of the bed opening, x along the bed (its length), y across it
// (its width), z along the bed's normal, up. Heights are bed-frame z; the planner only compares
// heights with each other, so whether z = 0 is the floor or the rim is the caller's convention.
//
// Grid layout: cell (ix, iy) covers x ∈ [ix·c, (ix+1)·c), y ∈ [iy·c, (iy+1)·c); the matrices have
// one row per x cell and one column per y cell. A bed whose size is not a multiple of c gets a
// last, partial row or column (its centre may lie outside the bed: the planner's wall margin
// never lets the bucket there). Unknown cells hold 0 in `heights()`, never NaN; `known_mask()`
// says which cells carry data.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <limits>
#include <optional>
#include <span>

#include "runtime/planning/dump/cell_mask.h"

namespace autoshovel::planning {

/// The inside of the bed opening as truck recognition measures it (§4.1).
struct BedGeometry {
  double length_m = 0;  ///< along bed x [m]
  double width_m = 0;   ///< along bed y [m]
};

/// How the points falling in one cell become its height.
enum class CellReduction {
  kMean,  ///< average: robust to the scanner's range noise
  kMax,   ///< highest point: conservative against spill over a heap's top
};

struct BedHeightMapConfig {
  double cell_size_m = 0.15;  ///< §4.3: 15 cm cells [m]
  CellReduction reduction = CellReduction::kMean;
  /// Points outside [min_height_m, max_height_m] in bed z are ignored, e.g. returns from dust or
  /// from the wall tops when the bed frame's z = 0 is the floor. Infinite bounds keep all.
  double min_height_m = -std::numeric_limits<double>::infinity();
  double max_height_m = std::numeric_limits<double>::infinity();
};

class BedHeightMap {
 public:
  /// An all-unknown grid over `bed`. Throws std::invalid_argument when a size or the cell size
  /// is not finite and positive, or when the grid would exceed a million cells.
  BedHeightMap(const BedGeometry& bed, double cell_size_m);

  /// Bins world-frame points into the grid: each is mapped into the bed frame by T_world_bed⁻¹,
  /// points outside the bed or the height window are dropped, each remaining cell takes the
  /// mean or max of its points. Throws std::invalid_argument on a non-finite point or pose.
  static BedHeightMap FromWorldPoints(const BedGeometry& bed, const Eigen::Isometry3d& T_world_bed,
                                      std::span<const Eigen::Vector3d> p_world,
                                      const BedHeightMapConfig& config = {});
  /// The same with points already in the bed frame.
  static BedHeightMap FromBedPoints(const BedGeometry& bed, std::span<const Eigen::Vector3d> p_bed,
                                    const BedHeightMapConfig& config = {});

  const BedGeometry& bed() const { return bed_; }
  double cell_size_m() const { return cell_size_m_; }
  int cells_x() const { return static_cast<int>(heights_.rows()); }
  int cells_y() const { return static_cast<int>(heights_.cols()); }

  /// Bed-frame (x, y) of the centre of cell (ix, iy) [m].
  Eigen::Vector2d CellCentre(int ix, int iy) const;
  /// The cell holding bed-frame plan position `p_bed_xy`; nullopt outside the bed (the bed's far
  /// edges x = length, y = width belong to the last cells).
  std::optional<Eigen::Vector2i> CellOf(const Eigen::Vector2d& p_bed_xy) const;

  bool known(int ix, int iy) const { return known_(ix, iy); }
  double height(int ix, int iy) const { return heights_(ix, iy); }
  /// Sets a cell's height and marks it known. Throws std::invalid_argument on a non-finite
  /// height, std::out_of_range on a cell outside the grid.
  void SetHeight(int ix, int iy, double height_m);
  /// Forgets a cell (height back to 0, unknown).
  void SetUnknown(int ix, int iy);

  const Eigen::MatrixXd& heights() const { return heights_; }
  const CellMask& known_mask() const { return known_; }
  int known_count() const { return static_cast<int>(known_.count()); }

 private:
  void CheckCell(int ix, int iy) const;

  BedGeometry bed_;
  double cell_size_m_;
  Eigen::MatrixXd heights_;  ///< bed-frame z per cell [m]; 0 where unknown
  CellMask known_;
};

}  // namespace autoshovel::planning
