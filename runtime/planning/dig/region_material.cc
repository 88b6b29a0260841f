#include "runtime/planning/dig/region_material.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace autoshovel::planning {

void ForEachCellInPolarBox(const control::HeightGrid& map_base, double swing_min, double swing_max,
                           double radius_min, double radius_max,
                           const std::function<void(int, int, double)>& visit) {
  // Bounding box of the annular sector: its four corners and the points of the outer arc where
  // it crosses an axis direction (ψ = -π/2, 0, π/2, π) inside the swing interval.
  Eigen::Vector2d lo(std::numeric_limits<double>::infinity(),
                     std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  auto include = [&](double swing, double radius) {
    const Eigen::Vector2d p = radius * Eigen::Vector2d(std::cos(swing), std::sin(swing));
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  };
  for (double swing : {swing_min, swing_max}) {
    include(swing, radius_min);
    include(swing, radius_max);
  }
  for (int k = -2; k <= 2; ++k) {
    const double axis = 0.5 * std::numbers::pi * k;
    if (axis >= swing_min && axis <= swing_max) include(axis, radius_max);
  }
  const double res = map_base.resolution();
  const Eigen::Vector2d& origin = map_base.origin();
  const int ix0 = std::max(0, static_cast<int>(std::floor((lo.x() - origin.x()) / res)));
  const int iy0 = std::max(0, static_cast<int>(std::floor((lo.y() - origin.y()) / res)));
  const int ix1 =
      std::min(map_base.nx() - 1, static_cast<int>(std::floor((hi.x() - origin.x()) / res)));
  const int iy1 =
      std::min(map_base.ny() - 1, static_cast<int>(std::floor((hi.y() - origin.y()) / res)));
  for (int iy = iy0; iy <= iy1; ++iy) {
    for (int ix = ix0; ix <= ix1; ++ix) {
      const Eigen::Vector2d c = map_base.CellCenter(ix, iy);
      const double radius = c.norm();
      if (radius < radius_min || radius > radius_max) continue;
      const double swing = std::atan2(c.y(), c.x());
      if (swing < swing_min || swing > swing_max) continue;
      visit(ix, iy, map_base.height(ix, iy));
    }
  }
}

RegionMaterial MeasureMaterial(const control::HeightGrid& map_base, const DigRegion& region,
                               double min_thickness) {
  RegionMaterial out;
  out.top_height = std::numeric_limits<double>::quiet_NaN();
  const double cell_area = map_base.resolution() * map_base.resolution();
  ForEachCellInPolarBox(map_base, region.swing_min, region.swing_max, region.radius_min,
                        region.radius_max, [&](int, int, double height) {
                          if (!std::isfinite(height)) {
                            ++out.unknown_cells;
                            return;
                          }
                          ++out.known_cells;
                          if (std::isnan(out.top_height) || height > out.top_height) {
                            out.top_height = height;
                          }
                          const double thickness = std::min(height, region.z_max) - region.z_min;
                          if (thickness > min_thickness) out.volume += thickness * cell_area;
                        });
  return out;
}

}  // namespace autoshovel::planning
