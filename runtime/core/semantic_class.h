// The semantic classes a camera pixel or a map cell can carry (wheel-loader seed §4.2, Fig. 5).
// The simulated camera renders them as ground truth; segmentation predicts them; perception fuses
// them. Kept in core so that the world model (plant), the sensors and perception share one list
// without perception depending on the simulator.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

namespace autoshovel::core {

enum class SemanticClass : std::uint8_t {
  kGround = 0,       ///< the yard floor
  kPile = 1,         ///< material that can be shovelled
  kOwnLoader = 2,    ///< the machine the sensors are mounted on (its bucket, boom, hood)
  kOtherLoader = 3,  ///< another machine: an obstacle
  kPerson = 4,       ///< an obstacle that must never be approached
  kWall = 5,         ///< bin walls, fences
  kOther = 6,        ///< debris, sky, anything else
};

inline constexpr int kNumSemanticClasses = 7;

inline constexpr std::array<std::string_view, kNumSemanticClasses> kSemanticClassNames = {
    "ground", "pile", "own_loader", "other_loader", "person", "wall", "other"};

inline constexpr std::string_view ToString(SemanticClass c) {
  return kSemanticClassNames[static_cast<int>(c)];
}

}  // namespace autoshovel::core
