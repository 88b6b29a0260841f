#include "identification/weights/demo_scenes.h"

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

#include "identification/weights/expert_model.h"
#include "runtime/plant/scenario_builder.h"

namespace autoshovel::identification {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kYardSize = 36.0;               // square yard, centred on the origin [m]
constexpr double kTerrainResolution = 0.1;       // as the scenario files' default [m]
constexpr double kIrregularSlopeFraction = 0.8;  // flanks a little below the angle of repose
constexpr double kIrregularRoughness = 0.15;     // bump amplitude / height

// Doubles from the generator's top 53 bits: bit-exact, unlike std::uniform_real_distribution.
class Draw {
 public:
  explicit Draw(std::uint64_t seed) : rng_(seed) {}
  double Uniform(double lo, double hi) {
    return lo + (hi - lo) * static_cast<double>(rng_() >> 11) * 0x1.0p-53;
  }
  bool Chance(double p) { return Uniform(0, 1) < p; }
  std::uint64_t Bits() { return rng_(); }

 private:
  std::mt19937_64 rng_;
};

int MaterialIndex(const model::MachineDescription& machine, bool sand) {
  for (std::size_t i = 0; i < machine.materials.size(); ++i) {
    const std::string& name = machine.materials[i].name;
    if (sand == (name.find("sand") != std::string::npos) &&
        (sand || name.find("gravel") != std::string::npos)) {
      return static_cast<int>(i);
    }
  }
  throw std::invalid_argument("machine '" + machine.name + "' has no " +
                              (sand ? "sand" : "gravel") + " material");
}

plant::OrientedBox Box(const std::string& name, const Eigen::Vector2d& xy, double yaw,
                       double length, double width, double height, core::SemanticClass cls) {
  plant::OrientedBox b;
  b.name = name;
  b.center = {xy.x(), xy.y(), 0.5 * height};
  b.half_extents = {0.5 * length, 0.5 * width, 0.5 * height};
  b.yaw = yaw;
  b.semantic_class = cls;
  b.reflectivity = cls == core::SemanticClass::kWall ? 0.45 : 0.3;
  return b;
}

}  // namespace

DemoScene RandomDemoScene(const model::MachineDescription& machine, std::uint64_t seed) {
  Draw draw(seed);
  DemoScene scene;
  plant::Scenario& s = scene.scenario;
  s.name = "demo_" + std::to_string(seed);
  s.machine = machine.name;
  s.seed = static_cast<std::uint32_t>(seed);
  s.world.materials = machine.materials;
  plant::GridGeometry geometry;
  geometry.resolution = kTerrainResolution;
  geometry.nx = geometry.ny = static_cast<int>(std::lround(kYardSize / kTerrainResolution));
  geometry.origin = Eigen::Vector2d::Constant(-0.5 * kYardSize);
  s.world.terrain = plant::Terrain(geometry, 0.0);

  // The pile at the origin; its local +x axis points away from the loader's side (the open side
  // is −x, where the start pose is drawn).
  plant::Pile pile;
  pile.name = "pile";
  const bool sand = draw.Chance(0.5);
  pile.material_index = MaterialIndex(machine, sand);
  pile.material = machine.materials[pile.material_index].name;
  const double tan_repose = std::tan(machine.materials[pile.material_index].angle_of_repose);
  const double facing = draw.Uniform(-kPi, kPi);  // the open side's direction, world
  pile.yaw = facing + kPi;
  const int shape = static_cast<int>(draw.Uniform(0, 5));
  double half_length = 0, reach_back = 0;  // the pile's extent across and behind its centre
  switch (shape) {
    case 0:
    case 1:
      pile.shape = shape == 0 ? plant::PileShape::kCone : plant::PileShape::kIrregular;
      pile.height = draw.Uniform(1.5, 3.5);
      pile.slope = shape == 0 ? tan_repose : kIrregularSlopeFraction * tan_repose;
      pile.base_radius = pile.height / pile.slope;
      if (shape == 1) {
        pile.roughness = kIrregularRoughness * pile.height;
        pile.seed = draw.Bits();
      }
      half_length = reach_back = pile.base_radius;
      scene.kind = shape == 0 ? "cone" : "irregular";
      break;
    case 2:
      pile.shape = plant::PileShape::kLow;
      pile.height = draw.Uniform(0.5, 1.0);
      pile.slope = tan_repose;
      pile.length = draw.Uniform(4.0, 8.0);
      pile.width = draw.Uniform(5.0, 9.0);
      half_length = 0.5 * pile.width, reach_back = 0.5 * pile.length;
      scene.kind = "low";
      break;
    case 3:
      pile.shape = plant::PileShape::kRidge;
      pile.height = draw.Uniform(1.2, 2.5);
      pile.slope = tan_repose;
      pile.width = 2 * pile.height / tan_repose;
      pile.length = pile.width + draw.Uniform(3.0, 8.0);
      // A windrow lies across the approach: its long axis at right angles to the open side.
      pile.yaw = facing + 0.5 * kPi;
      half_length = 0.5 * pile.length, reach_back = 0.5 * pile.width;
      scene.kind = "ridge";
      break;
    default: {
      pile.shape = plant::PileShape::kAgainstWall;
      pile.height = draw.Uniform(1.5, 2.8);
      pile.slope = tan_repose;
      pile.base_radius = pile.height / tan_repose;
      pile.length = draw.Uniform(2.0, 6.0);
      // The wall's face is the pile's local y axis and the pile lies on its +x side, so the
      // pile faces the open side when its +x points there; the centre sits on the wall.
      pile.yaw = facing;
      const double length = pile.length + 2 * pile.base_radius + 1.0;
      const Eigen::Vector2d u(std::cos(facing), std::sin(facing));
      // The crest's middle sits half the reach behind the origin, so that the pile's mass is
      // near it; the wall stands behind the crest.
      s.world.obstacles.push_back(Box("pile/wall", -(0.5 * pile.base_radius + 0.25) * u, facing,
                                      0.5, length, 3.0, core::SemanticClass::kWall));
      half_length = 0.5 * length, reach_back = 0.5;
      scene.kind = "against_wall";
      break;
    }
  }
  // Centre the pile's mass near the origin: an against-wall pile extends towards the open side.
  const Eigen::Vector2d open(std::cos(facing), std::sin(facing)), side(-open.y(), open.x());
  pile.center = pile.shape == plant::PileShape::kAgainstWall
                    ? Eigen::Vector2d(-0.5 * pile.base_radius * open)
                    : Eigen::Vector2d::Zero();

  // Obstacles beside and behind the pile, each with its own chance.
  const double flank = half_length + draw.Uniform(1.0, 3.0);
  if (draw.Chance(0.4)) {  // a bin wall along one flank, from behind the pile towards the open side
    const double sign = draw.Chance(0.5) ? 1.0 : -1.0;
    const double length = draw.Uniform(6.0, 12.0);
    const Eigen::Vector2d c = sign * flank * side + (0.5 * length - reach_back - 1.0) * open;
    s.world.obstacles.push_back(
        Box("flank_wall", c, facing, length, 0.4, 3.0, core::SemanticClass::kWall));
    scene.kind += "+wall";
  }
  if (draw.Chance(0.35)) {  // a parked loader on one flank, facing the open side
    const double sign = draw.Chance(0.5) ? 1.0 : -1.0;
    const double offset = flank + 1.5 + draw.Uniform(0.0, 2.0);
    const Eigen::Vector2d c = sign * offset * side + draw.Uniform(0.0, 4.0) * open;
    s.world.obstacles.push_back(
        Box("parked_loader", c, facing, 8.5, 3.0, 3.4, core::SemanticClass::kOtherLoader));
    scene.kind += "+loader";
  }
  if (draw.Chance(0.3)) {  // a fence behind the pile
    const Eigen::Vector2d c = -(reach_back + draw.Uniform(0.8, 2.5)) * open;
    s.world.obstacles.push_back(Box("fence", c, facing + 0.5 * kPi, 2 * half_length + 4.0, 0.1, 1.8,
                                    core::SemanticClass::kWall));
    scene.kind += "+fence";
  }
  std::vector<plant::Pile> piles = {pile};
  plant::BuildTerrain(s.world, piles, {});
  s.piles = piles;

  // The loader on the open side, facing the pile within ±25°, with its body (a 5 m circle about
  // the hinge) clear of every obstacle: drawn again until it is (a few tries at most).
  const auto clear_of_obstacles = [&](const Eigen::Vector2d& xy) {
    for (const plant::OrientedBox& box : s.world.obstacles) {
      if (FootprintDistance(box, xy) < 5.0) return false;
    }
    return true;
  };
  for (int attempt = 0;; ++attempt) {
    const double bearing = facing + draw.Uniform(-1.0, 1.0);
    const double distance = std::max(reach_back, half_length) + draw.Uniform(7.0, 11.0);
    scene.start.xy = distance * Eigen::Vector2d(std::cos(bearing), std::sin(bearing));
    scene.start.heading = bearing + kPi + draw.Uniform(-0.44, 0.44);
    if (clear_of_obstacles(scene.start.xy) || attempt == 50) break;
  }
  s.start = {scene.start.xy.x(), scene.start.xy.y(), scene.start.heading};
  return scene;
}

}  // namespace autoshovel::identification
