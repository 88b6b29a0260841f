// A simulated expert operator who picks where to shovel, for the demonstrations the Eq. (18)
// weights are tuned on (wheel-loader seed §5). It must not be Eq. (12)–(18) in disguise, or
// the fit would be circular, so it looks at different things in different ways:
//
// - it sees the true terrain and the true obstacle boxes, not the perceived map;
// - fill: the material in a bite of the bucket's width and `bite_depth` ahead of the entry
//   point, relative to the best bite among the candidates (Eq. 15 only compares three strips);
// - balance: |left − right| / (left + right) of that bite, a linear penalty (Eq. 13 is
//   quadratic in a moment against a threshold);
// - clearance: the straight corridor from the loader to the entry point, the bucket's width
//   plus a body margin, against the obstacle boxes; comfortable beyond `comfort_distance`,
//   never closer than `veto_distance` (Eq. 14 uses the Dubins path and the map's cells);
// - effort: the straight distance and the heading changes needed (Eq. 16 uses path length);
// - squareness: cos of the entry offset from the face's normal (Eq. 17 uses path curvature);
// - inconsistency: Gumbel noise on the utility, so the same scene is not always answered the
//   same way (a softmax choice at temperature `noise`).
#pragma once

#include <cstdint>
#include <vector>

#include "runtime/planning/shovel_point_selection.h"
#include "runtime/plant/world.h"

namespace autoshovel::identification {

struct ExpertModel {
  double fill = 1.0;              ///< weight of the relative bite volume
  double balance = 0.8;           ///< weight of the left/right imbalance (a penalty)
  double clearance = 0.7;         ///< weight of the corridor's clearance / comfort distance
  double effort = 0.5;            ///< weight of the driving effort (a penalty)
  double squareness = 0.3;        ///< weight of cos(entry offset)
  double noise = 0.05;            ///< Gumbel scale: the operator's inconsistency [utility]
  double bite_depth = 1.5;        ///< the bite's depth into the pile [m]
  double comfort_distance = 2.5;  ///< clearance beyond which the expert is at ease [m]
  double veto_distance = 0.6;     ///< the expert never comes closer than this [m]
  double body_half_width = 1.8;   ///< the corridor's half width [m]
  double effort_length = 20.0;    ///< driving distance that costs one unit of effort [m]
};

/// The expert's view of one candidate (the terms above, before weighting).
struct ExpertTerms {
  double bite = 0;       ///< material in the bite [m³]
  double imbalance = 0;  ///< |left − right| / (left + right), 0 without material
  double clearance = 0;  ///< corridor and bite to the nearest obstacle box [m]
  double effort = 0;     ///< distance / effort_length + heading changes / π
  double squareness = 0;
};

/// Distance from `xy` to the footprint (xy rectangle) of `box`, 0 inside [m].
double FootprintDistance(const plant::OrientedBox& box, const Eigen::Vector2d& xy);

ExpertTerms ExpertView(const plant::World& world, const planning::CandidatePose& candidate,
                       const planning::Pose2& start, double bucket_width, const ExpertModel& model);

/// The index of the candidate the expert picks, or −1 when every candidate is vetoed. The
/// noise comes from `seed` (one Gumbel draw per candidate, in order).
int ChooseLikeAnExpert(const plant::World& world,
                       const std::vector<planning::CandidatePose>& candidates,
                       const planning::Pose2& start, double bucket_width, const ExpertModel& model,
                       std::uint64_t seed);

}  // namespace autoshovel::identification
