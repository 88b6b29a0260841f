#include "runtime/plant/world.h"

#include <cmath>

namespace autoshovel::plant {

const char* ToString(Lighting lighting) {
  switch (lighting) {
    case Lighting::kBright:
      return "bright";
    case Lighting::kDim:
      return "dim";
    case Lighting::kNormal:
      break;
  }
  return "normal";
}

std::optional<Lighting> ParseLighting(std::string_view name) {
  for (Lighting l : {Lighting::kNormal, Lighting::kBright, Lighting::kDim}) {
    if (name == ToString(l)) return l;
  }
  return std::nullopt;
}

World EmptyYard(const model::MachineDescription& machine, double size) {
  World world;
  GridGeometry geometry;
  geometry.resolution = 0.1;
  geometry.nx = geometry.ny = static_cast<int>(std::ceil(size / geometry.resolution));
  geometry.origin = Eigen::Vector2d(-size / 2, -size / 2);
  world.terrain = Terrain(geometry, 0.0);
  world.materials = machine.materials;
  return world;
}

}  // namespace autoshovel::plant
