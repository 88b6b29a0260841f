// The crowd look-ahead of the main job (docs/main_job.md): from contact on, crowding ends when
// what the scoop will sweep comes too close to an obstacle the map is sure of, straight ahead.
// The planned path's clearance (d_min) does not cover the crowd: a pile heaped against a wall
// draws the bucket towards the wall.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "runtime/control/scooping_strategies.h"
#include "runtime/model/description.h"
#include "runtime/perception/grid_map.h"
#include "runtime/perception/machine_footprint.h"

namespace autoshovel::app {

/// Centres of the map's *sure* obstacle cells [m, world]: class obstacle with obstacle
/// confidence ("steep_obstacle_confidence" where the map has it, semantic_map.h) ≥
/// `min_confidence` and ≥ the
/// pile confidence + `margin`, plus the cells of confidence ≥ 0.95 within `growth_cells` cells of
/// those. A pile's top the camera saw only obliquely comes out of Eq. (11) as obstacle by its
/// height with both confidences middling (obstacle 0.6–0.8, pile 0.4–0.9): the bucket already in
/// the pile must not stop for it. A wall's face next to a pile's crest carries pile evidence too
/// (the boundary is blurred), hence the growth.
std::vector<Eigen::Vector2d> SureObstacleCells(const perception::GridMap& map, double margin,
                                               int growth_cells, double min_confidence = 0.95);

/// The farthest horizontal reach of a loader's bucket tip from the hinge while scooping from
/// (q_boom, q_bucket): the boom raised by every Stairway lift and the exit lift, the bucket as
/// now, or levelled (model::BucketLevelAttitude) and shaken about level [m].
double ScoopReach(const model::MachineDescription& machine, double q_boom, double q_bucket,
                  const control::StrategyParameters& strategy);

/// Distance from the front edge (`front_length` ahead of the hinge along `heading`) to the
/// nearest of `cells` in the corridor of ±`half_width` ahead, less half a cell (the cells are
/// centres) [m]; +inf when none is ahead. `nearest`, if given, receives the index in `cells` of
/// that nearest cell (−1 when none).
double DistanceAhead(const std::vector<Eigen::Vector2d>& cells, const Eigen::Vector2d& hinge_xy,
                     double heading, double half_width, double front_length, double cell_size,
                     int* nearest = nullptr);

/// Plan-view distance from the loader `footprint` (both frames) to the nearest of `cells`, less
/// half a cell [m]; +inf when there are none. The crowd look-ahead's side check: a bucket driven
/// into a pile at an angle to a wall closes on the wall beside it, not ahead of it.
double FootprintDistanceToCells(const perception::MachineFootprint& footprint,
                                const std::vector<Eigen::Vector2d>& cells, double cell_size,
                                int* nearest = nullptr);

}  // namespace autoshovel::app
