#include "runtime/app/shovel_job/sure_cell_report.h"

#include "runtime/app/safety_margin.h"
#include "runtime/app/shovel_job/cycle_log.h"

namespace autoshovel::app {

std::string SureCellReport(const perception::GridMap& map, const Eigen::Vector2d& cell,
                           const plant::World& world) {
  const std::vector<plant::OrientedBox>& obstacles = world.obstacles;
  perception::Index index;
  if (!map.IndexOf(cell, index)) return "nearest sure cell off the map";
  std::string text = "nearest sure cell (" + Fixed(cell.x(), 2) + ", " + Fixed(cell.y(), 2) +
                     "): height " + Fixed(map.at("elevation", index), 2) + " m, obstacle " +
                     Fixed(map.at("obstacle_confidence", index), 2) + " (steep " +
                     Fixed(map.at("steep_obstacle_confidence", index), 2) + "), pile " +
                     Fixed(map.at("pile_confidence", index), 2);
  // A footprint shrunk to the cell's centre: FootprintClearance gives the nearest box.
  perception::MachineFootprint point;
  point.hinge_xy = cell;
  const Clearance truth = FootprintClearance(point, obstacles);
  if (truth.obstacle >= 0) {
    text += "; simulation truth: " + Fixed(truth.distance, 2) + " m from " +
            obstacles[static_cast<std::size_t>(truth.obstacle)].name + ", ground " +
            Fixed(world.terrain.HeightAt(cell.x(), cell.y()), 2) + " m";
  }
  return text;
}

}  // namespace autoshovel::app
