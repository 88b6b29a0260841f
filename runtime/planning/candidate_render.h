// Pictures of shovel point selection in the style of the wheel-loader seed's Fig. 19: the map
// (pile heights in colour, ground grey, obstacles dark red, unknown dark), the top-ranked
// candidates as arrows pointing along their entry heading at the point where the bucket meets
// the pile, coloured by score, and the best one in red with its path. With a baseline ranking
// the PNG has two panels side by side: Algorithm 2 (Eq. 18) and Chen et al. (2024).
#pragma once

#include <string>
#include <vector>

#include "runtime/perception/grid_map.h"
#include "runtime/planning/chen2024_baseline.h"
#include "runtime/planning/shovel_point_selection.h"

namespace autoshovel::planning {

struct CandidateRenderOptions {
  int pixels_per_cell = 4;
  int top = 20;               ///< arrows drawn per panel (seed Fig. 19: 20)
  double arrow_length = 1.8;  ///< [m]
  double margin = 3.0;        ///< around the known cells, the loader and the arrows [m]
};

/// Writes the picture to `png_path` (the baseline panel only when `baseline` is non-null).
/// `T_world_hinge` is the loader's pose, drawn as its outline. Throws std::runtime_error if
/// the file cannot be written.
void WriteCandidatePng(const perception::GridMap& map, const ShovelPointResult& result,
                       const std::vector<Chen2024Candidate>* baseline, const Pose2& T_world_hinge,
                       const LoaderGeometry& loader, const std::string& png_path,
                       const CandidateRenderOptions& options = {});

}  // namespace autoshovel::planning
