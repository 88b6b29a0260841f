// The baseline of the wheel-loader seed's §7.3 (Fig. 19, Table 4): the shovel point selection of
// Chen et al. (2024), which "integrates four indicators: convexity, inclination, slope, and
// distance traveled" (seed §2). The seed names the indicators and nothing more; this is our
// reading of them, on the same candidates (pile-front points × entry angles) as Algorithm 2 so
// that the two rankings differ only by their criteria:
//
// - a quadratic surface z = a u² + b u v + c v² + d u + e v + f is fitted by least squares to
//   the heights above ground of the known cells within `fit_radius` of the point, in the
//   candidate's frame (u along the entry heading, v to its left) — the local fit of Magnusson
//   & Almqvist (2011), on which Chen et al. build;
// - convexity   = −2c: the surface's curvature across the bucket, positive on a ridge [1/m];
// - inclination = d / √(d² + e²): the cosine of the angle between the entry heading and the
//   uphill direction of the face (1: the bucket meets the face square on) [-];
// - slope       = atan √(d² + e²): the steepness of the face, steeper holding more material
//   per metre of crowd [rad];
// - distance    = the straight-line distance from the loader's hinge to the point [m] — no path,
//   no obstacles: the baseline knows nothing of the machine's surroundings, which is the gap
//   the seed's safety score fills (§7.3: "our approach tends to recommend safer shovel points").
//
// Each indicator is min–max normalised over the candidates of the same pile (distance
// inverted: nearer is better) and the four are summed with weights, equal by default (the
// seed gives none).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "runtime/perception/grid_map.h"
#include "runtime/perception/pile_extraction.h"
#include "runtime/planning/shovel_point_selection.h"

namespace autoshovel::planning {

struct Chen2024Config {
  double w_convexity = 0.25;
  double w_inclination = 0.25;
  double w_slope = 0.25;
  double w_distance = 0.25;
  double fit_radius = 1.5;  ///< cells within this of the point enter the quadratic fit [m]
};

struct Chen2024Indicators {
  double convexity = 0;    ///< −2c [1/m]
  double inclination = 0;  ///< cos of heading vs uphill [-]
  double slope = 0;        ///< [rad]
  double distance = 0;     ///< [m]
};

struct Chen2024Candidate {
  CandidatePose pose;
  Chen2024Indicators raw;
  Chen2024Indicators normalized;  ///< each in [0, 1], 1 best
  double score = 0;               ///< weighted sum of `normalized`
};

/// The four indicators of one candidate (raw, before normalisation). `hinge_xy` is the loader's
/// hinge now.
Chen2024Indicators Chen2024IndicatorsAt(const perception::GridMap& map,
                                        const Eigen::Vector3d& ground_plane,
                                        const CandidatePose& pose, const Eigen::Vector2d& hinge_xy,
                                        const Chen2024Config& config = {});

/// Ranks `candidates` (GenerateCandidates) by the baseline, best first (ties keep their order).
std::vector<Chen2024Candidate> RankChen2024(const perception::GridMap& map,
                                            const Eigen::Vector3d& ground_plane,
                                            const std::vector<CandidatePose>& candidates,
                                            const Eigen::Vector2d& hinge_xy,
                                            const Chen2024Config& config = {});

}  // namespace autoshovel::planning
