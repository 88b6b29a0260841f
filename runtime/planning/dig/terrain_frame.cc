#include "runtime/planning/dig/terrain_frame.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace autoshovel::planning {

control::HeightGrid BaseFrameGrid(const control::HeightGrid& map_world,
                                  const Eigen::Isometry3d& T_world_base,
                                  const Eigen::Vector2d& origin_base, double resolution, int nx,
                                  int ny, double max_tilt) {
  if (!T_world_base.matrix().allFinite()) {
    throw std::invalid_argument("BaseFrameGrid: T_world_base is not finite");
  }
  if (!(std::isfinite(max_tilt) && max_tilt >= 0)) {
    throw std::invalid_argument("BaseFrameGrid: max_tilt must be finite and >= 0 rad, got " +
                                std::to_string(max_tilt));
  }
  const double tilt = std::acos(std::clamp(T_world_base.linear()(2, 2), -1.0, 1.0));
  if (tilt > max_tilt) {
    throw std::invalid_argument("BaseFrameGrid: the base is tilted " + std::to_string(tilt) +
                                " rad from level, more than max_tilt " + std::to_string(max_tilt) +
                                " rad");
  }
  control::HeightGrid map_base(origin_base, resolution, nx, ny);
  const Eigen::Isometry3d T_base_world = T_world_base.inverse();
  for (int iy = 0; iy < ny; ++iy) {
    for (int ix = 0; ix < nx; ++ix) {
      const Eigen::Vector2d c = map_base.CellCenter(ix, iy);
      const Eigen::Vector3d p_world = T_world_base * Eigen::Vector3d(c.x(), c.y(), 0.0);
      const double h_world = map_world.HeightAt(p_world.x(), p_world.y());
      if (!std::isfinite(h_world)) continue;  // stays NaN: unknown
      // The surface point's base z; to first order in the tilt it lies above this cell's centre.
      map_base.set_height(ix, iy,
                          (T_base_world * Eigen::Vector3d(p_world.x(), p_world.y(), h_world)).z());
    }
  }
  return map_base;
}

}  // namespace autoshovel::planning
