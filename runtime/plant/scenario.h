// Yard scenarios: a `models/scenarios/<name>.yaml` file read strictly and turned into the simulated
// World (terrain with piles, bin walls, obstacles), the machine that works in it, its start pose,
// the lighting and the seed. The schema is documented field by field in models/scenarios/README.md.
//
// Terrain construction (scenario_builder.cc): every pile is a height field over the floor; piles
// combine by max, a cell takes the material of the pile on top, floor cells have no material.
// Piles are clipped at bin walls and at their own retaining wall; the footprint of every wall
// (semantic class kWall) is bare floor. A final pass lowers any cell that stands steeper than its
// material's angle of repose above one of its 8 neighbours, except across a wall, which holds
// material up: afterwards no slope between neighbouring cells exceeds the angle of repose.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "runtime/plant/fault_spec.h"
#include "runtime/plant/world.h"

namespace autoshovel::plant {

enum class PileShape {
  kCone,         ///< a regular cone
  kIrregular,    ///< a cone with seeded lobes, bumps and dents
  kLow,          ///< a thin, flat-topped pile (at most 1 m high)
  kRidge,        ///< an elongated windrow: a horizontal crest with half-cone ends
  kAgainstWall,  ///< heaped against its own retaining wall, on one side of it only
};

/// Where the loader starts, in the world frame.
struct StartPose {
  double x = 0;        ///< [m]
  double y = 0;        ///< [m]
  double heading = 0;  ///< base x axis from world x, counter-clockwise [rad]
};

/// One bin of a row of bins: open at the front, walls on both sides and at the back.
struct Bin {
  std::string name;
  Eigen::Vector2d front_center = Eigen::Vector2d::Zero();  ///< middle of the open front, world [m]
  /// Direction of the row (bin frame u axis) from world x [rad]; the bin extends along
  /// v = u turned by +90°, so a machine enters it heading `yaw + π/2`.
  double yaw = 0;
  double width = 0;  ///< interior, wall face to wall face [m]
  double depth = 0;  ///< open front to the back wall's face [m]
};

/// A pile as the scenario specifies it, plus what building the terrain left of it.
struct Pile {
  std::string name;
  PileShape shape = PileShape::kCone;
  std::string material;     ///< material name
  int material_index = -1;  ///< into World::materials (= Terrain material index)
  int bin = -1;             ///< index into Scenario::bins; -1 in the open yard
  Eigen::Vector2d center = Eigen::Vector2d::Zero();  ///< world xy of the apex / crest middle [m]
  double yaw = 0;                                    ///< of the pile's local x axis [rad]
  double height = 0;                                 ///< specified peak height above the floor [m]
  double base_radius = 0;  ///< cone, irregular: base radius; against_wall: reach from the wall [m]
  double length = 0;       ///< ridge, low: along local x; against_wall: crest along the wall [m]
  double width = 0;        ///< ridge, low: base width across local x [m]
  double slope = 0;        ///< tangent of the flanks (before irregularities) [-]
  double roughness = 0;    ///< irregular: bump amplitude [m]
  std::uint64_t seed = 0;  ///< irregular: the seed of its lobes and bumps
  // Filled in by building the terrain: the cells where this pile is on top.
  double volume = 0;       ///< material volume [m³]
  double peak_height = 0;  ///< largest depth above the floor [m]
  int cells = 0;           ///< number of cells
};

struct Scenario {
  std::string name;
  std::string source_file;
  std::string sha256;  ///< of the file's bytes
  std::string description;
  std::string materials_dir;
  World world;
  std::string machine;  ///< machine description name (models/loaders, models/excavators)
  StartPose start;
  Lighting lighting = Lighting::kNormal;
  std::uint32_t seed = 0;
  std::vector<Bin> bins;
  std::vector<Pile> piles;
  std::vector<FaultSpec> faults;  ///< injected by the simulator (fault_spec.h); usually none

  /// The pile of that name, or nullptr.
  const Pile* FindPile(const std::string& pile_name) const;
};

/// Reads, validates and builds a scenario. Every problem is reported as
/// `file:line:column: key.path: message`; all of them are collected and thrown once as
/// core::InputError, and nothing partly built is returned.
Scenario LoadScenario(const std::string& path);

/// Scenario files under `<models_dir>/scenarios`, sorted.
std::vector<std::string> FindScenarios(const std::string& models_dir);

/// A scenario given by name (`<models_dir>/scenarios/<name>.yaml`) or by path. Throws
/// std::runtime_error listing the known scenarios when nothing matches.
std::string ResolveScenario(const std::string& name_or_path, const std::string& models_dir);

const char* ToString(PileShape shape);

/// Whether the footprint (xy rectangle) of `box` contains world point `xy`.
bool FootprintContains(const OrientedBox& box, const Eigen::Vector2d& xy);

}  // namespace autoshovel::plant
