#include "runtime/app/shovel_job/clearance_record.h"

#include <algorithm>
#include <numbers>

#include "runtime/app/safety_margin.h"

namespace autoshovel::app {

void ClearanceRecord::Update(const perception::MachineFootprint& footprint,
                             const std::vector<plant::OrientedBox>& obstacles,
                             const plant::MachineState& s, double path_error, double t0,
                             const CycleLog& log) {
  constexpr double kDeg = std::numbers::pi / 180.0;
  const Clearance c = FootprintClearance(footprint, obstacles);
  min_clearance_ = std::min(min_clearance_, c.distance);
  const bool violating = c.distance < safety_distance_;
  if (violating && !in_violation_) {
    ++violations_;
    log.Say("SAFETY: " + Fixed(c.distance, 2) + " m from " + obstacles[c.obstacle].name +
            " at t = " + Fixed(s.time - t0, 2) + " s, hinge (" + Fixed(s.hinge_xy.x(), 2) + ", " +
            Fixed(s.hinge_xy.y(), 2) + "), heading " + Fixed(s.heading / kDeg, 1) +
            " deg, articulation " + Fixed(s.articulation / kDeg, 1) + " deg, path error so far " +
            Fixed(path_error, 2) + " m");
  }
  in_violation_ = violating;
}

}  // namespace autoshovel::app
