// Randomised shovelling scenes for expert demonstrations (wheel-loader seed §5: the Eq. (18)
// weights were tuned by CMA-ES on 482 expert scenarios). A scene is one pile in a bare yard,
// sometimes with obstacles beside or behind it, and a loader start pose facing it roughly:
//
// - pile: cone, irregular heap, low flat-topped remainder, ridge, or heaped against its own
//   retaining wall; gravel or sand; size, orientation and seeds random;
// - obstacles (each independently): a bin wall along one flank, a parked loader near the
//   other flank, a fence segment behind the pile;
// - start: 9–15 m from the pile's centre on its open side, heading at the pile ± 25°.
//
// Everything comes from one 64-bit seed through std::mt19937_64 (bit-exact by the standard)
// and doubles from its top 53 bits, so a seed gives the same scene with every standard library.
#pragma once

#include <cstdint>
#include <string>

#include "runtime/model/description.h"
#include "runtime/planning/dubins_path.h"
#include "runtime/plant/scenario.h"

namespace autoshovel::identification {

struct DemoScene {
  plant::Scenario scenario;  ///< world (terrain, obstacles) and the one pile
  planning::Pose2 start;     ///< the loader's hinge pose, front frame heading [m, rad]
  std::string kind;          ///< e.g. "cone+wall+loader": the pile shape and obstacles present
};

/// The scene of `seed` for `machine` (its materials and bucket width size the scene). Throws
/// std::invalid_argument if the machine has no gravel or sand material.
DemoScene RandomDemoScene(const model::MachineDescription& machine, std::uint64_t seed);

}  // namespace autoshovel::identification
