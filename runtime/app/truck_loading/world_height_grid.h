// The elevation map the excavator's look-ahead tests its linkage against (excavator seed §4.5),
// taken from the simulated yard: the terrain's surface at each cell centre, raised over every box
// in the yard (truck walls and cab, people). The seed builds this map from its scanners; here the
// world stands in for a perfect scan, so that the look-ahead and the stop are tested on their
// own (a person is in the map from the instant they step in: the scanners' 20 Hz revolution adds
// at most 0.05 s to the reaction, well inside the look-ahead's 2.5 s).
#pragma once

#include <vector>

#include "runtime/control/excavator/height_grid.h"
#include "runtime/control/excavator/obstacle_box.h"
#include "runtime/plant/world.h"

namespace autoshovel::app {

/// A world box as the look-ahead's vertical box.
control::ObstacleBox ToObstacleBox(const plant::OrientedBox& box);

/// The boxes of `world` whose name starts with `prefix` ("" for all).
std::vector<control::ObstacleBox> ObstacleBoxes(const plant::World& world,
                                                const std::string& prefix = "");

/// A `half_size` × `half_size` square map around `center` (world xy) at `resolution`.
control::HeightGrid HeightGridFromWorld(const plant::World& world, const Eigen::Vector2d& center,
                                        double half_size, double resolution);

}  // namespace autoshovel::app
