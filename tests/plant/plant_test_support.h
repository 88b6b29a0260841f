// Shared fixtures of the plant tests: a machine with its generated code and a small yard.
#pragma once

#include <cmath>
#include <memory>
#include <numbers>
#include <string>

#include "generated/registry.h"
#include "runtime/model/description.h"
#include "runtime/plant/machine_state.h"
#include "runtime/plant/poses.h"
#include "runtime/plant/world.h"

namespace autoshovel::plant::testing {

inline std::string ModelsDir() { return std::string(AUTOSHOVEL_SOURCE_DIR) + "/models"; }

inline model::MachineDescription LoadMachine(const std::string& name) {
  return model::LoadMachineDescription(model::ResolveMachineDescription(name, ModelsDir()));
}

inline const generated::MachineFunctions& Functions(const std::string& name) {
  const generated::MachineFunctions* f = generated::FindMachine(name);
  if (f == nullptr) throw std::runtime_error("no generated code for " + name);
  return *f;
}

/// A flat yard of `size` × `size` metres centred on the origin, with the description's materials.
inline World FlatYard(const model::MachineDescription& machine, double size = 30.0,
                      double resolution = 0.05) {
  GridGeometry geometry;
  geometry.resolution = resolution;
  geometry.nx = geometry.ny = static_cast<int>(std::round(size / resolution));
  geometry.origin = Eigen::Vector2d(-size / 2, -size / 2);
  World world;
  world.terrain = Terrain(geometry, 0.0);
  world.materials = machine.materials;
  return world;
}

inline int MaterialIndex(const World& world, const std::string& name) {
  for (std::size_t i = 0; i < world.materials.size(); ++i) {
    if (world.materials[i].name == name) return static_cast<int>(i);
  }
  throw std::runtime_error("no material " + name);
}

/// Adds a cone of `material` with its slope at the angle of repose, apex height `height`.
inline void AddCone(World& world, const Eigen::Vector2d& center, double height,
                    const std::string& material) {
  const int m = MaterialIndex(world, material);
  const double slope = std::tan(world.materials[m].angle_of_repose);
  Terrain& t = world.terrain;
  for (int iy = 0; iy < t.ny(); ++iy) {
    for (int ix = 0; ix < t.nx(); ++ix) {
      const double r = (t.CellCenter(ix, iy) - center).norm();
      const double h = height - slope * r;
      if (h > t.height(ix, iy)) {
        t.SetHeight(ix, iy, h);
        t.SetMaterial(ix, iy, static_cast<std::int16_t>(m));
      }
    }
  }
}

/// A loader at `x` facing +x with its bucket flat on the floor (`boom` and `bucket` NaN) or at
/// the given joint positions.
inline MachineState LoaderAt(const model::MachineDescription& machine, double x,
                             double boom = std::nan(""), double bucket = std::nan("")) {
  if (std::isnan(boom)) {
    const std::vector<double> q = BucketOnFloor(machine);
    boom = q[0], bucket = q[1];
  }
  MachineState state;
  state.hinge_xy = Eigen::Vector2d(x, 0.0);
  state.q.assign(machine.num_joints(), 0.0);
  state.q[0] = boom;
  if (machine.num_joints() > 1) state.q[1] = bucket;
  return state;
}

}  // namespace autoshovel::plant::testing
