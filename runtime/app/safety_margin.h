// The clearance between the loader and the yard's obstacles, in plan view: what each cycle's
// `safety_margin_m` records (issue 6: "no cycle ever closer to an obstacle than the safety
// distance"). Ground truth from the simulator, not the map: it judges the planner, so it must
// not share the planner's errors.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "runtime/perception/machine_footprint.h"
#include "runtime/plant/world.h"

namespace autoshovel::app {

using Quad = std::array<Eigen::Vector2d, 4>;

/// The two rectangles of a loader footprint (front frame from the hinge, rear frame behind it).
std::array<Quad, 2> FootprintQuads(const perception::MachineFootprint& footprint);
/// An obstacle box's outline in plan view.
Quad BoxQuad(const plant::OrientedBox& box);
/// Distance between two convex quadrilaterals; 0 when they overlap [m].
double QuadDistance(const Quad& a, const Quad& b);

struct Clearance {
  double distance = 0;  ///< [m]; +inf without obstacles
  int obstacle = -1;    ///< index of the nearest obstacle
};
/// The smallest distance from the footprint to any of `obstacles`.
Clearance FootprintClearance(const perception::MachineFootprint& footprint,
                             const std::vector<plant::OrientedBox>& obstacles);

}  // namespace autoshovel::app
