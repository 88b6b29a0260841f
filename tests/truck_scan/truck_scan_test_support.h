// Test support for scanning the truck (excavator seed §2–4): the yard of `autoshovel run
// truck_loading`: the excavator on a bench at z = 0 (world origin, heading +x), a dig face ahead
// (+x), the haul road 2 m below the bench on the operator's left (+y), where the truck parks.
#pragma once

#include <string>

#include "runtime/model/description.h"
#include "runtime/plant/world.h"

namespace autoshovel::app::testing {

struct BenchYard {
  double crest_y = 3.0;        ///< bench edge [m]
  double face_angle_deg = 70;  ///< bench face slope
  double road_z = -2.0;        ///< haul road surface [m]
  double resolution = 0.1;     ///< terrain cells [m]
  bool dig_face = true;        ///< a material slope ahead of the machine
};

/// The bench, its face, the road and (optionally) a dig face of the first material: x from −16
/// to 16 m, y from −10 to 22 m.
plant::World MakeBenchYard(const BenchYard& yard, const model::MachineDescription& machine);

/// The shipped 25 t excavator's description, loaded once.
const model::MachineDescription& Excavator25t();

}  // namespace autoshovel::app::testing
