// Turning validated scenario piles into terrain (used by scenario.cc; see scenario.h for the
// rules). Kept apart from the YAML reading so that the geometry can be read on its own.
#pragma once

#include <vector>

#include "runtime/plant/scenario.h"

namespace autoshovel::plant {

struct TerrainBuildReport {
  std::vector<int> outside_yard;  ///< piles with material beyond the edge of the grid
  std::vector<int> hidden;        ///< piles left with no cell on top (under others or walls)
};

/// Rasterises `piles` into `world.terrain` (sized and flat), clipping each at its bin's walls
/// (`bins`) or its own wall (against_wall), clears the footprints of the kWall obstacles of
/// `world`, lowers every cell steeper than its material's angle of repose, and fills in each
/// pile's volume, peak height and cell count. Deterministic: no threads, seeded generators
/// specified bit for bit.
TerrainBuildReport BuildTerrain(World& world, std::vector<Pile>& piles,
                                const std::vector<Bin>& bins);

}  // namespace autoshovel::plant
