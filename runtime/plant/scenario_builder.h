// Turning validated scenario piles into terrain (used by scenario.cc; see scenario.h for the
// rules). Kept apart from the YAML reading so that the geometry can be read on its own.
#pragma once

#include <cstdint>
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

/// A restocked yard, as a campaign's shifts meet it: every pile's height scaled by a factor
/// drawn in [1 − fraction, 1] (deliveries top a pile up to at most its nominal height), an
/// irregular pile's lobes and bumps re-seeded, and the terrain rebuilt. Drawn from `seed`,
/// bit-exact; fraction 0 leaves the scenario as it is. Throws std::invalid_argument for a
/// fraction outside [0, 0.9].
void VaryPiles(Scenario& scenario, std::uint64_t seed, double fraction);

}  // namespace autoshovel::plant
