#include "runtime/control/excavator/height_grid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace autoshovel::control {

HeightGrid::HeightGrid(const Eigen::Vector2d& origin, double resolution, int nx, int ny,
                       double height)
    : origin_(origin), resolution_(resolution), nx_(nx), ny_(ny) {
  if (!origin.allFinite() || !(std::isfinite(resolution) && resolution > 0) || nx < 1 || ny < 1) {
    throw std::invalid_argument("HeightGrid: origin must be finite, resolution > 0, nx, ny >= 1");
  }
  heights_.assign(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny), height);
}

bool HeightGrid::CellOf(double x, double y, int& ix, int& iy) const {
  const double fx = std::floor((x - origin_.x()) / resolution_);
  const double fy = std::floor((y - origin_.y()) / resolution_);
  if (!(fx >= 0 && fx < nx_ && fy >= 0 && fy < ny_)) return false;  // NaN fails too
  ix = static_cast<int>(fx);
  iy = static_cast<int>(fy);
  return true;
}

Eigen::Vector2d HeightGrid::CellCenter(int ix, int iy) const {
  return origin_ + resolution_ * Eigen::Vector2d(ix + 0.5, iy + 0.5);
}

double HeightGrid::HeightAt(double x, double y) const {
  int ix = 0, iy = 0;
  if (!CellOf(x, y, ix, iy)) return std::numeric_limits<double>::quiet_NaN();
  return height(ix, iy);
}

void HeightGrid::RaiseBox(const ObstacleBox& box) {
  Validate(box, "HeightGrid::RaiseBox");
  Eigen::Vector2d corners[4];
  box.Corners(corners);
  Eigen::Vector2d lo = corners[0], hi = corners[0];
  for (const Eigen::Vector2d& c : corners) {
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  const int ix0 =
      std::max(0, static_cast<int>(std::floor((lo.x() - origin_.x()) / resolution_)) - 1);
  const int iy0 =
      std::max(0, static_cast<int>(std::floor((lo.y() - origin_.y()) / resolution_)) - 1);
  const int ix1 =
      std::min(nx_ - 1, static_cast<int>(std::floor((hi.x() - origin_.x()) / resolution_)) + 1);
  const int iy1 =
      std::min(ny_ - 1, static_cast<int>(std::floor((hi.y() - origin_.y()) / resolution_)) + 1);
  // Every cell that overlaps the footprint has its centre within half a diagonal of it; raising
  // all such cells over-approximates by less than one cell, never misses an overlapping one.
  const double half_diagonal = resolution_ * std::sqrt(0.5);
  for (int iy = iy0; iy <= iy1; ++iy) {
    for (int ix = ix0; ix <= ix1; ++ix) {
      if (box.FootprintDistance(CellCenter(ix, iy)) <= half_diagonal) {
        double& h = heights_[Index(ix, iy)];
        if (std::isnan(h) || h < box.z_max) h = box.z_max;
      }
    }
  }
}

}  // namespace autoshovel::control
