// The pile elevation map (wheel-loader seed §4.3, last paragraph): the cells the fusion classed
// as pile, split into connected piles (one per bin in a mixing station), each with its volume
// above the ground plane and its boundary, ordered along the outline; the part of the boundary
// that borders ground is the shovelling front from which shovel points are chosen (§5).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "runtime/perception/semantic_map.h"

namespace autoshovel::perception {

struct BoundaryPoint {
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  ///< cell centre, world [m]
  float height = 0;                              ///< [m]
  bool front = false;  ///< borders ground cells (reachable), not walls, obstacles or unknown
};

struct ExtractedPile {
  std::vector<Index> cells;
  double volume = 0;       ///< above the ground plane [m³]
  double peak_height = 0;  ///< above the ground plane [m]
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  std::vector<BoundaryPoint> boundary;  ///< the outline, in order (OpenCV contour order)
};

struct PileExtractionConfig {
  int min_cells = 6;  ///< smaller components are noise, not piles
  /// Components whose highest cell stands lower than this above the ground are not piles:
  /// where no image has seen the ground, Eq. (11) falls back on the height alone, and far
  /// cells (σp² = α_d d² is large there) a few centimetres up come out as pile by a hair [m].
  double min_peak_height = 0.15;
};

/// Adds the layer "pile_elevation" (the height of pile cells, NaN elsewhere) and returns the
/// piles, largest first. Needs SemanticMap::Fuse() to have run.
std::vector<ExtractedPile> ExtractPiles(GridMap& map, const Eigen::Vector3d& ground_plane,
                                        const PileExtractionConfig& config = {});

}  // namespace autoshovel::perception
