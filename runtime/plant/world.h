// The simulated yard the plant moves in and the sensors observe: the terrain, the materials its
// cells refer to, and box-shaped obstacles (bin walls, fences, parked loaders, debris, people).
// Built from a scenario file (scenario.h); the plant changes the terrain as it digs; obstacles
// may be moved between frames (a person walking).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/core/semantic_class.h"
#include "runtime/model/description.h"
#include "runtime/plant/terrain.h"

namespace autoshovel::plant {

/// Lighting of the yard, for the simulated camera (wheel-loader seed §7.2: normal, bright, dim).
enum class Lighting { kNormal, kBright, kDim };

/// "normal", "bright", "dim".
const char* ToString(Lighting lighting);
/// Inverse of ToString; nullopt for anything else.
std::optional<Lighting> ParseLighting(std::string_view name);

/// A box standing on or above the ground, turned about the vertical axis.
struct OrientedBox {
  std::string name;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();        ///< world frame [m]
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();  ///< along the box's own axes [m]
  double yaw = 0;                                          ///< about world z [rad]
  core::SemanticClass semantic_class = core::SemanticClass::kOther;
  double reflectivity = 0.3;  ///< LiDAR reflectivity [0, 1]
};

struct World {
  Terrain terrain;
  std::vector<model::Material> materials;  ///< indexed by Terrain::material()
  std::vector<OrientedBox> obstacles;
  double ground_reflectivity = 0.2;  ///< of the bare floor
};

/// A bare level floor of `size` × `size` metres centred on the world origin, at 0.1 m
/// resolution, with the machine's materials: for experiments that need no material (valve
/// steps, identification logs).
World EmptyYard(const model::MachineDescription& machine, double size = 20.0);

}  // namespace autoshovel::plant
