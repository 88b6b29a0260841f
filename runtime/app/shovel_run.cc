// The main job: closed-loop shoveling cycles in a simulated yard (shovel_run.h).
#include "runtime/app/shovel_run.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "runtime/app/crowd_lookahead.h"
#include "runtime/app/executive.h"
#include "runtime/app/plant_machine.h"
#include "runtime/app/safety_margin.h"
#include "runtime/control/joint_pid.h"
#include "runtime/control/path_follower.h"
#include "runtime/control/speed_pid.h"
#include "runtime/core/strings.h"
#include "runtime/optimal/warm_scoop_solver.h"
#include "runtime/perception/elevation_map.h"
#include "runtime/perception/machine_footprint.h"
#include "runtime/perception/map_render.h"
#include "runtime/perception/perceive_from_plant.h"
#include "runtime/perception/pile_extraction.h"
#include "runtime/perception/semantic_map.h"
#include "runtime/planning/candidate_render.h"
#include "runtime/planning/chen2024_baseline.h"
#include "runtime/planning/shovel_point_selection.h"
#include "runtime/planning/shovel_weights_file.h"
#include "runtime/plant/plant.h"
#include "runtime/plant/poses.h"
#include "runtime/plant/scenario.h"
#include "runtime/plant/scenario_builder.h"
#include "runtime/prediction/model_provenance.h"
#include "runtime/prediction/penetration_predictor.h"
#include "runtime/prediction/shipped_models.h"
#include "runtime/prediction/volume_estimation.h"
#include "runtime/results/plots.h"
#include "runtime/results/report.h"
#include "runtime/results/run_folder.h"
#include "runtime/sensors/raycast.h"
#include "runtime/sensors/rng.h"

namespace autoshovel::app {

const char* ToString(TriggerChoice trigger) {
  switch (trigger) {
    case TriggerChoice::kPredicted:
      return "predicted";
    case TriggerChoice::kPerception:
      return "perception";
    case TriggerChoice::kPressure:
      return "pressure";
  }
  return "?";
}

const char* ToString(SelectionMethod method) {
  return method == SelectionMethod::kOurs ? "ours" : "chen2024";
}

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// The elevation layer as the regular grid the volume estimation reads (unknown cells NaN).
prediction::HeightGrid HeightGridOf(const perception::GridMap& map) {
  prediction::HeightGrid grid;
  grid.resolution = map.resolution();
  grid.nx = map.size().x();
  grid.ny = map.size().y();
  grid.origin = map.position() - 0.5 * map.length();
  grid.height.assign(static_cast<std::size_t>(grid.nx) * grid.ny, NAN);
  const Eigen::MatrixXf& elevation = map["elevation"];
  for (int iy = 0; iy < grid.ny; ++iy) {
    for (int ix = 0; ix < grid.nx; ++ix) {
      perception::Index index;
      if (!map.IndexOf(grid.CellCenter(ix, iy), index)) continue;
      grid.height[static_cast<std::size_t>(iy) * grid.nx + ix] = elevation(index.x(), index.y());
    }
  }
  return grid;
}

// Where cycles dig: a bin holding piles, or the open yard (piles outside bins).
struct Site {
  std::string name;
  int bin = -1;  ///< into Scenario::bins; −1: the open yard
  Eigen::Vector2d start_xy = Eigen::Vector2d::Zero();
  double start_heading = 0;
};

bool InsideBin(const plant::Bin& bin, const Eigen::Vector2d& p) {
  const Eigen::Vector2d u(std::cos(bin.yaw), std::sin(bin.yaw)), v(-u.y(), u.x());
  const Eigen::Vector2d d = p - bin.front_center;
  return std::abs(d.dot(u)) <= bin.width / 2 && d.dot(v) >= -0.5 && d.dot(v) <= bin.depth;
}

std::string Fixed(double value, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, value);
  return text;
}

// What the look-ahead stopped for, for the log: the map's view of the nearest sure obstacle cell
// and, from the simulation's truth, how far that cell lies from the nearest real obstacle (the
// map's blur at a wall; docs/main_job.md).
std::string SureCellReport(const perception::GridMap& map, const Eigen::Vector2d& cell,
                           const plant::World& world) {
  const std::vector<plant::OrientedBox>& obstacles = world.obstacles;
  perception::Index index;
  if (!map.IndexOf(cell, index)) return "nearest sure cell off the map";
  std::string text = "nearest sure cell (" + Fixed(cell.x(), 2) + ", " + Fixed(cell.y(), 2) +
                     "): height " + Fixed(map.at("elevation", index), 2) + " m, obstacle " +
                     Fixed(map.at("obstacle_confidence", index), 2) + " (steep " +
                     Fixed(map.at("steep_obstacle_confidence", index), 2) + "), pile " +
                     Fixed(map.at("pile_confidence", index), 2);
  // A footprint shrunk to the cell's centre: FootprintClearance gives the nearest box.
  perception::MachineFootprint point;
  point.hinge_xy = cell;
  const Clearance truth = FootprintClearance(point, obstacles);
  if (truth.obstacle >= 0) {
    text += "; simulation truth: " + Fixed(truth.distance, 2) + " m from " +
            obstacles[static_cast<std::size_t>(truth.obstacle)].name + ", ground " +
            Fixed(world.terrain.HeightAt(cell.x(), cell.y()), 2) + " m";
  }
  return text;
}

// The options a user can set, checked before anything is loaded, against the ranges documented in
// `autoshovel run --help` and named as the user wrote them: the command line checks them while it
// parses (cli_checks.h), this catches every other caller (campaign specs, tests, library users).
// NaN fails every comparison, hence the negated forms.
void CheckRange(double value, double low, double high, bool open_low, const char* name,
                const char* unit) {
  if (!std::isfinite(value) || value < low || value > high || (open_low && value == low)) {
    throw std::invalid_argument(std::string(name) + " must be in " + (open_low ? "(" : "[") +
                                core::FormatNumber(low) + ", " + core::FormatNumber(high) + "] " +
                                unit + ", got " + core::FormatNumber(value));
  }
}

const ShovelRunOptions& Validated(const ShovelRunOptions& o) {
  if (o.cycles < 1) throw std::invalid_argument("--cycles must be >= 1");
  // The seed is not checked here: a user's --seed is held to [0, 2^63 - 1] by the command line
  // (cli_checks.h), while a campaign derives its jobs' seeds over all 64 bits (campaign_spec.cc).
  CheckRange(o.attack_speed, 0, 3, true, "--attack-speed", "m/s");
  CheckRange(o.scoop_deceleration, 0, 10, true, "--scoop-deceleration", "m/s^2");
  CheckRange(o.pressure_threshold, 0, 420e5, true, "--pressure-bar (as Pa)", "Pa");
  CheckRange(o.safety_distance, 0, 20, false, "--safety-distance", "m");
  CheckRange(o.d_res, 0, 20, true, "--d-res", "m");
  CheckRange(o.target_fill, 0.1, 1.5, false, "--target-fill", "");
  CheckRange(o.yard_variation, 0, 0.9, false, "--yard-variation", "");
  if (o.stairway_steps < 1 || o.stairway_steps > 20) {
    throw std::invalid_argument("--stairway-steps must be in [1, 20], got " +
                                std::to_string(o.stairway_steps));
  }
  return o;
}

}  // namespace

struct ShovelJob::State {
  ShovelRunOptions options;
  // ScoopPolicy::kOptimal: one solver for the run, so that each plan warm-starts from the last.
  optimal::WarmScoopSolver optimal_solver;
  plant::ScenarioWithMachine setup;
  std::vector<std::string> site_names;
  std::vector<Site> sites;
  prediction::PenetrationPredictor predictor;
  planning::LoaderGeometry loader;
  std::unique_ptr<sensors::RaycastScene> scene;
  std::unique_ptr<perception::ElevationMap> map;
  std::unique_ptr<perception::SemanticMap> semantic;
  sensors::Rng rng;
  std::string segmenter;
  /// The scenario's faults and the run's own (plant/fault_spec.h), merged once.
  std::vector<plant::FaultSpec> faults;
  /// Dirt on the lens stays from cycle to cycle, and so does what the monitor learnt of it.
  perception::LensDirtMonitor lens_dirt;
  planning::ShovelPointConfig selection;  ///< Eq. (18) weights: Table 1 or --shovel-weights
  double cycle_clock = 0;  ///< each cycle's plant starts where the last one ended [s]
  int next_site = 0;

  State(const ShovelRunOptions& o)
      : options(o),
        setup(plant::LoadScenarioWithMachine(o.scenario, o.models_dir, o.machine)),
        predictor(prediction::PenetrationPredictor::Load(
            o.predictor.empty() ? prediction::MainJobPredictor(o.models_dir) : o.predictor)),
        rng(o.seed) {
    if (!o.shovel_weights.empty()) planning::ReadShovelWeights(o.shovel_weights, selection);
    plant::VaryPiles(setup.scenario, o.seed, o.yard_variation);
  }
};

ShovelJob::ShovelJob(const ShovelRunOptions& options)
    : state_(std::make_unique<State>(Validated(options))) {
  State& st = *state_;
  const plant::Scenario& scenario = st.setup.scenario;
  const model::MachineDescription& machine = st.setup.machine;
  if (machine.kind != model::MachineKind::kWheelLoader) {
    throw std::invalid_argument("machine '" + machine.name + "' is not a wheel loader");
  }
  if (options.sure_obstacle_growth_cells < 0 || options.sure_obstacle_growth_cells > 10) {
    throw std::invalid_argument("--sure-obstacle-growth must be in [0, 10], got " +
                                std::to_string(options.sure_obstacle_growth_cells));
  }
  const double rates[] = {options.map_rate, options.decision_rate, options.control_rate};
  for (double r : rates) {
    if (!(r > 0) || !std::isfinite(r)) throw std::invalid_argument("bad rate");
  }
  if (options.map_rate > options.control_rate || options.decision_rate > options.control_rate) {
    throw std::invalid_argument("control must be the fastest rate");
  }
  // A fault that names a sensor must name one this machine has (else it would never strike).
  st.faults = scenario.faults;
  st.faults.insert(st.faults.end(), options.faults.begin(), options.faults.end());
  for (const plant::FaultSpec& f : st.faults) {
    if (f.kind != plant::FaultKind::kLidarDeadSector) continue;
    std::string names;
    bool known = false;
    for (const model::Lidar& l : machine.sensors.lidars) {
      known = known || l.name == f.lidar;
      names += (names.empty() ? "" : ", ") + l.name;
    }
    if (!known) {
      throw std::invalid_argument(f.where + ": lidar_dead_sector: machine '" + machine.name +
                                  "' has no LiDAR '" + f.lidar + "' (it has: " + names + ")");
    }
  }
  // Sites: the bins asked for, else every bin holding a pile and the open yard if piles lie
  // outside bins. A bin is entered from `approach_distance` out of its open front, facing in;
  // the open yard from the scenario's start pose.
  auto holds_pile = [&](int b) {
    return std::any_of(scenario.piles.begin(), scenario.piles.end(),
                       [&](const plant::Pile& p) { return p.bin == b; });
  };
  auto bin_site = [&](int b) {
    const plant::Bin& bin = scenario.bins[b];
    const double into_bin = bin.yaw + std::numbers::pi / 2;
    Site site;
    site.name = bin.name;
    site.bin = b;
    site.start_heading = into_bin;
    site.start_xy = bin.front_center - options.approach_distance *
                                           Eigen::Vector2d(std::cos(into_bin), std::sin(into_bin));
    return site;
  };
  if (options.bins.empty()) {
    for (int b = 0; b < static_cast<int>(scenario.bins.size()); ++b) {
      if (holds_pile(b)) st.sites.push_back(bin_site(b));
    }
    if (holds_pile(-1)) {
      st.sites.push_back({.name = "yard",
                          .bin = -1,
                          .start_xy = Eigen::Vector2d(scenario.start.x, scenario.start.y),
                          .start_heading = scenario.start.heading});
    }
  } else {
    for (const std::string& name : options.bins) {
      int found = -1;
      for (int b = 0; b < static_cast<int>(scenario.bins.size()); ++b) {
        if (scenario.bins[b].name == name) found = b;
      }
      if (found < 0) {
        std::string known;
        for (const plant::Bin& b : scenario.bins) known += " " + b.name;
        throw std::invalid_argument("scenario '" + scenario.name + "' has no bin '" + name +
                                    "' (bins:" + (known.empty() ? " none" : known) + ")");
      }
      if (!holds_pile(found)) {
        throw std::invalid_argument("bin '" + name + "' holds no pile");
      }
      st.sites.push_back(bin_site(found));
    }
  }
  if (st.sites.empty()) {
    throw std::invalid_argument("scenario '" + scenario.name + "' has no pile");
  }
  for (const Site& site : st.sites) st.site_names.push_back(site.name);
  st.loader = planning::LoaderGeometryFrom(machine, *st.setup.functions);
  st.segmenter = options.segmenter.empty()
                     ? options.models_dir + "/segmentation/yard_segmenter.onnx"
                     : options.segmenter;
  st.scene = std::make_unique<sensors::RaycastScene>(scenario.world);
  // One map over the whole yard (60 m × 60 m by default), kept across cycles.
  perception::ElevationMapConfig map_config;
  const plant::GridGeometry& g = scenario.world.terrain.geometry();
  const Eigen::Vector2d size(g.nx * g.resolution, g.ny * g.resolution);
  map_config.length = size;
  st.map = std::make_unique<perception::ElevationMap>(map_config, g.origin + 0.5 * size);
  st.semantic = std::make_unique<perception::SemanticMap>(*st.map);
}

ShovelJob::~ShovelJob() = default;

const std::vector<std::string>& ShovelJob::sites() const { return state_->site_names; }
const std::string& ShovelJob::scenario_name() const { return state_->setup.scenario.name; }
const std::string& ShovelJob::machine_name() const { return state_->setup.machine.name; }

const model::MachineDescription& ShovelJob::machine() const { return state_->setup.machine; }

std::string ShovelJob::PredictorMismatch() const {
  const prediction::FeatureScaling& scaling = state_->predictor.scaling();
  // The speed feature's range is the speeds seen at the training runs' triggers: at most the
  // approach speed. 0.1 m/s of slack covers the speed PID's overshoot.
  constexpr double kSlack = 0.1;
  if (scaling.max.empty() || !(state_->options.attack_speed > scaling.max[0] + kSlack)) return "";
  char why[200];
  std::snprintf(why, sizeof why,
                "the predictor was trained at speeds up to %.2f m/s but the machine attacks at "
                "%.2f m/s; V2 is extrapolated (retrain with train_predictor --max-speed)",
                scaling.max[0], state_->options.attack_speed);
  return why;
}

std::string ShovelJob::PredictorMachineMismatch() const {
  const ShovelRunOptions& o = state_->options;
  return prediction::ProvenanceMismatch(
      o.predictor.empty() ? prediction::MainJobPredictor(o.models_dir) : o.predictor,
      state_->setup.machine, o.machine);
}

std::string ShovelJob::ConfigYaml() const {
  const ShovelRunOptions& o = state_->options;
  std::ostringstream y;
  y << "scenario: " << state_->setup.scenario.name << "\n"
    << "scenario_file: " << state_->setup.scenario.source_file << "\n"
    << "machine: " << state_->setup.machine.name << "\n"
    << "cycles: " << o.cycles << "\n"
    << "seed: " << o.seed << "\n"
    << "bins: [";
  for (std::size_t i = 0; i < state_->site_names.size(); ++i) {
    y << (i ? ", " : "") << state_->site_names[i];
  }
  y << "]\n"
    << "semantics: " << (o.truth_labels ? "simulator labels" : state_->segmenter) << "\n"
    << "predictor: "
    << (o.predictor.empty() ? prediction::MainJobPredictor(o.models_dir) : o.predictor) << "\n"
    << "selection: " << ToString(o.selection) << "\n"
    << "shovel_weights: {k_t: " << state_->selection.k_t << ", k_s: " << state_->selection.k_s
    << ", k_c: " << state_->selection.k_c << ", k_e: " << state_->selection.k_e
    << ", k_a: " << state_->selection.k_a << "}"
    << (o.shovel_weights.empty() ? "  # Table 1" : "  # from " + o.shovel_weights) << "\n"
    << "trigger: " << ToString(o.trigger) << "\n"
    << "policy: " << control::ToString(o.policy) << "\n"
    << "pressure_threshold_bar: " << o.pressure_threshold / 1e5 << "\n"
    << "stairway_steps: " << o.stairway_steps << "\n"
    << "scoop_deceleration_mps2: " << o.scoop_deceleration << "\n"
    << "optimal_max_time_s: " << o.optimal_max_time << "\n"
    << "attack_speed_mps: " << o.attack_speed << "\n"
    << "target_fill: " << o.target_fill << "\n"
    << "attitude_feed_forward: " << (o.attitude_feed_forward ? "true" : "false") << "\n"
    << "approach_distance_m: " << o.approach_distance << "\n"
    << "safety_distance_m: " << o.safety_distance << "\n"
    << "d_res_m: " << o.d_res << "\n"
    << "planning_margin_m: " << o.planning_margin << "\n"
    << "selection_margin_m: " << o.selection_margin << "\n"
    << "clear_obstacle_margin: " << o.clear_obstacle_margin << "\n"
    << "sure_obstacle_growth_cells: " << o.sure_obstacle_growth_cells << "\n"
    << "yard_variation: " << o.yard_variation << "\n"
    << "handover_distance_m: " << o.handover_distance << "\n"
    << "max_cycle_time_s: " << o.max_cycle_time << "\n"
    << "rates_hz: {control: " << o.control_rate << ", decisions: " << o.decision_rate
    << ", map_and_selection: " << o.map_rate << "}\n";
  return y.str();
}

CycleOutcome ShovelJob::RunCycle(int index, const std::filesystem::path& figures_dir,
                                 std::ostream* progress) {
  // Sites in turn; one where no shovel point is feasible (blocked by a parked machine, dug out)
  // is skipped, as an operator would drive on to the next bin. Nothing moved there.
  State& st = *state_;
  CycleOutcome out;
  for (std::size_t attempt = 0; attempt < st.sites.size(); ++attempt) {
    const int site = st.next_site;
    st.next_site = (st.next_site + 1) % static_cast<int>(st.sites.size());
    out = RunCycleAt(index, site, figures_dir, progress);
    if (!out.no_shovel_point) return out;
  }
  return out;
}

namespace {

// ScoopPolicy::kOptimal's planner: the optimal-control scoop (runtime/optimal) on the pile the
// map saw, to V_t within `max_time`, warm-started from the run's last plan.
std::optional<control::PlannedScoop> PlanOptimalScoop(optimal::WarmScoopSolver& solver,
                                                      const model::MachineDescription& machine,
                                                      const model::Material& material,
                                                      const control::ScoopPlanRequest& request,
                                                      double max_time, std::string* why) {
  optimal::ContactProblem problem;
  problem.speed = request.speed;
  problem.q = {request.q_boom, request.q_bucket};
  problem.payload_volume = request.payload_volume;
  problem.profile_spacing = request.profile_spacing;
  problem.profile_heights = request.profile_heights;
  problem.target_volume = request.target_volume;
  problem.max_time = max_time;
  const std::optional<optimal::ScoopOcpSolution> solution =
      solver.Solve(machine, material, problem, why);
  if (!solution || !solution->ok) return std::nullopt;
  control::PlannedScoop plan;
  plan.time = solution->time_at;
  for (const auto& x : solution->state) {
    plan.speed.push_back(x[optimal::kV]);
    plan.q_boom.push_back(x[optimal::kQ]);
    plan.q_bucket.push_back(x[optimal::kQ + 1]);
  }
  plan.energy = solution->energy;
  plan.volume = solution->volume;
  plan.solve_seconds = solution->solve_seconds;
  return plan;
}

// The machine and the pile as the bucket touches it: what an optimal scoop from the same start
// needs (runtime/optimal). The pile is the plant's own terrain (simulation truth) sampled along
// the front frame's heading from the hinge, heights above the ground under the hinge.
ContactSnapshot SnapshotAtContact(const plant::Plant& plant, const results::CycleRecord& rec) {
  ContactSnapshot c;
  const plant::MachineState& state = plant.state();
  c.valid = state.q.size() >= 2;
  if (!c.valid) return c;
  c.speed = state.speed;
  c.q = {state.q[0], state.q[1]};
  c.payload_volume = state.payload_volume;
  c.material = rec.material;
  const plant::Terrain& terrain = plant.world().terrain;
  const Eigen::Vector2d forward(std::cos(state.heading), std::sin(state.heading));
  const double ground = terrain.HeightAt(state.hinge_xy.x(), state.hinge_xy.y());
  c.profile_start = 0;
  c.profile_spacing = 0.05;
  for (double x = 0; x <= 14.0 + 1e-9; x += c.profile_spacing) {
    const Eigen::Vector2d p = state.hinge_xy + x * forward;
    c.profile_heights.push_back(terrain.HeightAt(p.x(), p.y()) - ground);
  }
  return c;
}

}  // namespace

CycleOutcome ShovelJob::RunCycleAt(int index, int site_index,
                                   const std::filesystem::path& figures_dir,
                                   std::ostream* progress) {
  State& st = *state_;
  const ShovelRunOptions& o = st.options;
  plant::Scenario& scenario = st.setup.scenario;
  const model::MachineDescription& machine = st.setup.machine;
  const Site& site = st.sites[site_index];
  // Piles of this site: inside its bin, or, in the open yard, within the stockpile area the
  // yard's plan gives (2 m beyond each open pile's footprint). A map pile elsewhere (noise far
  // away, where Eq. (11) falls back on height alone) is not a work area.
  auto in_site = [&](const Eigen::Vector2d& p) {
    if (site.bin >= 0) return InsideBin(scenario.bins[site.bin], p);
    return std::any_of(scenario.piles.begin(), scenario.piles.end(), [&](const plant::Pile& q) {
      const double extent = std::max({q.base_radius, q.length / 2, q.width / 2});
      return q.bin < 0 && (p - q.center).norm() <= extent + 2.0;
    });
  };

  CycleOutcome out;
  results::CycleRecord& rec = out.record;
  rec.cycle = index;
  rec.scenario = scenario.name;
  rec.machine = machine.name;
  rec.bin = site.name;
  rec.completed = false;
  auto say = [&](const std::string& text) {
    if (progress != nullptr) *progress << "[cycle " << index + 1 << "] " << text << "\n";
  };

  // Start: at the site's start pose, bucket on the floor, empty.
  plant::MachineState start = plant::StartState(scenario, machine);
  start.hinge_xy = site.start_xy;
  start.heading = site.start_heading;
  start.time = st.cycle_clock;
  plant::PlantOptions plant_options;
  plant_options.energy_audit = o.energy_audit;
  plant::Plant plant(machine, *st.setup.functions, scenario.world, start, plant_options);
  PlantMachine machine_io(plant);
  st.scene->Update();  // the terrain as the last cycle left it

  control::ScoopCycleOptions scoop_options;
  scoop_options.tick = 1.0 / o.control_rate;
  scoop_options.decision_every =
      std::max(1, static_cast<int>(std::lround(o.control_rate / o.decision_rate)));
  const std::vector<double> q_attack = plant::BucketOnFloor(machine);
  scoop_options.attack_pose = {.boom = q_attack[0], .bucket = q_attack[1]};
  scoop_options.policy = o.policy;
  scoop_options.strategy.fixed_steps = o.stairway_steps;
  scoop_options.scoop_deceleration = o.scoop_deceleration;
  scoop_options.attack_speed = o.attack_speed;
  scoop_options.target_fill = o.target_fill;
  scoop_options.attitude_feed_forward = o.attitude_feed_forward;
  out.target_volume = scoop_options.target_fill * machine.bucket.rated_capacity;

  perception::PerceptionFromPlantOptions perceive;
  perceive.lighting = scenario.lighting;
  perceive.truth_labels = o.truth_labels;
  perceive.segmenter = st.segmenter;

  planning::ShovelPointConfig select_config = st.selection;
  // Eq. (14) scores clearance but, as the seed writes it, only penalises a path that comes
  // closer than d_res (s_s = d_min / d_res). The run holds every cycle to the safety distance,
  // so our selection takes the best candidate whose planned clearance is at least the safety
  // distance plus `selection_margin` (the path follower cuts corners and lags curvature steps
  // by some centimetres; the planned clearance already leaves out half a map cell and half
  // its outline sampling, shovel_point_selection.h).
  select_config.safety_distance = o.d_res;
  const double min_planned_clearance = o.safety_distance + o.selection_margin;
  // Paths are planned at most at `curvature_reserve` of κmax: the follower keeps articulation
  // in hand to pull back onto a path whose curvature steps it can only follow at a finite rate.
  select_config.max_curvature = o.curvature_reserve * st.loader.MaxCurvature();
  // Eq. (14)'s area A runs on past the contact as far as the machine drives in, with the front
  // edge as far as the bucket reaches while it scoops (the boom lifted: beyond the tip on the
  // floor that the selection's body outline assumes).
  select_config.scoop_advance =
      o.scoop_drive_in +
      std::max(0.0, ScoopReach(machine, scoop_options.attack_pose.boom,
                               scoop_options.attack_pose.bucket, scoop_options.strategy) -
                        st.loader.tip_reach);
  // The look-ahead (below) ends the crowd once the sweep's front edge comes within the safety
  // distance, the planning margin, a map cell and the stopping distance of an obstacle ahead;
  // the selection's scoop drives on only as far (0.5 m stands in for the stopping distance,
  // v / f + v² / 2a at crowding speeds, and the middle of the front edge for the corridor).
  select_config.crowd_stop_distance =
      o.safety_distance + o.planning_margin + st.map->map().resolution() + 0.5;

  // kSafeStop: the supervisor abandoned the cycle; the machine brakes to rest, then kDone.
  enum class Stage { kSelect, kNavigate, kScoop, kSafeStop, kDone } stage = Stage::kSelect;
  std::optional<planning::ShovelCandidate> goal;
  std::optional<control::PathFollower> follower;
  std::unique_ptr<control::ScoopTrigger> trigger;
  std::unique_ptr<control::ScoopCycle> scoop;
  const plant::Pile* pile = nullptr;
  prediction::HeightGrid pre_contact;  ///< the map before contact, which the scoop cycle reads
  std::vector<Eigen::Vector2d> sure_obstacles;  ///< the pre-contact map's sure obstacle cells
  double obstacle_resolution = 0;
  planning::ShovelPointResult last_selection;
  std::vector<planning::Chen2024Candidate> last_baseline;
  std::vector<perception::ExtractedPile> last_piles;
  double remaining = INFINITY;
  double max_cross_track = 0;  ///< largest distance of the front axle from its path [m]
  double min_clearance = INFINITY;
  /// Farthest the front axle went past the planned contact pose along the entry heading [m]:
  /// what the selection's scoop_advance must cover.
  double scoop_advance = 0;
  int violations = 0;
  bool in_violation = false;
  bool stop_requested = false;
  long perception_calls = 0, selections = 0;
  double perception_seconds = 0, selection_seconds = 0;
  const double t0 = plant.time();

  // Faults this cycle meets (plant/fault_spec.h): the scenario's and the run's own; and the
  // supervisor that answers them (safety_supervisor.h).
  const std::vector<plant::FaultSpec>& faults = st.faults;
  auto active = [&](plant::FaultKind kind) -> const plant::FaultSpec* {
    for (const plant::FaultSpec& f : faults) {
      if (f.kind == kind && f.ActiveAt(index, plant.time() - t0)) return &f;
    }
    return nullptr;
  };
  auto has_fault = [&](plant::FaultKind kind) {
    return std::any_of(faults.begin(), faults.end(), [&](const plant::FaultSpec& f) {
      return f.kind == kind && f.InCycle(index);
    });
  };
  SafetySupervisor supervisor(o.supervisor);
  std::vector<plant::OrientedBox> fault_obstacles;  ///< people a fault put in the yard
  bool person_placed = false;
  Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic> planned_obstacles;  ///< see start_path
  double last_reason_seen = -1e9;  ///< when the supervisor last saw a reason to hold [s]
  long frames_arrived = 0;         ///< perception ticks (every second one lags in a fault)
  std::string degraded;            ///< degraded sensors as the last map update found them
  bool dirt_reported = false;
  std::vector<Eigen::Vector2d> nav_sure;  ///< the current map's sure obstacle cells
  double stop_speed = 0, stop_xy_travel = 0;
  Eigen::Vector2d stop_xy = Eigen::Vector2d::Zero();
  // Abandons the cycle: the interlock holds the machine stopped until it rests.
  auto safe_stop = [&](const std::string& reason) {
    supervisor.Stop(reason);
    machine_io.HoldStop(true);
    stop_xy = plant.state().hinge_xy;
    stop_speed = std::abs(plant.state().speed);
    out.failure = "safe stop: " + reason;
    stage = Stage::kSafeStop;
    say("SAFE STOP at t = " + Fixed(plant.time() - t0, 2) + " s: " + reason);
  };

  control::JointPid boom_pid(
      scoop_options.boom_gains,
      machine.hydraulics.actuators[machine.ActuatorOfJoint(0)].valve.dead_zone);
  control::JointPid bucket_pid(
      scoop_options.bucket_gains,
      machine.hydraulics.actuators[machine.ActuatorOfJoint(1)].valve.dead_zone);
  control::SpeedPid speed_pid(scoop_options.speed_gains);
  speed_pid.Reset(0.0);
  core::ActuatorCommand command;
  command.valve.assign(machine.hydraulics.actuators.size(), 0.0);
  double target_speed = 0;
  double articulation_rate = 0;

  // 7 Hz: the map from the sensors now, then (before committing to a path) the selection.
  auto select = [&]() {
    const auto w0 = std::chrono::steady_clock::now();
    perception::GridMap& grid = st.map->map();
    const Eigen::Vector3d plane = st.semantic->ground_plane();
    std::vector<perception::ExtractedPile> piles = perception::ExtractPiles(grid, plane);
    std::vector<perception::ExtractedPile> in_bin;
    for (auto& p : piles) {
      if (in_site(p.centroid)) in_bin.push_back(std::move(p));
    }
    // From the localisation (a jump moves where the machine believes it stands).
    const control::Proprioception s = machine_io.Sense();
    const planning::Pose2 T_world_hinge{s.hinge_xy, s.heading};
    last_selection =
        planning::SelectShovelPoints(grid, in_bin, plane, T_world_hinge, st.loader, select_config);
    last_piles = in_bin;
    // The best candidate whose approach and whole scoop keep the planned clearance; failing
    // that, the best whose approach does (its crowd will be ended early by the look-ahead).
    const planning::ShovelCandidate* best = nullptr;
    for (const bool whole_scoop : {true, false}) {
      for (const planning::ShovelCandidate& k : last_selection.ranked) {
        const double d =
            whole_scoop ? k.scores.min_obstacle_distance : k.scores.approach_obstacle_distance;
        if (k.feasible && d >= min_planned_clearance) {
          best = &k;
          break;
        }
      }
      if (best != nullptr) break;
    }
    if (o.selection == SelectionMethod::kChen2024) {
      last_baseline = planning::RankChen2024(
          grid, plane, planning::GenerateCandidates(grid, in_bin, select_config), s.hinge_xy);
      best = nullptr;
      // The baseline's first choice that our planner can reach (Chen et al. plan no path): a
      // kinematically feasible path that neither collides nor drives over the pile, whatever
      // its clearance and our five scores.
      for (const planning::Chen2024Candidate& chen : last_baseline) {
        const planning::CandidatePose& c = chen.pose;
        for (const planning::ShovelCandidate& k : last_selection.ranked) {
          if (k.feasible && k.pose.pile == c.pile && k.pose.point == c.point &&
              std::abs(k.pose.entry_offset - c.entry_offset) < 1e-9) {
            best = &k;
          }
        }
        if (best != nullptr) break;
      }
    }
    ++selections;
    selection_seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
    return best;
  };
  auto update_map = [&]() {
    const auto w0 = std::chrono::steady_clock::now();
    std::vector<plant::OrientedBox> extra = plant.OwnBodies();
    extra.insert(extra.end(), fault_obstacles.begin(), fault_obstacles.end());
    st.scene->SetExtraBoxes(std::move(extra));
    // Frames that arrive: none in a dropout or a blackout; late ones (stamped `lag_s` before
    // now, every second frame) refused by the supervisor's order check, never fused.
    const double now = plant.time();
    const plant::FaultSpec* late = active(plant::FaultKind::kTimestampsOutOfOrder);
    auto stamp_of = [&](const char* sensor) {
      const bool lagging = late != nullptr && late->sensor == sensor && frames_arrived % 2 == 1;
      return lagging ? now - late->lag_s : now;
    };
    const bool lidar = active(plant::FaultKind::kLidarDropout) == nullptr &&
                       supervisor.AcceptFrame(SensorStream::kLidar, stamp_of("lidar"), now);
    const bool camera = active(plant::FaultKind::kCameraBlackout) == nullptr &&
                        supervisor.AcceptFrame(SensorStream::kCamera, stamp_of("camera"), now);
    ++frames_arrived;
    perceive.lidar_frames = !lidar ? 0 : perception_calls == 0 ? 5 : 1;
    perceive.camera_frame = camera;
    const plant::FaultSpec* blind = active(plant::FaultKind::kLidarDeadSector);
    perceive.dead_lidar = blind != nullptr ? blind->lidar : "";
    perceive.dead_sector = blind != nullptr ? blind->sector_rad : Eigen::Vector2d::Zero();
    const plant::FaultSpec* dirt = active(plant::FaultKind::kCameraLensDirt);
    const model::Camera& camera_model = machine.sensors.camera;
    perceive.lens_dirt_center_px = dirt != nullptr
                                       ? Eigen::Vector2d(dirt->center.x() * camera_model.width_px,
                                                         dirt->center.y() * camera_model.height_px)
                                       : Eigen::Vector2d::Zero();
    perceive.lens_dirt_radius_px = dirt != nullptr ? dirt->radius * camera_model.width_px : 0.0;
    perceive.check_lidar_health = true;
    perceive.lens_dirt = &st.lens_dirt;
    const perception::PerceptionFromPlantStats seen =
        perception::PerceiveFromPlant(plant, *st.scene, st.rng, perceive, *st.map, *st.semantic);
    // Degraded sensors: a blind sector facing the way the machine goes, a view masked for dirt.
    out.masked_fraction = std::max(out.masked_fraction, seen.camera_dirty_fraction);
    out.blind_sector = out.blind_sector || !seen.blind_sectors.empty();
    degraded.clear();
    const double travel = target_speed < 0 ? std::numbers::pi : 0.0;
    for (const auto& [name, sector] : seen.blind_sectors) {
      if (!perception::SectorFaces(sector, travel, o.supervisor.blind_sector_cone)) continue;
      degraded += (degraded.empty() ? "" : ", ") + std::string("LiDAR ") + name + " blind from " +
                  Fixed(sector.from * 180 / std::numbers::pi, 0) + " to " +
                  Fixed(sector.to * 180 / std::numbers::pi, 0) + " deg";
    }
    if (perceive.camera_frame && seen.camera_dirty_fraction > o.supervisor.max_masked_fraction) {
      degraded += (degraded.empty() ? "" : ", ") + std::string("camera view ") +
                  Fixed(100 * seen.camera_dirty_fraction, 0) + " % masked for lens dirt";
    }
    if (seen.camera_dirty_fraction > 0 && !dirt_reported) {
      say("lens dirt found: " + Fixed(100 * seen.camera_dirty_fraction, 1) +
          " % of the image masked at t = " + Fixed(now - t0, 2) + " s");
      dirt_reported = true;
    }
    // The look-ahead along the path stops for less: a person who stepped in is in the
    // obstacle evidence at 0.5 two frames later (blended at 0.3 a frame), at 0.95 only after
    // nine (1.3 s at 7 Hz, beyond a loader's stopping distance at 1.5 m/s).
    // Only what stands at least `path_obstacle_height` above the ground plane: a low cell's
    // middling obstacle evidence is a shadow or a label's blur on the floor, not a person.
    nav_sure.clear();
    const Eigen::Vector3d plane = st.semantic->ground_plane();
    for (const Eigen::Vector2d& c :
         SureObstacleCells(st.map->map(), o.path_obstacle_margin, 0, o.path_obstacle_confidence)) {
      perception::Index i;
      if (!st.map->map().IndexOf(c, i)) continue;
      const double height =
          st.map->map().at("elevation", i) - (plane.x() * c.x() + plane.y() * c.y() + plane.z());
      if (height >= o.path_obstacle_height) nav_sure.push_back(c);
    }
    ++perception_calls;
    perception_seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  };
  planning::ShovelPointResult goal_selection;
  std::vector<planning::Chen2024Candidate> goal_baseline;
  planning::Pose2 goal_from{start.hinge_xy, start.heading};
  // A new goal (its selection kept for the figure), or the same goal on a re-planned path.
  auto start_path = [&](const planning::ShovelCandidate& c, bool new_goal = true) {
    goal = c;
    if (new_goal) {
      goal_selection = last_selection;
      goal_baseline = last_baseline;
      const control::Proprioception now = machine_io.Sense();
      goal_from = {now.hinge_xy, now.heading};
    }
    follower.emplace(planning::SamplePath(c.path, 0.1), st.loader);
    // The obstacles this path was planned round: the look-ahead along the path stops only for
    // the others (those that came after).
    const Eigen::MatrixXf& cls = st.map->map()["class"];
    planned_obstacles = (cls.array() == static_cast<float>(perception::CellClass::kObstacle));
  };

  MultiRateExecutive executive(1.0 / o.control_rate, plant.time());
  executive.Add("map_and_selection", 1.0 / o.map_rate, [&](double) {
    if (stage != Stage::kSelect && stage != Stage::kNavigate) return;
    update_map();
    // Selection re-runs until the remaining path is short (a goal that moved under the bucket
    // would be chased): commit 5 m before the handover; a new goal must beat the one being
    // driven to by 0.05 in F (hysteresis against dithering between near-equal candidates).
    if (stage == Stage::kSelect || remaining > o.handover_distance + 5.0) {
      const planning::ShovelCandidate* best = select();
      if (stage == Stage::kSelect) {
        if (best == nullptr) {
          double best_approach = -INFINITY;
          for (const planning::ShovelCandidate& k : last_selection.ranked) {
            if (k.feasible) {
              best_approach = std::max(best_approach, k.scores.approach_obstacle_distance);
            }
          }
          out.failure =
              "no feasible shovel point in " + site.name + " (" + last_selection.message +
              (std::isfinite(best_approach)
                   ? "; none planned " + Fixed(min_planned_clearance, 2) +
                         " m clear of obstacles, the clearest " + Fixed(best_approach, 2) + " m"
                   : std::string()) +
              ")";
          out.no_shovel_point = true;
          stage = Stage::kDone;
          return;
        }
        start_path(*best);
        stage = Stage::kNavigate;
        say("selected point (" + Fixed(best->pose.xy.x(), 2) + ", " + Fixed(best->pose.xy.y(), 2) +
            ") heading " + Fixed(best->pose.entry_heading / kDeg, 1) + " deg, F " +
            Fixed(best->score, 3) + ", path " + Fixed(best->path.length(), 1) + " m, d_min " +
            Fixed(best->scores.min_obstacle_distance, 2) + " m (approach " +
            Fixed(best->scores.approach_obstacle_distance, 2) + " m, scoop " +
            Fixed(select_config.scoop_advance, 1) + " m in); Eq. (18) scores s_t " +
            Fixed(best->scores.s_t, 2) + ", s_s " + Fixed(best->scores.s_s, 2) + ", s_c " +
            Fixed(best->scores.s_c, 0) + " (V_l/V_m/V_r " + Fixed(best->scores.volume_left, 2) +
            "/" + Fixed(best->scores.volume_middle, 2) + "/" + Fixed(best->scores.volume_right, 2) +
            " m3), s_e " + Fixed(best->scores.s_e, 2) + ", s_a " + Fixed(best->scores.s_a, 2));
      } else if (best != nullptr) {
        // The goal being driven to, as seen on the new map and planned from where the machine
        // is now: infeasible (an obstacle came into view) → take the best; beaten by 0.05 in F
        // (our selection only) → take the best; otherwise keep it, on its re-planned path.
        // The goal is found again as the nearest candidate within 0.5 m and half the entry
        // angles' spacing in heading: the boundary normal a heading is measured from moves a
        // few degrees as more of the pile comes into view, and an exact match lost the goal
        // every few frames and sent the machine round the pile after whatever scored best.
        double half_angle_step = std::numbers::pi;
        const std::vector<double>& offsets = select_config.entry_angle_offsets;
        for (std::size_t i = 1; i < offsets.size(); ++i) {
          half_angle_step = std::min(half_angle_step, 0.5 * std::abs(offsets[i] - offsets[i - 1]));
        }
        const planning::ShovelCandidate* current = nullptr;
        double current_mismatch = 1.0;
        for (const planning::ShovelCandidate& k : last_selection.ranked) {
          const double mismatch =
              std::max((k.pose.xy - goal->pose.xy).norm() / 0.5,
                       std::abs(std::remainder(k.pose.entry_heading - goal->pose.entry_heading,
                                               2 * std::numbers::pi)) /
                           half_angle_step);
          if (mismatch < current_mismatch) current = &k, current_mismatch = mismatch;
        }
        if (current == nullptr || !current->feasible ||
            (o.selection == SelectionMethod::kOurs &&
             current->scores.approach_obstacle_distance < min_planned_clearance)) {
          const std::string why = current == nullptr ? "not among the new candidates"
                                  : !current->feasible
                                      ? current->infeasible
                                      : "approach " +
                                            Fixed(current->scores.approach_obstacle_distance, 2) +
                                            " m from an obstacle";
          start_path(*best);
          say("re-selected (goal no longer feasible: " + why + "): point (" +
              Fixed(best->pose.xy.x(), 2) + ", " + Fixed(best->pose.xy.y(), 2) + ") heading " +
              Fixed(best->pose.entry_heading / kDeg, 1) + " deg, F " + Fixed(best->score, 3) +
              ", d_min " + Fixed(best->scores.min_obstacle_distance, 2) + " m");
        } else if (o.selection == SelectionMethod::kOurs && best->score > current->score + 0.05) {
          start_path(*best);
          say("re-selected: point (" + Fixed(best->pose.xy.x(), 2) + ", " +
              Fixed(best->pose.xy.y(), 2) + ") heading " +
              Fixed(best->pose.entry_heading / kDeg, 1) + " deg, F " + Fixed(best->score, 3) +
              ", d_min " + Fixed(best->scores.min_obstacle_distance, 2) + " m");
        } else {
          start_path(*current, /*new_goal=*/false);
        }
      }
    }
  });
  // The supervisor's 20 Hz checks (safety_supervisor.h): faults that put a person in the way,
  // the sensor watchdog and the look-ahead along the path while driving, the actuators.
  auto supervise_at_20hz = [&]() {
    const plant::MachineState& truth = plant.state();
    const control::Proprioception sensed = machine_io.Sense();
    const plant::FaultSpec* person = active(plant::FaultKind::kPersonEntersPath);
    if (person != nullptr && !person_placed && stage == Stage::kNavigate && goal) {
      // On the planned path, `ahead_m` beyond the point of it nearest the front axle now.
      const std::vector<planning::PathSample> path = planning::SamplePath(goal->path, 0.1);
      const Eigen::Vector2d front_axle =
          truth.hinge_xy + machine.chassis.hinge_to_front_axle *
                               Eigen::Vector2d(std::cos(truth.heading), std::sin(truth.heading));
      std::size_t nearest = 0;
      for (std::size_t k = 0; k < path.size(); ++k) {
        if ((path[k].xy - front_axle).norm() < (path[nearest].xy - front_axle).norm()) nearest = k;
      }
      std::size_t at = nearest;
      while (at + 1 < path.size() && path[at].s - path[nearest].s < person->ahead_m) ++at;
      plant::OrientedBox box;
      box.name = "person (fault " + person->where + ")";
      box.center = {path[at].xy.x(), path[at].xy.y(), 0.9};
      box.half_extents = {0.3, 0.3, 0.9};
      box.semantic_class = core::SemanticClass::kPerson;
      fault_obstacles.push_back(box);
      person_placed = true;
      say("a person steps onto the path at t = " + Fixed(plant.time() - t0, 2) + " s at (" +
          Fixed(box.center.x(), 2) + ", " + Fixed(box.center.y(), 2) + "), " +
          Fixed(path[at].s - path[nearest].s, 1) + " m ahead along it (fault)");
    }
    if (person_placed && person == nullptr && !fault_obstacles.empty()) {
      // The fault's window ended: the person walks off (the map forgets them as it sees the
      // ground there again).
      fault_obstacles.clear();
      say("the person leaves at t = " + Fixed(plant.time() - t0, 2) + " s (fault)");
    }
    if (stage == Stage::kNavigate) {
      const double t = plant.time();
      // Watchdog: no motion on a stale map, nor on one from a degraded sensor.
      std::string stale = supervisor.StaleSensors(t);
      if (!degraded.empty()) stale += (stale.empty() ? "" : ", ") + degraded;
      // Look-ahead along the path: a tube of the body's half width plus half the safety
      // distance round the rest of the planned path, for obstacles the path was not planned
      // round (a person who stepped onto it; one beside it makes the 7 Hz re-selection plan
      // round them). The distance is from the bucket's front edge along the path.
      const double v = std::max(0.0, sensed.speed);
      const double stopping =
          v / o.decision_rate + v * v / (2 * scoop_options.speed_gains.max_deceleration);
      const double reach = prediction::TipInBase(machine, sensed.q_boom, sensed.q_bucket).x();
      const double lf = machine.chassis.hinge_to_front_axle;
      const double front_beyond_axle = reach + 0.3 - lf;
      const perception::MachineFootprint body = perception::LoaderFootprint(
          machine, sensed.hinge_xy, sensed.heading, sensed.articulation, reach);
      const double tube = body.half_width + o.safety_distance / 2;
      const double needed = o.safety_distance + o.planning_margin + stopping +
                            st.map->map().resolution() +
                            (supervisor.stopped() ? o.resume_clearance : 0.0);
      double ahead = INFINITY;
      Eigen::Vector2d blocking_cell = Eigen::Vector2d::Zero();
      if (goal && !nav_sure.empty()) {
        const std::vector<planning::PathSample> path = planning::SamplePath(goal->path, 0.2);
        const Eigen::Vector2d axle =
            sensed.hinge_xy +
            lf * Eigen::Vector2d(std::cos(sensed.heading), std::sin(sensed.heading));
        std::size_t k0 = 0;
        for (std::size_t k = 0; k < path.size(); ++k) {
          if ((path[k].xy - axle).norm() < (path[k0].xy - axle).norm()) k0 = k;
        }
        const double horizon = front_beyond_axle + needed + 1.0;
        std::vector<Eigen::Vector2d> near;
        for (const Eigen::Vector2d& c : nav_sure) {
          // Within two cells of one it was planned round: more of that obstacle, come into
          // view as the machine drove on (a parked loader's far side), not a newcomer.
          perception::Index i;
          bool planned_round = false;
          if (st.map->map().IndexOf(c, i)) {
            for (int dx = -2; dx <= 2 && !planned_round; ++dx) {
              for (int dy = -2; dy <= 2 && !planned_round; ++dy) {
                const int x = i.x() + dx, y = i.y() + dy;
                planned_round = x >= 0 && y >= 0 && x < planned_obstacles.rows() &&
                                y < planned_obstacles.cols() && planned_obstacles(x, y);
              }
            }
          }
          if (!planned_round && (c - axle).norm() < horizon + tube) near.push_back(c);
        }
        for (std::size_t k = k0; k < path.size() && std::isinf(ahead); ++k) {
          const double along = path[k].s - path[k0].s;
          if (along > horizon) break;
          // From the bucket's front edge on: beside the body lie its own returns' fringe (the
          // map's cells straddle the self-filter's outline) and what the planner kept clear.
          if (along < front_beyond_axle - 0.3) continue;
          for (const Eigen::Vector2d& c : near) {
            if ((c - path[k].xy).norm() < tube) {
              ahead = along - front_beyond_axle;
              blocking_cell = c;
              break;
            }
          }
        }
      }
      const bool blocked = ahead < needed;
      const std::string why = !stale.empty() ? "sensor watchdog: " + stale
                              : blocked
                                  ? "obstacle " + Fixed(ahead, 2) + " m ahead on the path; " +
                                        SureCellReport(st.map->map(), blocking_cell, plant.world())
                                  : "";
      if (!why.empty() && !supervisor.stopped()) {
        supervisor.Stop(why);
        machine_io.HoldStop(true);
        stop_xy = truth.hinge_xy;
        stop_speed = std::abs(truth.speed);
        say("stop at t = " + Fixed(t - t0, 2) + " s: " + why);
      }
      if (!why.empty()) last_reason_seen = t;
      if (why.empty() && supervisor.stopped() && t - last_reason_seen >= o.resume_after) {
        say("drives on at t = " + Fixed(t - t0, 2) + " s (was: " + supervisor.reason() + ")");
        supervisor.Resume();
        machine_io.HoldStop(false);
        speed_pid.Reset(sensed.speed);  // its integral wound up against the brake
      }
      if (supervisor.stopped()) {
        stop_xy_travel = std::max(stop_xy_travel, (truth.hinge_xy - stop_xy).norm());
      }
    }
    if (stage == Stage::kNavigate || stage == Stage::kScoop) {
      for (int j = 0; j < 2; ++j) {
        const JointCheck check = supervisor.CheckJoint(
            j, j == 0 ? "boom" : "bucket", plant.time(),
            ReadJoint(machine, j, sensed, machine_io.last_command()), RangeOf(machine, j));
        if (check.state == JointState::kDoesNotAnswer) {
          safe_stop(check.message);
          return;
        }
        if (check.state == JointState::kStallsUnderLoad && check.first_report) {
          // Not a fault: the scoop ends what it was doing (ScoopCycle::JointStalledUnderLoad).
          say(check.message + " at t = " + Fixed(plant.time() - t0, 2) + " s" +
              (scoop ? std::string(" (scoop ") + scoop->phase_name() + "): the " +
                           (j == 0 ? "boom" : "bucket") + " is held where it stalled"
                     : std::string()));
          if (scoop) scoop->JointStalledUnderLoad(j, check.message);
        }
      }
    }
  };
  executive.Add("state_machine_and_safety", 1.0 / o.decision_rate, [&](double) {
    const plant::MachineState& s = plant.state();
    const double reach = prediction::TipInBase(machine, s.q[0], s.q[1]).x();
    const perception::MachineFootprint footprint =
        perception::LoaderFootprint(machine, s.hinge_xy, s.heading, s.articulation, reach);
    std::vector<plant::OrientedBox> truth_obstacles = scenario.world.obstacles;
    truth_obstacles.insert(truth_obstacles.end(), fault_obstacles.begin(), fault_obstacles.end());
    const Clearance c = FootprintClearance(footprint, truth_obstacles);
    min_clearance = std::min(min_clearance, c.distance);
    const bool violating = c.distance < o.safety_distance;
    if (violating && !in_violation) {
      ++violations;
      say("SAFETY: " + Fixed(c.distance, 2) + " m from " + truth_obstacles[c.obstacle].name +
          " at t = " + Fixed(plant.time() - t0, 2) + " s, hinge (" + Fixed(s.hinge_xy.x(), 2) +
          ", " + Fixed(s.hinge_xy.y(), 2) + "), heading " + Fixed(s.heading / kDeg, 1) +
          " deg, articulation " + Fixed(s.articulation / kDeg, 1) + " deg, path error so far " +
          Fixed(max_cross_track, 2) + " m");
    }
    in_violation = violating;
    supervise_at_20hz();
    if (stage == Stage::kScoop && goal) {
      const Eigen::Vector2d front_axle =
          s.hinge_xy + machine.chassis.hinge_to_front_axle *
                           Eigen::Vector2d(std::cos(s.heading), std::sin(s.heading));
      const double entry = goal->front_axle_goal.heading;
      scoop_advance =
          std::max(scoop_advance, (front_axle - goal->front_axle_goal.xy)
                                      .dot(Eigen::Vector2d(std::cos(entry), std::sin(entry))));
    }
    // Look-ahead on the map (the machine's own knowledge, not the truth above; crowd_lookahead.h):
    // while the scoop cycle drives in, the front edge of what the scoop will sweep must keep the
    // safety distance plus the planning margin plus the stopping distance from the map's sure
    // obstacle cells ahead; closer, crowding ends here (a pile against a wall is dug up to the
    // wall's safety distance, never into it).
    const std::string scoop_phase = scoop ? scoop->phase_name() : "";
    // From contact on: before it the planned path (clearance d_min with its margin) holds.
    const bool driving_in = scoop_phase == "crowd" || scoop_phase == "scoop";
    if (stage == Stage::kScoop && driving_in && !stop_requested) {
      // The front edge of what the scoop will sweep, and the sure obstacles in the corridor.
      perception::MachineFootprint sweep = footprint;
      sweep.front_length =
          std::max(footprint.front_length,
                   ScoopReach(machine, s.q[0], s.q[1], scoop_options.strategy) + 0.3);
      int nearest = -1;
      const double ahead = DistanceAhead(sure_obstacles, s.hinge_xy, s.heading, sweep.half_width,
                                         sweep.front_length, obstacle_resolution, &nearest);
      // Stopping takes the decision latency (one 20 Hz period) plus v² / 2 a_dec of the speed
      // profile; in a pile the resistance shortens it, on the floor it does not.
      const double v = std::max(0.0, s.speed);
      const double stopping =
          v / o.decision_rate + v * v / (2 * scoop_options.speed_gains.max_deceleration);
      // One more map cell: the wall's face next to a pile's crest is blurred by pile evidence.
      if (ahead < o.safety_distance + o.planning_margin + stopping + obstacle_resolution) {
        scoop->RequestStop("obstacle_ahead");
        stop_requested = true;
        say("obstacle " + Fixed(ahead, 2) + " m ahead on the map (scoop " + scoop_phase +
            ", sweep reach " + Fixed(sweep.front_length, 2) + " m, stopping " + Fixed(stopping, 2) +
            " m): crowding ends; " +
            SureCellReport(st.map->map(), sure_obstacles[nearest], plant.world()));
      } else {
        // Beside: the whole machine where it will stand once stopped. Entered at an angle to a
        // wall, the body closes on the wall sideways while the corridor ahead stays clear
        // (seed §5.2: the safety distance holds for the area covered during the process).
        perception::MachineFootprint stopped = sweep;
        stopped.hinge_xy += stopping * Eigen::Vector2d(std::cos(s.heading), std::sin(s.heading));
        const double beside =
            FootprintDistanceToCells(stopped, sure_obstacles, obstacle_resolution, &nearest);
        if (beside < o.safety_distance + o.planning_margin) {
          scoop->RequestStop("obstacle_beside");
          stop_requested = true;
          say("obstacle " + Fixed(beside, 2) + " m beside on the map (scoop " + scoop_phase +
              ", stopping " + Fixed(stopping, 2) + " m): crowding ends; " +
              SureCellReport(st.map->map(), sure_obstacles[nearest], plant.world()));
        }
      }
    }
    if (stage == Stage::kNavigate && remaining <= o.handover_distance && !supervisor.stopped()) {
      // Hand over to the scoop cycle with the map as it stands before contact. The material is
      // that of the site's pile nearest the shovel point: the yard's inventory (which material
      // lies in which bin) is known to the station; the map's classes do not tell materials.
      double nearest = INFINITY;
      for (const plant::Pile& p : scenario.piles) {
        const double d = (p.center - goal->pose.xy).norm();
        if (in_site(p.center) && d < nearest) nearest = d, pile = &p;
      }
      if (pile == nullptr) {
        out.failure = "no pile of the scenario lies in " + site.name;
        stage = Stage::kDone;
        return;
      }
      std::string material_name = pile->material;
      for (const plant::FaultSpec& f : faults) {
        if (f.kind == plant::FaultKind::kMaterialMistyped && f.InCycle(index)) {
          say("inventory reports " + f.reported + " for " + pile->material + " (fault, " + f.where +
              ")");
          material_name = f.reported;
        }
      }
      const model::Material* material = machine.FindMaterial(material_name);
      if (material == nullptr) {
        out.failure = "machine '" + machine.name + "' has no material '" + material_name + "'";
        stage = Stage::kDone;
        return;
      }
      rec.material = material->name;
      if (o.trigger == TriggerChoice::kPredicted) {
        trigger = std::make_unique<control::PredictedVolumeTrigger>(out.target_volume);
      } else if (o.trigger == TriggerChoice::kPerception) {
        trigger = std::make_unique<control::PerceptionTrigger>(out.target_volume);
      } else {
        trigger = std::make_unique<control::BoomPressureTrigger>(o.pressure_threshold);
      }
      pre_contact = HeightGridOf(st.map->map());
      sure_obstacles =
          SureObstacleCells(st.map->map(), o.clear_obstacle_margin, o.sure_obstacle_growth_cells);
      obstacle_resolution = st.map->map().resolution();
      scoop =
          std::make_unique<control::ScoopCycle>(machine, *st.setup.functions, pre_contact,
                                                *material, *trigger, &st.predictor, scoop_options);
      if (o.policy == control::ScoopPolicy::kOptimal) {
        const double max_time = o.optimal_max_time;
        scoop->SetPlanner([&st, &machine, material, max_time](
                              const control::ScoopPlanRequest& request, std::string* why) {
          return PlanOptimalScoop(st.optimal_solver, machine, *material, request, max_time, why);
        });
      }
      scoop->Start(machine_io);
      stage = Stage::kScoop;
      say("attack (" + std::string(control::ToString(o.policy)) + ", trigger " +
          ToString(o.trigger) + ") on " + material->name);
    }
  });
  executive.Add("control", 1.0 / o.control_rate, [&](double) {
    // Localisation and actuator faults, then what the machine senses.
    const plant::FaultSpec* jump = active(plant::FaultKind::kLocalisationJump);
    machine_io.SetPoseError(jump ? jump->offset_m : Eigen::Vector2d::Zero(),
                            jump ? jump->heading_rad : 0.0);
    const plant::FaultSpec* stuck = active(plant::FaultKind::kStuckValve);
    machine_io.SetStuckValve(stuck ? machine.ActuatorOfJoint(stuck->joint == "boom" ? 0 : 1) : -1);
    // Arm IMU faults: a bias growing from the fault's start, or a reading frozen there.
    const plant::FaultSpec* drift = active(plant::FaultKind::kImuBiasDrift);
    const plant::FaultSpec* frozen = active(plant::FaultKind::kImuStuck);
    if (frozen != nullptr) {
      machine_io.SetJointReadingFault(frozen->joint == "boom" ? 0 : 1, 0.0, true);
    } else if (drift != nullptr) {
      machine_io.SetJointReadingFault(drift->joint == "boom" ? 0 : 1,
                                      drift->rate_rad_s * (plant.time() - t0 - drift->start_s),
                                      false);
    } else {
      machine_io.SetJointReadingFault(-1, 0.0, false);
    }
    const plant::FaultSpec* noise = active(plant::FaultKind::kEncoderNoise);
    machine_io.SetAngleNoise(noise != nullptr ? noise->sigma_rad : 0.0,
                             0x9E3779B97F4A7C15ull * static_cast<std::uint64_t>(index + 1));
    if (has_fault(plant::FaultKind::kHydraulicDelayDrift)) {
      const plant::FaultSpec* slow = active(plant::FaultKind::kHydraulicDelayDrift);
      for (std::size_t k = 0; k < machine.hydraulics.actuators.size(); ++k) {
        plant.SetTransportDelay(static_cast<int>(k),
                                machine.hydraulics.actuators[k].valve.transport_delay *
                                    (slow != nullptr ? slow->factor : 1.0));
      }
    }
    const control::Proprioception s = machine_io.Sense();
    if (stage == Stage::kSafeStop) {
      stop_xy_travel = std::max(stop_xy_travel, (plant.state().hinge_xy - stop_xy).norm());
      command.drive = 0, command.brake = 1, command.articulation_rate = 0;
      std::string why;
      machine_io.Command(command, &why);
      if (std::abs(plant.state().speed) < 0.01) stage = Stage::kDone;
      return;
    }
    const std::string pose_jump = supervisor.CheckPose(s.time, s.hinge_xy, s.heading, s.speed);
    if (!pose_jump.empty()) {
      safe_stop(pose_jump);
      return;
    }
    if (stage == Stage::kNavigate || (stage == Stage::kScoop && follower)) {
      const control::SteeringCommand steer =
          follower->Update(s.hinge_xy, s.heading, s.articulation);
      remaining = steer.remaining;
      max_cross_track = std::max(max_cross_track, std::abs(steer.cross_track));
      articulation_rate = steer.articulation_rate;
      target_speed = steer.speed;
    }
    if (stage == Stage::kNavigate) {
      speed_pid.SetTarget(target_speed);
      const control::DriveCommand drive = speed_pid.Update(s.speed, scoop_options.tick);
      command.drive = drive.drive;
      command.brake = drive.brake;
      command.articulation_rate = articulation_rate;
      command.valve[machine.ActuatorOfJoint(0)] =
          boom_pid.Update(scoop_options.attack_pose.boom, s.q_boom, s.qd_boom, scoop_options.tick);
      command.valve[machine.ActuatorOfJoint(1)] = bucket_pid.Update(
          scoop_options.attack_pose.bucket, s.q_bucket, s.qd_bucket, scoop_options.tick);
      std::string why;
      machine_io.Command(command, &why);
    } else if (stage == Stage::kSelect) {
      command.drive = 0, command.brake = 1, command.articulation_rate = 0;
      std::fill(command.valve.begin(), command.valve.end(), 0.0);
      std::string why;
      machine_io.Command(command, &why);
    } else if (stage == Stage::kScoop) {
      // Navigation keeps steering (the path, then straight on along the entry heading) for as
      // long as the scoop cycle drives forward: through approach and crowd, and through the
      // scoop phase, where the drive keeps crowding through the hydraulic delay and then
      // decelerates over a metre or more. Holding the articulation there instead drove an arc:
      // a frame still articulated 18.6° from correcting the approach swung the heading 11° off
      // the planned line in 4 s and took the bucket to 0.38 m from a side wall the selection
      // had planned 0.65 m from (docs/campaigns.md). Levelling, shaking and retreat hold it.
      const std::string phase = scoop->phase_name();
      const bool steering = phase == "approach" || phase == "crowd" || phase == "scoop";
      machine_io.SetSteeringOverride(steering ? articulation_rate : 0.0);
      if (!scoop->Tick(machine_io)) stage = Stage::kDone;
    }
  });

  std::string last_phase;
  while (stage != Stage::kDone) {
    executive.Step();
    if (stage == Stage::kDone) break;
    plant.Advance(1.0 / o.control_rate);
    if (scoop && scoop->phase_name() != last_phase) {
      last_phase = scoop->phase_name();
      // Contact: the crowd begins (a planned scoop goes from contact straight to its scoop).
      if ((last_phase == "crowd" || last_phase == "scoop") && !out.contact.valid) {
        out.contact = SnapshotAtContact(plant, rec);
      }
      if (last_phase != "approach" && last_phase != "done") {
        say(last_phase + " at t = " + Fixed(plant.time() - t0, 2) + " s");
      }
    }
    if (plant.time() - t0 > o.max_cycle_time) {
      out.failure = "cycle not complete within " + Fixed(o.max_cycle_time, 0) + " s";
      break;
    }
  }
  const double nav_time = scoop ? 0.0 : plant.time() - t0;
  out.safe_stops = supervisor.safe_stops();
  out.recoveries = supervisor.recoveries();
  out.stop_travel_m = stop_xy_travel;
  out.refused_frames = supervisor.refused_frames();
  out.speed_at_stop = stop_speed;
  if (scoop) out.scoop = scoop->Finish(machine_io);
  st.cycle_clock = plant.time();

  // The row.
  const control::ScoopResult& r = out.scoop;
  if (out.failure.empty() && scoop && !r.ok) out.failure = r.failure;
  rec.completed = out.failure.empty() && r.ok;
  rec.failure = rec.completed ? "" : out.failure;
  rec.safe_stops = out.safe_stops;
  rec.recoveries = out.recoveries;
  rec.refused_frames = static_cast<int>(out.refused_frames);
  for (const plant::FaultSpec& f : faults) {
    const std::string kind = plant::ToString(f.kind);
    if (f.InCycle(index) && rec.faults.find(kind) == std::string::npos) {
      rec.faults += (rec.faults.empty() ? "" : ",") + kind;
    }
  }
  rec.strategy = scoop ? control::ToString(r.strategy) : "";
  std::string actions;
  for (const std::string& a : r.action_names) actions += (actions.empty() ? "" : ",") + a;
  rec.atomic_actions = actions;
  if (scoop && r.has_features_at_trigger && rec.completed &&
      std::isfinite(r.travel_after_trigger)) {
    results::CrowdingSample& c = rec.crowding;
    c.present = true;
    c.strategy = rec.strategy;
    c.trigger = r.trigger_reason;
    c.material = r.features_at_trigger.material;
    c.speed = r.features_at_trigger.speed;
    c.v1 = r.features_at_trigger.shoveled_volume;
    for (int k = 0; k < 6; ++k) c.heights[k] = r.features_at_trigger.heights[k];
    c.penetration = r.travel_after_trigger;
    c.predicted_penetration = r.predicted_travel_at_trigger;
  }
  rec.trigger_time_s = std::isnan(r.trigger_time) ? NAN : r.trigger_time - t0;
  rec.payload_m3 = machine_io.PayloadVolume();
  rec.fill_rate = rec.payload_m3 / machine.bucket.rated_capacity;
  auto phase = [&](const char* name, bool energy) {
    const control::PhaseRecord* p = r.Phase(name);
    if (p == nullptr) return 0.0;
    return energy ? p->energy / 1e3 : p->duration;
  };
  // Navigation: from the cycle start to the scoop cycle's start (booked to "approach").
  const double to_scoop_time = scoop ? r.start_time - t0 : nav_time;
  for (const bool energy : {false, true}) {
    results::PhaseValues& v = energy ? rec.energy_kj : rec.time_s;
    v.approach = phase("approach", energy) + (energy ? 0.0 : to_scoop_time);
    v.crowd = phase("crowd", energy);
    v.scoop = phase("scoop", energy);
    v.level = phase("level", energy) + phase("shake", energy);
    v.retreat = phase("retreat", energy);
    v.total = energy ? machine_io.Energy() / 1e3 : plant.time() - t0;
  }
  // Energy before the scoop cycle began (navigation): total less the cycle's phases.
  double booked = 0;
  for (const control::PhaseRecord& p : r.phases) booked += p.energy / 1e3;
  rec.energy_kj.approach += std::max(0.0, rec.energy_kj.total - booked);
  if (o.energy_audit) {
    out.energy_audit_by_phase = plant.phase_energy_audit();
    out.energy_audit_trace = plant.energy_audit_trace();
  }
  rec.safety_margin_m = min_clearance;
  rec.safety_violations = violations;
  // Samples: V1, V1+V2, trigger; the tip in the frame of the machine at contact (x ahead, z up).
  const Eigen::Vector2d frame_origin =
      r.tip_path.empty() ? start.hinge_xy : r.tip_path.front().head<2>();
  const double frame_heading = goal ? goal->pose.entry_heading : start.heading;
  const Eigen::Vector2d ahead(std::cos(frame_heading), std::sin(frame_heading));
  for (const control::ScoopSample& s : r.samples) {
    results::CycleSample cs;
    cs.t = s.time - t0;
    cs.v1 = s.v1;
    cs.v1v2 = s.v1_plus_v2;
    cs.triggered = s.triggered;
    cs.actual_tip_x = (s.tip.head<2>() - frame_origin).dot(ahead);
    cs.actual_tip_z = s.tip.z();
    rec.samples.push_back(cs);
  }
  for (std::size_t k = 0; k < r.predicted_tip_path.size(); ++k) {
    results::CycleSample cs;
    cs.t = r.trigger_time - t0 + 0.02 * static_cast<double>(k);
    cs.triggered = true;
    cs.predicted_tip_x = (r.predicted_tip_path[k].head<2>() - frame_origin).dot(ahead);
    cs.predicted_tip_z = r.predicted_tip_path[k].z();
    rec.samples.push_back(cs);
  }

  // Figures.
  if (!figures_dir.empty() && o.figures) {
    const std::string n = std::to_string(index);  // the database's cycle index
    const std::filesystem::path map_png = figures_dir / ("map_cycle_" + n + ".png");
    perception::WriteSemanticMapPng(st.map->map(), last_piles, map_png.string(), 2);
    out.figures.push_back(map_png);
    out.figure_titles.push_back("Cycle " + n + ": semantic elevation map layers (Fig. 5)");
    if (goal) {
      const std::filesystem::path cand_png = figures_dir / ("candidates_cycle_" + n + ".png");
      planning::WriteCandidatePng(
          st.map->map(), goal_selection,
          o.selection == SelectionMethod::kChen2024 ? &goal_baseline : nullptr, goal_from,
          st.loader, cand_png.string());
      out.figures.push_back(cand_png);
      out.figure_titles.push_back("Cycle " + n + ": scored shovel points (Fig. 19)");
    }
    if (scoop) {
      const std::filesystem::path vol_png = figures_dir / ("volume_cycle_" + n + ".png");
      results::WriteVolumePlotPng(rec, out.target_volume, vol_png);
      out.figures.push_back(vol_png);
      out.figure_titles.push_back("Cycle " + n + ": V1 and V1+V2 against time, trigger");
      const std::filesystem::path tip_png = figures_dir / ("tip_path_cycle_" + n + ".png");
      results::WriteTipPathPlotPng(rec, tip_png);
      out.figures.push_back(tip_png);
      out.figure_titles.push_back("Cycle " + n + ": predicted (at the trigger) and actual tip");
    }
  }
  if (out.no_shovel_point) {
    say("skipped " + site.name + ": " + out.failure);
    return out;
  }
  if (scoop && !r.payload_at_actions.empty()) {
    std::string volumes;
    for (double v : r.payload_at_actions) volumes += (volumes.empty() ? "" : ", ") + Fixed(v, 2);
    say("bucket volume before the first atomic action and after each: " + volumes + " m^3");
  }
  if (scoop && r.drive_eased_for_boom) {
    say("the drive eased: the boom stalled lifting against the pile");
  }
  say(std::string(rec.completed ? "done" : "NOT completed: " + out.failure) + " — " + site.name +
      ", " + rec.material + ", " + rec.strategy + " (" + rec.atomic_actions + "), fill " +
      Fixed(100 * rec.fill_rate, 1) + " %, trigger " + Fixed(r.trigger_after_contact, 2) +
      " s after contact, cycle " + Fixed(rec.time_s.total, 1) + " s, " +
      Fixed(rec.energy_kj.total, 0) + " kJ, clearance " + Fixed(min_clearance, 2) +
      " m, path error " + Fixed(max_cross_track, 2) + " m, drove in " + Fixed(scoop_advance, 2) +
      " m past the planned contact" +
      (scoop && std::isfinite(r.predicted_travel_at_trigger) &&
               std::isfinite(r.travel_after_trigger)
           ? ", predicted travel " + Fixed(r.predicted_travel_at_trigger, 2) + " m, actual " +
                 Fixed(r.travel_after_trigger, 2) + " m"
           : "") +
      "; map " + std::to_string(perception_calls) + "× (" + Fixed(perception_seconds, 1) +
      " s), selection " + std::to_string(selections) + "× (" + Fixed(selection_seconds, 1) + " s)" +
      (out.safe_stops + out.refused_frames > 0 || out.blind_sector || out.masked_fraction > 0
           ? "; supervisor: " + std::to_string(out.safe_stops) + " stop(s), " +
                 std::to_string(out.recoveries) + " recover(ies), " +
                 std::to_string(out.refused_frames) + " late frame(s) refused" +
                 (out.blind_sector ? ", a LiDAR blind sector" : "") +
                 (out.masked_fraction > 0
                      ? ", up to " + Fixed(100 * out.masked_fraction, 0) + " % of the image masked"
                      : "")
           : ""));
  return out;
}

int RunShovelCommand(const ShovelRunOptions& options, const std::filesystem::path& out_dir,
                     std::ostream& out, std::ostream& err) {
  std::unique_ptr<ShovelJob> job;
  try {
    job = std::make_unique<ShovelJob>(options);
  } catch (const std::exception& e) {
    err << "autoshovel run: " << e.what() << "\n";
    return 2;
  }
  const std::unique_ptr<results::RunFolder> folder =
      results::RunFolder::OpenWithConfig(out_dir, job->ConfigYaml(), err, "autoshovel run");
  if (!folder) return 2;
  results::RunLog& log = folder->log();
  results::ResultsDb db(folder->DatabasePath());
  results::RunInfo info;
  info.run_id = folder->name();
  info.scenario = job->scenario_name();
  info.machine = job->machine_name();
  info.seed = options.seed;
  info.cycles_planned = options.cycles;
  db.BeginRun(info);
  out << "autoshovel run: " << options.cycles << " cycle(s) of " << job->machine_name() << " in "
      << job->scenario_name() << " -> " << folder->dir().string() << "\n";
  log.Info("run " + info.run_id + ": " + std::to_string(options.cycles) + " cycles, seed " +
           std::to_string(options.seed));
  if (const std::string mismatch = job->PredictorMismatch(); !mismatch.empty()) {
    err << "autoshovel run: warning: " << mismatch << "\n";
    log.Warning(mismatch);
  }
  if (const std::string mismatch = job->PredictorMachineMismatch(); !mismatch.empty()) {
    err << "autoshovel run: warning: " << mismatch << "\n";
    log.Warning(mismatch);
  }

  std::vector<results::ReportFigure> figures;
  int incomplete = 0;
  const auto w0 = std::chrono::steady_clock::now();
  for (int i = 0; i < options.cycles; ++i) {
    std::ostringstream progress;
    CycleOutcome cycle;
    try {
      cycle = job->RunCycle(i, folder->dir() / "figures", &progress);
    } catch (const std::exception& e) {
      err << "autoshovel run: cycle " << i + 1 << ": " << e.what() << "\n";
      log.Error("cycle " + std::to_string(i + 1) + ": " + e.what());
      return 2;
    }
    std::istringstream lines(progress.str());
    for (std::string line; std::getline(lines, line);) log.Info(line);
    db.WriteCycle(info.run_id, cycle.record);
    if (!cycle.record.completed) ++incomplete;
    for (std::size_t k = 0; k < cycle.figures.size(); ++k) {
      figures.push_back(
          {cycle.figure_titles[k], std::filesystem::relative(cycle.figures[k], folder->dir()), ""});
    }
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
    const double eta = elapsed / (i + 1) * (options.cycles - i - 1);
    const results::CycleRecord& rec = cycle.record;
    char line[400];
    std::snprintf(line, sizeof line,
                  "[%d/%d] %-6s %-8s %-12s %-14s fill %5.1f %%  cycle %5.1f s  %6.0f kJ  "
                  "clearance %.2f m  %s  (%.0f s elapsed, ETA %.0f s)\n",
                  i + 1, options.cycles, rec.bin.c_str(), rec.completed ? "ok" : "FAILED",
                  rec.material.c_str(), rec.strategy.c_str(), 100 * rec.fill_rate, rec.time_s.total,
                  rec.energy_kj.total, rec.safety_margin_m, cycle.failure.c_str(), elapsed, eta);
    out << line << std::flush;
  }
  const std::vector<results::CycleRecord> cycles = db.Cycles(info.run_id, false);
  const std::filesystem::path fill_png = folder->FigurePath("fill_rate.png");
  results::WriteFillRatePlotPng(cycles, fill_png);
  figures.insert(figures.begin(), {"Fill rate per cycle", "figures/fill_rate.png", ""});
  // The penetration predictor in the closed loop, when some cycle logged its travel.
  if (results::WriteTravelPredictionPlotPng(results::RunCrowdingSamples(db, info.run_id),
                                            folder->FigurePath("travel_prediction.png"))) {
    figures.insert(figures.begin() + 1,
                   {results::kTravelPredictionTitle, "figures/travel_prediction.png", ""});
  }
  results::WriteReportHtml(db, info.run_id, figures, folder->ReportPath());
  const results::RunSummary summary = results::Summarize(cycles);
  char line[300];
  std::snprintf(line, sizeof line,
                "%d/%d cycles completed, mean fill %.1f %%, min clearance %.2f m, %d safety "
                "violation(s)\nreport: %s\n",
                summary.cycles_completed, summary.cycles, 100 * summary.mean_fill_rate,
                summary.min_safety_margin_m, summary.safety_violations,
                folder->ReportPath().string().c_str());
  out << line;
  log.Info(line);
  return incomplete == 0 ? 0 : 1;
}

}  // namespace autoshovel::app
