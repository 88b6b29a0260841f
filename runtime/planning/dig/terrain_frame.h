// The dig planners take the terrain map in the excavator base frame (origin on the swing axis at
// ground level, x forward, z up), because the dig sector, the regions and the arm's reach are all
// polar about the swing axis. A map kept in the world frame (perception's elevation map) is
// resampled into it once per plan with this function.
#pragma once

#include <Eigen/Geometry>

#include "runtime/control/excavator/height_grid.h"

namespace autoshovel::planning {

/// The base-frame map (origin_base: outer corner of cell (0, 0), `resolution`, nx × ny cells) of
/// `map_world` seen from an excavator at T_world_base. Each base cell takes the world cell under
/// its centre (nearest cell, no interpolation: a dig is far coarser than a cell) and that
/// surface point's base-frame height; NaN where the world map is unknown or does not reach.
/// A 2.5-D map stays 2.5-D only if the base is nearly level: throws std::invalid_argument when
/// T_world_base is not finite, its base z axis is tilted by more than `max_tilt` [rad] from the
/// world's, or the grid arguments are invalid (HeightGrid's rules).
control::HeightGrid BaseFrameGrid(const control::HeightGrid& map_world,
                                  const Eigen::Isometry3d& T_world_base,
                                  const Eigen::Vector2d& origin_base, double resolution, int nx,
                                  int ny, double max_tilt = 0.05);

}  // namespace autoshovel::planning
