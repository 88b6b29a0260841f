#include "identification/segmentation/yard_views.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <random>
#include <stdexcept>

#include "generated/registry.h"
#include "runtime/machines/machine_code.h"
#include "runtime/model/description.h"
#include "runtime/plant/plant.h"
#include "runtime/plant/scenario.h"
#include "runtime/sensors/camera.h"
#include "runtime/sensors/raycast.h"
#include "runtime/sensors/sensor_pose.h"

namespace autoshovel::identification {
namespace {

using core::SemanticClass;
constexpr double kPi = std::numbers::pi;

// Material deeper than this under a point means "on a pile", not on free floor [m] (the
// scenario's own rule for a start pose).
constexpr double kFreeFloorDepth = 0.05;

std::uint64_t SplitMix64(std::uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

struct Machine {
  model::MachineDescription description;
  const generated::MachineFunctions* functions = nullptr;
};

// Something a loader drives at: a pile, approached from anywhere around it in the open yard or
// through the open front of its bin.
struct Target {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  double radius = 0;  // of a disc with the pile's footprint area [m]
  bool in_bin = false;
  Eigen::Vector2d bin_front = Eigen::Vector2d::Zero();  // middle of the bin's open front
  Eigen::Vector2d outward = Eigen::Vector2d::Zero();    // out of the bin, unit
};

struct ScenarioEntry {
  std::string name;
  plant::Scenario scenario;
  int machine = -1;  // index into Data::machines
  std::vector<Target> targets;
};

class Draw {
 public:
  explicit Draw(std::uint64_t seed) : rng_(seed) {}
  double Uniform(double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng_);
  }
  double Normal(double sigma) { return std::normal_distribution<double>(0.0, sigma)(rng_); }
  bool Chance(double p) { return Uniform(0.0, 1.0) < p; }
  int Index(std::size_t n) {
    return std::uniform_int_distribution<int>(0, static_cast<int>(n) - 1)(rng_);
  }
  sensors::Rng& rng() { return rng_; }

 private:
  sensors::Rng rng_;
};

// Whether `xy` is inside the terrain grid by at least `margin` [m].
bool InsideYard(const plant::Terrain& t, const Eigen::Vector2d& xy, double margin) {
  const plant::GridGeometry& g = t.geometry();
  return xy.x() >= g.origin.x() + margin && xy.y() >= g.origin.y() + margin &&
         xy.x() <= g.origin.x() + g.nx * g.resolution - margin &&
         xy.y() <= g.origin.y() + g.ny * g.resolution - margin;
}

// Free floor: inside the yard, outside every obstacle's footprint, no pile under it.
bool FreeFloor(const plant::World& world, const Eigen::Vector2d& xy, double margin = 1.0) {
  if (!InsideYard(world.terrain, xy, margin)) return false;
  for (const plant::OrientedBox& box : world.obstacles) {
    if (plant::FootprintContains(box, xy)) return false;
  }
  int ix = 0, iy = 0;
  if (!world.terrain.CellOf(xy.x(), xy.y(), ix, iy)) return false;
  return world.terrain.depth(ix, iy) < kFreeFloorDepth;
}

// The centre and the corners of a rectangle of half sizes (a, b) turned by `yaw`.
std::array<Eigen::Vector2d, 5> FootprintPoints(const Eigen::Vector2d& c, double a, double b,
                                               double yaw) {
  const Eigen::Vector2d ex(std::cos(yaw), std::sin(yaw)), ey(-std::sin(yaw), std::cos(yaw));
  return {c, c + a * ex + b * ey, c + a * ex - b * ey, c - a * ex + b * ey, c - a * ex - b * ey};
}

bool FootprintFree(const plant::World& world, const Eigen::Vector2d& c, double a, double b,
                   double yaw) {
  for (const Eigen::Vector2d& p : FootprintPoints(c, a, b, yaw)) {
    if (!FreeFloor(world, p)) return false;
  }
  return true;
}

double FloorAt(const plant::Terrain& t, const Eigen::Vector2d& xy) {
  int ix = 0, iy = 0;
  return t.CellOf(xy.x(), xy.y(), ix, iy) ? t.floor(ix, iy) : 0.0;
}

// A pile of `material` raised on free floor: a cone (or a heap with a lobed rim) of height h and
// base radius R, or, one time in four, a low flat-topped remainder (0.25–0.8 m high, a plateau of
// 1–3 m radius): the worked-down heaps that look most like the floor (the low_pile yard). Cells
// keep the higher of the pile and what is there.
bool AddRandomPile(plant::World& world, Draw& draw, std::vector<Target>& targets) {
  if (world.materials.empty()) return false;
  const int material = draw.Index(world.materials.size());
  const bool low = draw.Chance(0.25);
  const double height = low ? draw.Uniform(0.25, 0.8) : draw.Uniform(0.8, 3.5);
  const double plateau = low ? draw.Uniform(1.0, 3.0) : 0.0;
  // Flanks at 70–100 % of the angle of repose: at it for a fresh heap, flatter when worked.
  const double slope =
      std::tan(world.materials[material].angle_of_repose) * draw.Uniform(0.7, 0.92);
  const double radius = plateau + height / slope;
  const bool lobed = draw.Chance(0.5);
  const double a2 = lobed ? draw.Uniform(0.0, 0.06) : 0.0;
  const double a3 = lobed ? draw.Uniform(0.0, 0.04) : 0.0;
  const double p2 = draw.Uniform(0, 2 * kPi), p3 = draw.Uniform(0, 2 * kPi);
  const plant::GridGeometry& g = world.terrain.geometry();
  const Eigen::Vector2d lo = g.origin, size(g.nx * g.resolution, g.ny * g.resolution);
  if (size.x() < 2 * radius + 4 || size.y() < 2 * radius + 4) return false;
  for (int attempt = 0; attempt < 30; ++attempt) {
    const Eigen::Vector2d c(draw.Uniform(lo.x() + radius + 2, lo.x() + size.x() - radius - 2),
                            draw.Uniform(lo.y() + radius + 2, lo.y() + size.y() - radius - 2));
    bool free = FreeFloor(world, c);
    for (int k = 0; k < 16 && free; ++k) {
      const double th = 2 * kPi * k / 16;
      free = FreeFloor(world, c + (radius + 0.5) * Eigen::Vector2d(std::cos(th), std::sin(th)));
    }
    if (!free) continue;
    plant::Terrain& t = world.terrain;
    const double reach = radius * (1 + a2 + a3);
    int ix0 = 0, iy0 = 0, ix1 = 0, iy1 = 0;
    t.CellOf(c.x() - reach, c.y() - reach, ix0, iy0);
    t.CellOf(c.x() + reach, c.y() + reach, ix1, iy1);
    for (int iy = std::max(0, iy0); iy <= std::min(t.ny() - 1, iy1); ++iy) {
      for (int ix = std::max(0, ix0); ix <= std::min(t.nx() - 1, ix1); ++ix) {
        const Eigen::Vector2d d = t.CellCenter(ix, iy) - c;
        const double th = std::atan2(d.y(), d.x());
        const double rim = radius * (1 + a2 * std::cos(2 * th + p2) + a3 * std::cos(3 * th + p3));
        const double z =
            std::min(height, height * (1 - d.norm() / rim) * radius / (radius - plateau));
        if (z > 0 && t.floor(ix, iy) + z > t.height(ix, iy)) {
          t.SetHeight(ix, iy, t.floor(ix, iy) + z);
          t.SetMaterial(ix, iy, static_cast<std::int16_t>(material));
        }
      }
    }
    Target target;
    target.center = c;
    target.radius = radius;
    targets.push_back(target);
    return true;
  }
  return false;
}

struct Pose2 {
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  double heading = 0;
};

// The machine's footprint (about 9 m × 3 m around the hinge) is on free floor.
bool MachineFits(const plant::World& world, const Pose2& pose) {
  return FootprintFree(world, pose.xy, 3.5, 1.5, pose.heading);
}

Pose2 DrawMachinePose(const ScenarioEntry& entry, const plant::World& world,
                      const std::vector<Target>& targets, Draw& draw) {
  const plant::Terrain& t = world.terrain;
  const plant::GridGeometry& g = t.geometry();
  const bool anywhere = targets.empty() || draw.Chance(0.2);
  for (int attempt = 0; attempt < 60; ++attempt) {
    Pose2 pose;
    if (anywhere) {
      pose.xy = Eigen::Vector2d(draw.Uniform(g.origin.x(), g.origin.x() + g.nx * g.resolution),
                                draw.Uniform(g.origin.y(), g.origin.y() + g.ny * g.resolution));
      pose.heading = draw.Uniform(-kPi, kPi);
    } else {
      const Target& target = targets[draw.Index(targets.size())];
      if (target.in_bin) {
        // In front of the bin's open front, within ±30° of its axis.
        const double d = draw.Uniform(2.0, 18.0), a = draw.Uniform(-0.5, 0.5);
        const Eigen::Vector2d along(-target.outward.y(), target.outward.x());
        pose.xy = target.bin_front + d * (std::cos(a) * target.outward + std::sin(a) * along);
      } else {
        const double bearing = draw.Uniform(-kPi, kPi);
        const double d = target.radius + draw.Uniform(2.0, 20.0);
        pose.xy = target.center + d * Eigen::Vector2d(std::cos(bearing), std::sin(bearing));
      }
      const Eigen::Vector2d to = target.center - pose.xy;
      pose.heading = std::atan2(to.y(), to.x()) + draw.Normal(0.2);
    }
    if (MachineFits(world, pose)) return pose;
  }
  const plant::StartPose& s = entry.scenario.start;
  return {Eigen::Vector2d(s.x, s.y), s.heading};
}

plant::OrientedBox Box(const std::string& name, const Eigen::Vector2d& xy, double floor,
                       double length, double width, double height, double yaw, SemanticClass c) {
  plant::OrientedBox b;
  b.name = name;
  b.center = Eigen::Vector3d(xy.x(), xy.y(), floor + 0.5 * height);
  b.half_extents = Eigen::Vector3d(0.5 * length, 0.5 * width, 0.5 * height);
  b.yaw = yaw;
  b.semantic_class = c;
  return b;
}

// Persons, a parked loader, debris and fences on free floor 7–28 m ahead of the cab, within the
// camera's horizontal field of view (±42°). Sizes vary around the scenario defaults.
int AddRandomObstacles(plant::World& world, const Pose2& cab, Draw& draw) {
  enum Kind { kPersonKind, kLoaderKind, kDebrisKind, kFenceKind };
  std::vector<Kind> kinds;
  const double persons = draw.Uniform(0, 1);
  const int n_persons = persons < 0.35 ? 0 : persons < 0.7 ? 1 : persons < 0.9 ? 2 : 3;
  kinds.insert(kinds.end(), n_persons, kPersonKind);
  if (draw.Chance(0.35)) kinds.push_back(kLoaderKind);
  if (draw.Chance(0.4)) kinds.push_back(kDebrisKind);
  if (draw.Chance(0.15)) kinds.push_back(kDebrisKind);
  if (draw.Chance(0.25)) kinds.push_back(kFenceKind);
  int added = 0;
  for (const Kind kind : kinds) {
    double length = 0, width = 0, height = 0;
    switch (kind) {
      case kPersonKind:
        height = draw.Uniform(1.6, 1.9), width = draw.Uniform(0.4, 0.6);
        length = draw.Uniform(0.3, 0.5);
        break;
      case kLoaderKind:
        length = draw.Uniform(7.5, 9.0), width = draw.Uniform(2.7, 3.2);
        height = draw.Uniform(3.1, 3.6);
        break;
      case kDebrisKind:
        length = draw.Uniform(0.3, 1.8), width = draw.Uniform(0.3, 1.0);
        height = draw.Uniform(0.2, 0.7);
        break;
      case kFenceKind:
        length = draw.Uniform(2.0, 6.0), width = 0.1, height = draw.Uniform(1.0, 2.0);
        break;
    }
    for (int attempt = 0; attempt < 20; ++attempt) {
      const double r = draw.Uniform(7.0, 28.0), bearing = cab.heading + draw.Uniform(-0.7, 0.7);
      const Eigen::Vector2d xy = cab.xy + r * Eigen::Vector2d(std::cos(bearing), std::sin(bearing));
      const double yaw = draw.Uniform(-kPi, kPi);
      if (!FootprintFree(world, xy, 0.5 * length + 0.2, 0.5 * width + 0.2, yaw)) continue;
      const double floor = FloorAt(world.terrain, xy);
      const std::string name = "extra_" + std::to_string(added);
      switch (kind) {
        case kPersonKind:
          world.obstacles.push_back(
              Box(name, xy, floor, length, width, height, yaw, SemanticClass::kPerson));
          break;
        case kLoaderKind: {
          // As a scenario's parked_loader: body with cab behind, lowered bucket in front.
          const Eigen::Vector2d ex(std::cos(yaw), std::sin(yaw));
          world.obstacles.push_back(Box(name + "/body", xy - 0.08 * length * ex, floor,
                                        0.84 * length, 0.87 * width, height, yaw,
                                        SemanticClass::kOtherLoader));
          world.obstacles.push_back(Box(name + "/bucket", xy + 0.42 * length * ex, floor,
                                        0.16 * length, width, 0.35 * height, yaw,
                                        SemanticClass::kOtherLoader));
          break;
        }
        case kDebrisKind:
          world.obstacles.push_back(
              Box(name, xy, floor, length, width, height, yaw, SemanticClass::kOther));
          break;
        case kFenceKind:
          world.obstacles.push_back(
              Box(name, xy, floor, length, width, height, yaw, SemanticClass::kWall));
          break;
      }
      ++added;
      break;
    }
  }
  return added;
}

}  // namespace

struct YardViewSampler::Data {
  std::vector<Machine> machines;
  std::vector<ScenarioEntry> scenarios;
};

std::uint64_t ViewSeed(std::uint64_t seed, std::uint64_t index) {
  return SplitMix64(SplitMix64(seed) ^ index);
}

YardViewSampler::YardViewSampler(const std::string& models_dir,
                                 const std::vector<std::string>& scenarios)
    : data_(std::make_unique<Data>()) {
  for (const std::string& path : model::FindMachineDescriptions(models_dir)) {
    model::MachineDescription d = model::LoadMachineDescription(path);
    if (d.kind != model::MachineKind::kWheelLoader) continue;
    const generated::MachineFunctions* f = nullptr;
    try {
      f = &machines::MachineFunctionsFor(d);  // compiled in, its library, or interpreted
    } catch (const machines::MachineCodeError&) {
      continue;  // no code it may run: not a yard this sampler can simulate
    }
    data_->machines.push_back({std::move(d), f});
  }
  std::vector<std::string> files;
  if (scenarios.empty()) {
    files = plant::FindScenarios(models_dir);
  } else {
    for (const std::string& s : scenarios) files.push_back(plant::ResolveScenario(s, models_dir));
  }
  for (const std::string& file : files) {
    ScenarioEntry entry;
    entry.name = std::filesystem::path(file).stem().string();
    entry.scenario = plant::LoadScenario(file);
    for (std::size_t m = 0; m < data_->machines.size(); ++m) {
      if (data_->machines[m].description.name == entry.scenario.machine) {
        entry.machine = static_cast<int>(m);
      }
    }
    if (entry.machine < 0) {
      // Every scenario by default: the excavator's yards (truck loading) are not the loader
      // camera's, and are left out. A scenario asked for by name must be a loader's.
      if (scenarios.empty()) continue;
      throw std::runtime_error("scenario " + file + ": machine '" + entry.scenario.machine +
                               "' is not a wheel loader with generated code under " + models_dir);
    }
    const double cell_area = entry.scenario.world.terrain.cell_area();
    for (const plant::Pile& pile : entry.scenario.piles) {
      if (pile.cells == 0) continue;
      Target target;
      target.center = pile.center;
      target.radius = std::sqrt(pile.cells * cell_area / kPi);
      if (pile.bin >= 0) {
        const plant::Bin& bin = entry.scenario.bins.at(pile.bin);
        target.in_bin = true;
        target.bin_front = bin.front_center;
        // The bin extends along v = u turned by +90°; out of it is −v.
        target.outward = Eigen::Vector2d(std::sin(bin.yaw), -std::cos(bin.yaw));
      }
      entry.targets.push_back(target);
    }
    data_->scenarios.push_back(std::move(entry));
  }
  if (data_->scenarios.empty()) {
    throw std::runtime_error("no scenario found under " + models_dir + "/scenarios");
  }
}

YardViewSampler::~YardViewSampler() = default;

std::vector<std::string> YardViewSampler::scenario_names() const {
  std::vector<std::string> names;
  for (const ScenarioEntry& e : data_->scenarios) names.push_back(e.name);
  return names;
}

YardView YardViewSampler::Render(std::uint64_t seed, std::uint64_t index,
                                 std::optional<plant::Lighting> lighting) const {
  Draw draw(ViewSeed(seed, index));
  const ScenarioEntry& entry = data_->scenarios[draw.Index(data_->scenarios.size())];
  // Four views in ten draw the loader among all of them (the scenario's one included), so the
  // network learns the own bodies of every loader description.
  int machine_index = entry.machine;
  if (data_->machines.size() > 1 && draw.Chance(0.4)) {
    machine_index = draw.Index(data_->machines.size());
  }
  const Machine& machine = data_->machines[machine_index];

  YardView view;
  view.scenario = entry.name;
  view.machine = machine.description.name;
  plant::World world = entry.scenario.world;
  std::vector<Target> targets = entry.targets;
  if (draw.Chance(0.5)) {
    const int n = draw.Chance(0.6) ? 1 : 2;
    for (int k = 0; k < n; ++k) view.extra_piles += AddRandomPile(world, draw, targets) ? 1 : 0;
  }

  const Pose2 pose = DrawMachinePose(entry, world, targets, draw);
  const double max_art = std::min(0.5, machine.description.chassis.max_articulation);
  const double articulation = draw.Chance(0.3) ? draw.Uniform(-max_art, max_art) : 0.0;
  const generated::MachineFunctions& f = *machine.functions;
  plant::MachineState state;
  state.hinge_xy = pose.xy;
  state.heading = pose.heading;
  state.articulation = articulation;
  state.pitch = draw.Uniform(-0.03, 0.03);
  state.q.resize(f.num_joints);
  for (int j = 0; j < f.num_joints; ++j) state.q[j] = draw.Uniform(f.joint_min[j], f.joint_max[j]);
  view.x = pose.xy.x(), view.y = pose.xy.y(), view.heading = pose.heading;
  view.articulation = articulation;
  view.joints = state.q;

  // The cab (camera) frame is the rear frame, turned by −γ from the front frame.
  view.extra_obstacles = AddRandomObstacles(world, {pose.xy, pose.heading - articulation}, draw);

  view.lighting = lighting ? *lighting : static_cast<plant::Lighting>(index % 3);
  sensors::CameraOptions options;
  options.lighting = view.lighting;
  const double azimuth = draw.Uniform(-kPi, kPi);
  const double elevation = draw.Uniform(25.0, 70.0) * kPi / 180.0;
  options.sun_direction =
      Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                      std::cos(elevation) * std::sin(azimuth), std::sin(elevation));

  // The plant only supplies the machine's body boxes here: it is never advanced.
  plant::Plant plant(machine.description, f, world, state);
  const sensors::RaycastScene scene(world, plant.OwnBodies());
  const model::Camera& camera = machine.description.sensors.camera;
  view.frame = sensors::SimulateCameraFrame(
      camera, scene, sensors::SensorInWorld(plant.state(), camera.pose), 0.0, options, draw.rng());
  return view;
}

void ConfusionMatrix::Add(const std::vector<std::uint8_t>& truth,
                          const std::vector<std::uint8_t>& predicted) {
  if (truth.size() != predicted.size()) {
    throw std::invalid_argument("ConfusionMatrix: " + std::to_string(truth.size()) +
                                " true labels against " + std::to_string(predicted.size()) +
                                " predicted");
  }
  constexpr int n = core::kNumSemanticClasses;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (truth[i] >= n || predicted[i] >= n) {
      throw std::invalid_argument("ConfusionMatrix: label out of range at pixel " +
                                  std::to_string(i));
    }
    ++counts_[truth[i] * n + predicted[i]];
  }
}

std::optional<double> ConfusionMatrix::Iou(int c) const {
  constexpr int n = core::kNumSemanticClasses;
  std::uint64_t tp = count(c, c), fp = 0, fn = 0;
  for (int k = 0; k < n; ++k) {
    if (k == c) continue;
    fn += count(c, k);
    fp += count(k, c);
  }
  const std::uint64_t uni = tp + fp + fn;
  if (uni == 0) return std::nullopt;
  return static_cast<double>(tp) / static_cast<double>(uni);
}

double ConfusionMatrix::MeanIou() const {
  double sum = 0;
  int defined = 0;
  for (int c = 0; c < core::kNumSemanticClasses; ++c) {
    if (const auto iou = Iou(c)) sum += *iou, ++defined;
  }
  return defined > 0 ? sum / defined : 0.0;
}

std::uint64_t ConfusionMatrix::TruthPixels(int c) const {
  std::uint64_t total = 0;
  for (int k = 0; k < core::kNumSemanticClasses; ++k) total += count(c, k);
  return total;
}

double ConfusionMatrix::PixelAccuracy() const {
  std::uint64_t right = 0, total = 0;
  for (int c = 0; c < core::kNumSemanticClasses; ++c) {
    right += count(c, c);
    total += TruthPixels(c);
  }
  return total > 0 ? static_cast<double>(right) / static_cast<double>(total) : 0.0;
}

}  // namespace autoshovel::identification
