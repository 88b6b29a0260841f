#include "truck_scan_test_support.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace autoshovel::app::testing {

plant::World MakeBenchYard(const BenchYard& yard, const model::MachineDescription& machine) {
  plant::World world;
  plant::GridGeometry geometry;
  geometry.resolution = yard.resolution;
  geometry.origin = Eigen::Vector2d(-16.0, -10.0);
  geometry.nx = static_cast<int>(std::lround(32.0 / yard.resolution));
  geometry.ny = static_cast<int>(std::lround(32.0 / yard.resolution));
  world.terrain = plant::Terrain(geometry, 0.0);
  world.materials = machine.materials;
  const double run = (0.0 - yard.road_z) / std::tan(yard.face_angle_deg * std::numbers::pi / 180);
  plant::Terrain& terrain = world.terrain;
  for (int iy = 0; iy < terrain.ny(); ++iy) {
    for (int ix = 0; ix < terrain.nx(); ++ix) {
      const Eigen::Vector2d c = terrain.CellCenter(ix, iy);
      const double s = std::clamp((c.y() - yard.crest_y) / run, 0.0, 1.0);
      terrain.SetFloor(ix, iy, s * yard.road_z);
      terrain.SetHeight(ix, iy, s * yard.road_z);
      // The dig face: material rising at 30° from x = 6 m to 3 m high, on the bench only.
      if (yard.dig_face && c.x() > 6.0 && c.y() < yard.crest_y - 0.5 && !world.materials.empty()) {
        const double h = std::min(3.0, (c.x() - 6.0) * std::tan(std::numbers::pi / 6));
        terrain.SetHeight(ix, iy, h);
        terrain.SetMaterial(ix, iy, 0);
      }
    }
  }
  return world;
}

const model::MachineDescription& Excavator25t() {
  static const model::MachineDescription machine =
      model::LoadMachineDescription(model::ResolveMachineDescription(
          "excavator_25t", std::string(AUTOSHOVEL_SOURCE_DIR) + "/models"));
  return machine;
}

}  // namespace autoshovel::app::testing
