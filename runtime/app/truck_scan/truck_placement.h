// A haul truck parked in the simulated yard (excavator seed §2, §4.1, §4.3): the truck the
// excavator recognises, dumps into and measures. The truck is built from oriented boxes (side
// walls, headboard, tailgate, floor slab, cab, chassis rails, wheels; semantic class
// kOtherLoader: another machine) plus the terrain under its bed:
//
// - Bed floor. The terrain's hard floor under the bed opening (every cell whose centre lies
//   inside the inside rectangle) is raised to the bed floor's height, with no material on it.
//   Soil dumped into the bed is then ordinary terrain material on that floor: the plant's
//   deposit and repose rules move it, the ray casters see it, and Terrain::MaterialVolume
//   counts it, so dumping conserves volume exactly as dumping on the ground does. A floor slab
//   box (top at the floor height) covers the terrain's bilinear fall-off from the raised cell
//   centres to the unraised ones beyond the walls, which would otherwise show as a groove along
//   the inside of the walls.
// - Wall cells (optional, on by default). The ring of cells around the floor cells (their
//   eight-neighbourhood) gets its hard floor at the rim height. The plant's repose rule only
//   compares surface heights of neighbouring cells; without the ring, soil reaching the bed's
//   edge would flow "through" the wall boxes down to the road. With it, soil leaves the bed only
//   over the rim, as it does on a real truck. A body without tailgate (articulated hauler) has
//   no ring at its open rear. The price: between a ring cell centre (rim height) and its
//   unraised outer neighbour the bilinear terrain falls to the road within one cell, so from
//   outside the lower part of the body looks solid down to the road for up to 2 cells beyond
//   the inner wall face, and inside the bed a fillet up to one cell wide rises from the floor to
//   the rim along the walls (docs/truck_scan.md measures what recognition makes of it).
//
// Frames. T_world_bed is truck recognition's bed frame (runtime/perception/truck/
// truck_recognition.h): origin at the centre of the bed opening on the rim plane, x along the
// bed towards the cab, y to its left, z up. T_world_bed_corner() is the dump planner's
// (runtime/planning/dump/bed_height_map.h): origin at the rear-right inside corner of the
// opening, same axes, so the opening is [0, length] × [0, width].
//
// Dimensions. Three classes with the figures of truck recognition's test trucks
// (tests/truck_recognition/truck_scan_simulation.cc), inside the recogniser's model ranges
// (truck_model.h): rounded figures of body data sheets, not one manufacturer's model.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/plant/terrain.h"
#include "runtime/plant/world.h"

namespace autoshovel::app {

/// Body and chassis of a haul truck [m]. Heights are above the ground the truck stands on.
struct TruckBody {
  std::string name;
  double inner_length = 5.8;     ///< headboard to tailgate, inside [m]
  double inner_width = 2.35;     ///< side wall to side wall, inside [m]
  double wall_height = 1.15;     ///< floor top to rim [m]
  double floor_height = 1.55;    ///< floor top above the ground [m]
  double wall_thickness = 0.07;  ///< side, end walls [m]
  double headboard_rise = 0.3;   ///< headboard top above the rim (cab guard) [m]
  bool has_tailgate = true;
  double cab_gap = 0.35;  ///< headboard to cab [m]
  double cab_length = 2.2;
  double cab_width = 2.3;
  double cab_height = 3.1;  ///< roof above the ground [m]
  double wheel_radius = 0.52;
  double reflectivity = 0.35;  ///< painted steel, Lambertian [0, 1]

  double rim_height() const { return floor_height + wall_height; }
  /// Inside volume of the bed up to the rim [m³] (struck capacity).
  double struck_volume() const { return inner_length * inner_width * wall_height; }
};

/// One solid part of a body, by its corners in the bed frame (origin at the centre of the
/// opening on the rim plane, x along the bed towards the cab, y to its left, z up).
struct TruckBodyBox {
  std::string part;  ///< "floor", "left_side", …, "cab", "chassis", "wheel_0" …
  Eigen::Vector3d lo_bed = Eigen::Vector3d::Zero();
  Eigen::Vector3d hi_bed = Eigen::Vector3d::Zero();
};

/// The body's parts: floor slab, side walls, headboard (cab guard), tailgate, cab, chassis
/// rails, six wheels. The one geometry of a truck that PlaceTruck and the recognition tests'
/// scenes build from.
std::vector<TruckBodyBox> TruckBodyBoxes(const TruckBody& body);

enum class TruckClass { kTipper15t, kTipper20t, kHauler38t };

/// "15 t tipper", "20 t tipper", "38 t articulated hauler".
std::string_view ToString(TruckClass truck_class);

/// A 3-axle road tipper of about 15 t payload: inside 4.8 × 2.30 m, 0.90 m sides, floor 1.45 m.
/// A 4-axle tipper of about 20 t: 5.8 × 2.35 m, 1.15 m sides, floor 1.55 m.
/// A 38 t articulated hauler without tailgate: 6.2 × 3.3 m, 1.55 m sides, floor 1.95 m.
TruckBody TruckBodyOf(TruckClass truck_class);

/// Where the truck stands.
struct TruckPose {
  Eigen::Vector2d p_world_bed = Eigen::Vector2d::Zero();  ///< centre of the bed opening, xy [m]
  double yaw = 0;       ///< heading of the bed's x axis (towards the cab) from world x [rad]
  double ground_z = 0;  ///< the ground under the wheels (the haul road) [m]
};

struct TruckPlacementOptions {
  std::string name = "truck";  ///< prefix of the obstacle boxes' names
  /// Raise the ring of cells around the bed floor to the rim (see the file comment).
  bool wall_cells_at_rim = true;
};

/// What was placed: the truth that recognition and the dump planner are measured against.
struct TruckPlacement {
  TruckBody body;
  TruckPose pose;
  /// Bed frame, as TruckRecognitionResult::T_world_bed.
  Eigen::Isometry3d T_world_bed = Eigen::Isometry3d::Identity();
  /// Inside corners of the opening at rim height: front-left, front-right, rear-right,
  /// rear-left (the order of TruckRecognitionResult::p_world_corners).
  std::array<Eigen::Vector3d, 4> p_world_corners{};
  double inner_length = 0;  ///< [m]
  double inner_width = 0;   ///< [m]
  double wall_height = 0;   ///< [m]
  double floor_z = 0;       ///< world height of the bed floor (the raised terrain floor) [m]
  double rim_z = 0;         ///< world height of the rim [m]
  /// The truck's boxes as added to World::obstacles (also the keep-out volumes of the arm).
  std::vector<plant::OrientedBox> boxes;
  /// Indices (Terrain::Index) of the cells whose floor is the bed floor, and of the wall ring.
  std::vector<int> floor_cells;
  std::vector<int> wall_cells;

  /// The dump planner's bed frame: origin at the rear-right inside corner of the opening.
  Eigen::Isometry3d T_world_bed_corner() const;
  /// Whether world plan position (x, y) lies inside the bed opening.
  bool InsideBed(double x, double y) const;
  /// Material on the bed floor [m³] (terrain material in floor_cells).
  double MaterialInBed(const plant::Terrain& terrain) const;
};

/// Puts a truck into `world`: boxes appended to world->obstacles, the terrain floor raised under
/// the bed (and the wall ring, see TruckPlacementOptions). The world's ray-cast scenes must be
/// updated afterwards (RaycastScene::Update()).
///
/// Throws std::invalid_argument for a non-finite pose, a body with non-positive or non-finite
/// sizes, a bed (with its wall ring) reaching beyond the terrain grid, a cell under it that
/// holds material (a truck does not park on a heap) or whose hard floor already lies above the
/// bed floor (the truck would stand inside the terrain, e.g. placed into the bench).
TruckPlacement PlaceTruck(const TruckBody& body, const TruckPose& pose, plant::World* world,
                          const TruckPlacementOptions& options = {});

}  // namespace autoshovel::app
