// The main job: closed-loop shoveling cycles in a simulated yard (shovel_run.h).
#include "runtime/app/shovel_run.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "runtime/app/shovel_job/shovel_cycle.h"
#include "runtime/core/file_output.h"
#include "runtime/core/strings.h"
#include "runtime/optimal/warm_scoop_solver.h"
#include "runtime/perception/elevation_map.h"
#include "runtime/perception/semantic_map.h"
#include "runtime/planning/shovel_point_selection.h"
#include "runtime/planning/shovel_weights_file.h"
#include "runtime/plant/plant.h"
#include "runtime/plant/poses.h"
#include "runtime/plant/scenario.h"
#include "runtime/plant/scenario_builder.h"
#include "runtime/prediction/model_provenance.h"
#include "runtime/prediction/penetration_predictor.h"
#include "runtime/prediction/shipped_models.h"
#include "runtime/recording/recording_writer.h"
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
  std::unique_ptr<recording::RecordingWriter> recorder;  ///< ShovelRunOptions::record_dir
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
  if (!options.record_dir.empty()) {
    recording::Manifest manifest;
    manifest.source = "autoshovel run " + scenario.name + " --seed " +
                      std::to_string(options.seed) + " (simulated)";
    manifest.map_resolution = map_config.resolution;
    manifest.map_length = map_config.length;
    manifest.map_center = g.origin + 0.5 * size;
    st.recorder = std::make_unique<recording::RecordingWriter>(
        options.record_dir, machine.source_file, std::move(manifest));
    st.recorder->SetPerception(options.truth_labels, options.segmentation_scale);
  }
}

void ShovelJob::FinishRecording() {
  if (state_->recorder != nullptr) state_->recorder->Close();
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

CycleOutcome ShovelJob::RunCycleAt(int index, int site_index,
                                   const std::filesystem::path& figures_dir,
                                   std::ostream* progress) {
  State& st = *state_;
  CycleResources resources{.options = st.options,
                           .scenario = st.setup.scenario,
                           .machine = st.setup.machine,
                           .functions = *st.setup.functions,
                           .predictor = st.predictor,
                           .loader = st.loader,
                           .selection = st.selection,
                           .faults = st.faults,
                           .segmenter = st.segmenter,
                           .scene = *st.scene,
                           .map = *st.map,
                           .semantic = *st.semantic,
                           .rng = st.rng,
                           .lens_dirt = st.lens_dirt,
                           .optimal_solver = st.optimal_solver,
                           .recorder = st.recorder.get()};
  return RunShovelCycle(resources, st.sites[site_index], index, st.cycle_clock, &st.cycle_clock,
                        figures_dir, progress);
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
  RunProfile profile;
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
    profile.Merge(cycle.profile);
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
  if (options.profile) {
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
    double simulated = 0;
    for (const results::CycleRecord& rec : db.Cycles(info.run_id, false))
      simulated += rec.time_s.total;
    std::ostringstream table;
    table << "profile: " << core::Fixed(wall, 2) << " s of wall time for "
          << core::Fixed(simulated, 1) << " s simulated (real-time factor "
          << core::Fixed(wall > 0 ? simulated / wall : 0.0, 2) << ")\n"
          << profile.Table(wall);
    out << table.str();
    log.Info(table.str());
    try {
      core::WriteFileAtomically(folder->dir() / "profile.csv", profile.Csv());
    } catch (const std::exception& e) {
      err << "autoshovel run: " << e.what() << "\n";
      return 2;
    }
  }
  if (!options.record_dir.empty()) {
    try {
      job->FinishRecording();
    } catch (const std::exception& e) {
      err << "autoshovel run: " << e.what() << "\n";
      log.Error(e.what());
      return 2;
    }
    out << "recording: " << options.record_dir << " (replay it: autoshovel replay "
        << options.record_dir << ")\n";
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
