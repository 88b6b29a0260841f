// The elevation map the look-ahead tests the linkage against (excavator seed §4.5: a 2-D grid of
// heights built from the scanners), reduced to what the test needs: square cells, a height per cell
// [m], NaN where nothing is known. Kept minimal so that perception's map (runtime/perception/
// elevation_map.h, layer "elevation") can be copied into it cell by cell without this library
// depending on perception.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <vector>

#include "runtime/control/excavator/obstacle_box.h"

namespace autoshovel::control {

class HeightGrid {
 public:
  /// `origin`: the outer corner of cell (0, 0) (smallest x and y) [m]; `resolution` [m] > 0;
  /// nx, ny >= 1 cells; every cell starts at `height` (NaN: unknown). Throws
  /// std::invalid_argument otherwise.
  HeightGrid(const Eigen::Vector2d& origin, double resolution, int nx, int ny,
             double height = std::numeric_limits<double>::quiet_NaN());

  int nx() const { return nx_; }
  int ny() const { return ny_; }
  double resolution() const { return resolution_; }
  const Eigen::Vector2d& origin() const { return origin_; }

  /// The cell containing (x, y); false outside the grid (or for a non-finite point).
  bool CellOf(double x, double y, int& ix, int& iy) const;
  Eigen::Vector2d CellCenter(int ix, int iy) const;
  double height(int ix, int iy) const { return heights_[Index(ix, iy)]; }
  void set_height(int ix, int iy, double h) { heights_[Index(ix, iy)] = h; }
  /// Height of the cell under (x, y); NaN outside the grid or unknown.
  double HeightAt(double x, double y) const;

  /// Raises to `box.z_max` every cell whose square overlaps the box's footprint (so that a thin
  /// obstacle is never lost between cell centres), and cells within half a cell diagonal of it.
  /// Cells keep a larger height.
  void RaiseBox(const ObstacleBox& box);

 private:
  std::size_t Index(int ix, int iy) const {
    return static_cast<std::size_t>(iy) * static_cast<std::size_t>(nx_) +
           static_cast<std::size_t>(ix);
  }

  Eigen::Vector2d origin_;
  double resolution_;
  int nx_, ny_;
  std::vector<double> heights_;
};

}  // namespace autoshovel::control
