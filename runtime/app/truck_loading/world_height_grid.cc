#include "runtime/app/truck_loading/world_height_grid.h"

#include <cmath>

namespace autoshovel::app {

control::ObstacleBox ToObstacleBox(const plant::OrientedBox& box) {
  control::ObstacleBox out;
  out.center = box.center.head<2>();
  out.yaw = box.yaw;
  out.half_extents = box.half_extents.head<2>();
  out.z_min = box.center.z() - box.half_extents.z();
  out.z_max = box.center.z() + box.half_extents.z();
  return out;
}

std::vector<control::ObstacleBox> ObstacleBoxes(const plant::World& world,
                                                const std::string& prefix) {
  std::vector<control::ObstacleBox> out;
  for (const plant::OrientedBox& box : world.obstacles) {
    if (box.name.rfind(prefix, 0) == 0) out.push_back(ToObstacleBox(box));
  }
  return out;
}

control::HeightGrid HeightGridFromWorld(const plant::World& world, const Eigen::Vector2d& center,
                                        double half_size, double resolution) {
  const int n = static_cast<int>(std::ceil(2.0 * half_size / resolution));
  control::HeightGrid grid(center - Eigen::Vector2d::Constant(half_size), resolution, n, n);
  const plant::Terrain& terrain = world.terrain;
  for (int ix = 0; ix < n; ++ix) {
    for (int iy = 0; iy < n; ++iy) {
      // The highest terrain cell inside the map cell: a thin ridge (a wall built into the
      // terrain) is never lost between cell centres.
      const Eigen::Vector2d c = grid.CellCenter(ix, iy);
      double top = -std::numeric_limits<double>::infinity();
      const double r = 0.5 * resolution;
      for (double dx = -r + 0.5 * terrain.resolution(); dx < r; dx += terrain.resolution()) {
        for (double dy = -r + 0.5 * terrain.resolution(); dy < r; dy += terrain.resolution()) {
          int tx, ty;
          if (terrain.CellOf(c.x() + dx, c.y() + dy, tx, ty))
            top = std::max(top, terrain.height(tx, ty));
        }
      }
      if (std::isfinite(top)) grid.set_height(ix, iy, top);
    }
  }
  for (const plant::OrientedBox& box : world.obstacles) grid.RaiseBox(ToObstacleBox(box));
  return grid;
}

}  // namespace autoshovel::app
