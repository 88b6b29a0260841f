// What a look-ahead stopped for, for the log: the map's view of the nearest sure obstacle cell
// and, from the simulation's truth, how far that cell lies from the nearest real obstacle (the
// map's blur at a wall; docs/main_job.md).
#pragma once

#include <Eigen/Core>
#include <string>

#include "runtime/perception/grid_map.h"
#include "runtime/plant/world.h"

namespace autoshovel::app {

std::string SureCellReport(const perception::GridMap& map, const Eigen::Vector2d& cell,
                           const plant::World& world);

}  // namespace autoshovel::app
