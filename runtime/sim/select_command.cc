#include "runtime/sim/select_command.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <numbers>

#include "generated/registry.h"
#include "runtime/core/diagnostics.h"
#include "runtime/model/description.h"
#include "runtime/perception/elevation_map.h"
#include "runtime/perception/semantic_map.h"
#include "runtime/planning/candidate_render.h"
#include "runtime/planning/chen2024_baseline.h"
#include "runtime/planning/shovel_point_selection.h"
#include "runtime/plant/plant.h"
#include "runtime/plant/poses.h"
#include "runtime/sensors/raycast.h"
#include "runtime/sim/perceive_from_plant.h"

namespace autoshovel::sim {

using namespace planning;  // the planner's selection, on a simulated yard

perception::GridMap TruthMap(const plant::Scenario& scenario, double resolution) {
  const plant::Terrain& t = scenario.world.terrain;
  const Eigen::Vector2d size(t.nx() * t.resolution(), t.ny() * t.resolution());
  perception::GridMap map(resolution, size, t.geometry().origin + size / 2);
  map.Add("elevation");
  map.Add("variance", 1e-4f);
  map.Add("class");
  const double r = resolution;
  for (perception::GridMapIterator it(map); !it.done(); ++it) {
    const Eigen::Vector2d xy = map.PositionOf(*it);
    bool obstacle = false;
    double top = 0;
    for (const plant::OrientedBox& box : scenario.world.obstacles) {
      // The cell is obstacle if the box's footprint comes within the cell's circumradius of its
      // centre: conservative (a little dilated), and thin walls and fences are never missed.
      const Eigen::Vector2d d = xy - box.center.head<2>();
      const double c = std::cos(box.yaw), s = std::sin(box.yaw);
      const double along = std::max(std::abs(c * d.x() + s * d.y()) - box.half_extents.x(), 0.0);
      const double across = std::max(std::abs(-s * d.x() + c * d.y()) - box.half_extents.y(), 0.0);
      if (std::hypot(along, across) <= r * std::sqrt(0.5)) {
        obstacle = true;
        top = std::max(top, box.center.z() + box.half_extents.z());
      }
    }
    if (obstacle) {
      map.at("elevation", *it) = static_cast<float>(top);
      map.at("class", *it) = static_cast<float>(perception::CellClass::kObstacle);
      continue;
    }
    double sum = 0;
    int covered = 0, total = 0;
    const double step = t.resolution();
    for (double dy = -r / 2 + step / 2; dy < r / 2; dy += step) {
      for (double dx = -r / 2 + step / 2; dx < r / 2; dx += step) {
        int ix, iy;
        if (!t.CellOf(xy.x() + dx, xy.y() + dy, ix, iy)) continue;
        ++total;
        sum += t.height(ix, iy);
        covered += t.depth(ix, iy) > 0.01;
      }
    }
    if (total == 0) continue;
    map.at("elevation", *it) = static_cast<float>(sum / total);
    map.at("class", *it) = static_cast<float>(2 * covered > total ? perception::CellClass::kPile
                                                                  : perception::CellClass::kGround);
  }
  return map;
}

namespace {

// The map as the loader perceives it from its start pose: the pipeline of `autoshovel map`.
bool PerceiveMap(const SelectOptions& options, plant::Scenario& scenario,
                 const model::MachineDescription& machine,
                 const generated::MachineFunctions& functions, const plant::MachineState& start,
                 perception::ElevationMap& map, Eigen::Vector3d& plane, std::ostream& err) {
  plant::Plant plant(machine, functions, scenario.world, start);
  sensors::RaycastScene scene(scenario.world, plant.OwnBodies());
  sensors::Rng rng(scenario.seed);
  perception::SemanticMap semantic(map);
  sim::PerceptionFromPlantOptions perceive;
  perceive.lidar_frames = options.frames;
  perceive.lighting = scenario.lighting;
  perceive.truth_labels = options.truth_labels;
  perceive.segmenter = options.segmenter.empty()
                           ? options.models_dir + "/segmentation/yard_segmenter.onnx"
                           : options.segmenter;
  if (!sim::PerceiveFromPlant(plant, scene, rng, perceive, map, semantic).ground_plane_found) {
    err << "autoshovel select: too few ground cells to fit the ground plane\n";
    return false;
  }
  plane = semantic.ground_plane();
  return true;
}

}  // namespace

int RunSelect(const SelectOptions& options, std::ostream& out, std::ostream& err) {
  try {
    plant::ScenarioWithMachine setup =
        plant::LoadScenarioWithMachine(options.scenario, options.models_dir);
    plant::Scenario& scenario = setup.scenario;
    const model::MachineDescription& machine = setup.machine;
    const generated::MachineFunctions* functions = setup.functions;
    if (machine.kind != model::MachineKind::kWheelLoader) {
      err << "autoshovel select: '" << machine.name << "' is not a wheel loader\n";
      return 2;
    }
    ShovelPointConfig config;
    config.candidate_spacing = options.spacing;
    config.safety_distance = options.safety_distance;
    config.pile = options.pile;
    config.entry_angle_offsets.clear();
    for (const double a : options.entry_angles_deg) {
      config.entry_angle_offsets.push_back(a * std::numbers::pi / 180);
    }
    if (const std::string problem = config.Validate(); !problem.empty()) {
      err << "autoshovel select: " << problem << "\n";
      return 2;
    }
    if (options.frames < 1 || options.top < 1) {
      err << "autoshovel select: --frames and --top must be >= 1\n";
      return 2;
    }

    const plant::MachineState start = plant::StartState(scenario, machine, options.advance);
    const Pose2 T_world_hinge{start.hinge_xy, start.heading};

    const auto t0 = std::chrono::steady_clock::now();
    perception::ElevationMap perceived({}, start.hinge_xy);
    perception::GridMap truth;
    Eigen::Vector3d plane(0, 0, scenario.world.terrain.floor(0, 0));
    if (options.truth_map) {
      truth = TruthMap(scenario);
    } else if (!PerceiveMap(options, scenario, machine, *functions, start, perceived, plane, err)) {
      return 1;
    }
    perception::GridMap& map = options.truth_map ? truth : perceived.map();
    const std::vector<perception::ExtractedPile> piles = perception::ExtractPiles(map, plane);
    const auto t1 = std::chrono::steady_clock::now();

    const LoaderGeometry loader = LoaderGeometryFrom(machine, *functions);
    const ShovelPointResult result =
        SelectShovelPoints(map, piles, plane, T_world_hinge, loader, config);
    const auto t2 = std::chrono::steady_clock::now();
    std::vector<Chen2024Candidate> baseline;
    if (options.baseline) {
      baseline = RankChen2024(map, plane, GenerateCandidates(map, piles, config), start.hinge_xy);
    }
    CandidateRenderOptions render;
    render.top = options.top;
    WriteCandidatePng(map, result, options.baseline ? &baseline : nullptr, T_world_hinge, loader,
                      options.png, render);

    char line[320];
    std::snprintf(line, sizeof line,
                  "%s: map from %s in %.2f s, %zu piles; kappa_max %.4f 1/m (R_min %.2f m), "
                  "T_res %.3f m^4, d_res %.2f m; selection %.3f s\n",
                  scenario.name.c_str(),
                  options.truth_map      ? "the simulator's truth"
                  : options.truth_labels ? "perception (simulator labels)"
                                         : "perception (network)",
                  std::chrono::duration<double>(t1 - t0).count(), piles.size(),
                  result.max_curvature, 1 / result.max_curvature, result.torque_threshold,
                  config.safety_distance, std::chrono::duration<double>(t2 - t1).count());
    out << line;
    for (std::size_t p = 0; p < piles.size(); ++p) {
      std::snprintf(line, sizeof line, "  pile %zu at (%.1f, %.1f): %.1f m3, peak %.2f m\n", p,
                    piles[p].centroid.x(), piles[p].centroid.y(), piles[p].volume,
                    piles[p].peak_height);
      out << line;
    }
    out << "Eq. (18): " << ToString(result.status) << ", " << result.message << "\n";
    out << " rank pile   x [m]   y [m] dir[deg] off     F      s_t   s_s  s_c   s_e   s_a  "
           "T_c[m4] d_min[m] path[m] word\n";
    for (int k = 0; k < options.top && k < static_cast<int>(result.ranked.size()); ++k) {
      const ShovelCandidate& c = result.ranked[k];
      if (!c.feasible) break;
      const ScoreBreakdown& s = c.scores;
      std::snprintf(line, sizeof line,
                    " %4d %4d %7.2f %7.2f %7.1f %4.0f %6.3f %6.3f %5.2f %4.0f %5.2f %5.2f %7.3f "
                    "%8.2f %7.2f %s\n",
                    k + 1, c.pose.pile, c.pose.xy.x(), c.pose.xy.y(),
                    c.pose.entry_heading * 180 / std::numbers::pi,
                    c.pose.entry_offset * 180 / std::numbers::pi, c.score, s.s_t, s.s_s, s.s_c,
                    s.s_e, s.s_a, s.torque, std::min(s.min_obstacle_distance, 999.0), s.path_length,
                    std::string(ToString(c.path.word)).c_str());
      out << line;
    }
    if (options.baseline && !baseline.empty()) {
      const Chen2024Candidate& b = baseline.front();
      std::snprintf(line, sizeof line,
                    "Chen et al. 2024 best: pile %d at (%.2f, %.2f) heading %.1f deg, score "
                    "%.3f (convexity %.3f 1/m, inclination %.2f, slope %.1f deg, distance "
                    "%.1f m)\n",
                    b.pose.pile, b.pose.xy.x(), b.pose.xy.y(),
                    b.pose.entry_heading * 180 / std::numbers::pi, b.score, b.raw.convexity,
                    b.raw.inclination, b.raw.slope * 180 / std::numbers::pi, b.raw.distance);
      out << line;
    }
    out << "candidates: " << options.png << "\n";
    return result.status == SelectionStatus::kSelected ? 0 : 1;
  } catch (const core::InputError& e) {
    err << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << "autoshovel select: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace autoshovel::sim
