// A yard with one cone pile for the closed-loop control tests, the plant behind the control
// layer's ScoopMachine interface being app::PlantMachine.
#pragma once

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "runtime/app/plant_machine.h"
#include "runtime/control/scoop_cycle.h"
#include "runtime/plant/plant.h"
#include "runtime/plant/scenario_builder.h"
#include "runtime/prediction/volume_estimation.h"
#include "tests/plant/plant_test_support.h"

namespace autoshovel::control::testing {

using PlantMachine = app::PlantMachine;

/// The whole terrain as the elevation map a perception stack would give (ε = terrain resolution).
inline prediction::HeightGrid ToHeightGrid(const plant::Terrain& terrain) {
  prediction::HeightGrid grid;
  grid.resolution = terrain.resolution();
  grid.origin = terrain.geometry().origin;
  grid.nx = terrain.nx();
  grid.ny = terrain.ny();
  grid.height.reserve(static_cast<std::size_t>(grid.nx) * grid.ny);
  for (int iy = 0; iy < grid.ny; ++iy) {
    for (int ix = 0; ix < grid.nx; ++ix) grid.height.push_back(terrain.height(ix, iy));
  }
  return grid;
}

/// A yard with one cone of `material` at its angle of repose, `height` high, its toe `gap` ahead
/// of the bucket tip of a loader at the origin facing +x with the bucket on the floor.
struct ConeYard {
  model::MachineDescription machine;
  plant::World world;
  plant::MachineState start;
  const model::Material* material = nullptr;
  ArmTargets attack_pose;

  ConeYard(const ConeYard&) = delete;
  ConeYard& operator=(const ConeYard&) = delete;
  ConeYard(const std::string& machine_name, const std::string& material_name, double height,
           double gap)
      : machine(plant::testing::LoadMachine(machine_name)) {
    const std::vector<double> q0 = plant::BucketOnFloor(machine);
    attack_pose = {.boom = q0[0], .bucket = q0[1]};
    start = plant::testing::LoaderAt(machine, 0.0);
    material = machine.FindMaterial(material_name);
    if (material == nullptr) throw std::runtime_error("no material " + material_name);
    const double tip_x = prediction::TipInBase(machine, q0[0], q0[1]).x();
    plant::Pile pile;
    pile.name = "cone";
    pile.shape = plant::PileShape::kCone;
    pile.material = material_name;
    world.materials = machine.materials;
    pile.material_index = plant::testing::MaterialIndex(world, material_name);
    pile.height = height;
    pile.slope = std::tan(material->angle_of_repose);
    pile.base_radius = height / pile.slope;
    pile.center = Eigen::Vector2d(tip_x + gap + pile.base_radius, 0.0);
    plant::GridGeometry geometry;
    geometry.resolution = 0.05;
    geometry.origin = Eigen::Vector2d(-8.0, -pile.base_radius - 2.0);
    geometry.nx = static_cast<int>(
        std::ceil((pile.center.x() + pile.base_radius + 1.0 + 8.0) / geometry.resolution));
    geometry.ny = static_cast<int>(std::ceil((2 * pile.base_radius + 4.0) / geometry.resolution));
    world.terrain = plant::Terrain(geometry, 0.0);
    std::vector<plant::Pile> piles = {pile};
    plant::BuildTerrain(world, piles, {});
  }
};

}  // namespace autoshovel::control::testing
