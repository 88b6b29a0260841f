// `autoshovel run`: the main job (wheel-loader seed §4–§6, issue 6). Closed-loop shoveling cycles
// in a simulated yard, each: perceive (semantic elevation map, Eq. 8–11) → select a shovel point
// (Algorithm 2) → drive the planned path → attack, crowd, trigger on V1 + V2 (Eq. 19, SVR) →
// scoop (Algorithm 3) → level, shake, retreat. A multi-rate executive steps everything on the
// simulated clock: 100 Hz control, 20 Hz state machines, 7 Hz map update and shovel point
// selection (executive.h).
//
// A cycle begins `approach_distance` out of a bin's open front, facing in, with an empty bucket
// (for piles in the open yard: at the scenario's start pose); cycles go round the bins that hold
// piles. What happens between a retreat and the next
// approach (haul to the hopper, dump) is not simulated: the load is booked and the next cycle
// starts empty at the next bin. The yard persists across cycles: piles are as the earlier cycles
// left them, and the map keeps what it has seen (the loader's own map, updated at 7 Hz).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "runtime/app/run_profile.h"
#include "runtime/app/safety_supervisor.h"
#include "runtime/control/scoop_cycle.h"
#include "runtime/plant/energy_audit.h"
#include "runtime/plant/fault_spec.h"
#include "runtime/results/results_db.h"

namespace autoshovel::app {

enum class TriggerChoice { kPredicted, kPerception, kPressure };
const char* ToString(TriggerChoice trigger);
enum class SelectionMethod { kOurs, kChen2024 };
const char* ToString(SelectionMethod method);

struct ShovelRunOptions {
  std::string scenario = "mixing_station";  ///< name under <models_dir>/scenarios, or a path
  std::string models_dir;
  std::string machine;  ///< name or path of a wheel-loader description; empty: the scenario's
  int cycles = 3;
  std::uint64_t seed = 1;
  /// Bins to shovel from, in turn; empty: every bin that holds a pile, in the scenario's order,
  /// then the open yard when piles lie outside bins.
  std::vector<std::string> bins;
  bool truth_labels = false;  ///< simulator labels instead of the segmentation network
  std::string segmenter;      ///< ONNX network; empty: models/segmentation/yard_segmenter.onnx
  /// perception::FusionOptions::segmentation_scale: the network at this fraction of the
  /// camera's resolution (1: full).
  double segmentation_scale = 1.0;
  /// SVR model prefix; empty: prediction::MainJobPredictor (models/prediction/
  /// penetration_svr_fast, trained for the scoop profile below).
  std::string predictor;
  control::ScoopPolicy policy = control::ScoopPolicy::kAutoSelection;
  TriggerChoice trigger = TriggerChoice::kPredicted;
  double pressure_threshold = 150e5;  ///< boom cylinder pressure of the pressure trigger [Pa]
  int stairway_steps = 3;             ///< N of "Stairway #N"
  /// The scoop profile. The main job attacks at 1.5 m/s and keeps pushing while the arm curls,
  /// its speed reference falling at 0.6 m/s² once the scoop moves the arm. The machine then
  /// carries enough way into the pile that V1 + V2 reaches V_t within 0.05–0.2 s of contact
  /// (seed Table 5: 0.32–0.41 s), where the braking scoop of control::ScoopCycleOptions
  /// (1 m/s, 1 m/s²) waits 2.2–7.6 s, crowding at full traction all the while; docs/results.md
  /// gives both, and the cost: a few percent more energy per cycle. The predictor must be
  /// trained for the profile it drives (train_predictor --min-speed/--max-speed
  /// --scoop-deceleration; identification/predictor/README.md).
  /// Fall of the drive's speed reference once the scoop moves the arm
  /// (control::ScoopCycleOptions::scoop_deceleration) [m/s²].
  double scoop_deceleration = 0.6;
  /// control::ScoopPolicy::kOptimal: the time bound of the optimal-control scoop planned at
  /// contact, contact to the end of the scooping motion (runtime/optimal/scoop_ocp.h) [s].
  double optimal_max_time = 6.0;
  /// Approach and crowding speed (control::ScoopCycleOptions::attack_speed) [m/s].
  double attack_speed = 1.5;
  /// V_t as a fraction of the bucket's rated capacity (control::ScoopCycleOptions::target_fill):
  /// the trigger fires when κ·(V1 + V2) reaches it and the adaptive Stairway stops there [-].
  double target_fill = 1.0;
  /// control::ScoopCycleOptions::attitude_feed_forward: the exit lift opens the tilt valve as
  /// the boom's demand will move the boom (false: the bucket PID alone; the attitude held is
  /// the same either way).
  bool attitude_feed_forward = true;
  SelectionMethod selection = SelectionMethod::kOurs;
  double approach_distance = 12.0;  ///< cycle start, out of the bin's open front [m]
  /// The safety rule every cycle is held to and checked against (ground truth, 20 Hz): the
  /// machine's footprint (body and bucket plus 0.3 m on every side, 2.5 m of counterweight
  /// behind the rear axle: perception/machine_footprint.h) never comes closer than this to an
  /// obstacle, so the body itself keeps 0.8 m by default [m].
  double safety_distance = 0.5;
  /// The crowd look-ahead stops the scoop this much before the safety distance: the map's
  /// 0.3 m cells and a frame's latency [m].
  double planning_margin = 0.15;
  /// Faults injected on top of the scenario's own (plant/fault_spec.h), and the supervisor
  /// that answers them.
  std::vector<plant::FaultSpec> faults;
  SupervisorConfig supervisor;
  /// While driving to a shovel point, the machine holds a stop for obstacle cells in the
  /// corridor ahead whose (steep) obstacle evidence reaches this and beats their pile evidence
  /// by `path_obstacle_margin` (a person who stepped in: docs/faults.md) [-].
  double path_obstacle_confidence = 0.5;
  double path_obstacle_margin = 0.3;
  double path_obstacle_height = 0.5;  ///< ... standing this high above the ground plane [m]
  /// A hold for the watchdog or an obstacle on the path ends once its cause has been gone
  /// this long [s].
  double resume_after = 1.0;
  /// ... and, for an obstacle on the path, once it is this much farther than the distance it
  /// stopped for [m].
  double resume_clearance = 1.0;
  /// Our selection only takes candidates planned with at least safety_distance + this much
  /// clearance. The planned clearance is already conservative: half a map cell and half the
  /// outline sampling are left out (0.2 m, shovel_point_selection.h) and obstacle cells cover
  /// more than the obstacle. That has covered the path follower's error (each cycle's done line
  /// logs it: 0.03–0.31 m): on pile_behind_loader a path planned 0.52 m clear, followed with
  /// 0.31 m of error, kept 0.70 m in truth. A margin of 0.15 m there left no candidate [m].
  double selection_margin = 0.0;
  /// How far the front axle drives on past the planned contact while scooping [m], for the
  /// selection's clearance over the whole scoop (Eq. 14's A). The main job logs the measured
  /// value per cycle ("drove in … m past the planned contact"): 1.5–3.2 m on the mixing station.
  double scoop_drive_in = 3.0;
  double d_res = 1.0;  ///< Eq. (14)'s safety distance: clearance below it lowers s_s [m]
  /// The crowd look-ahead stops for map obstacle cells whose obstacle confidence exceeds their
  /// pile confidence by this much [-].
  double clear_obstacle_margin = 0.5;
  /// ... plus the confident obstacle cells within this many cells of those (crowd_lookahead.h).
  /// 1, measured (docs/main_job.md): with the old Eq. (5) projection 0 let the footprint come
  /// 0.33 m from the wall on pile_against_wall (seeds 2, 3); since the rows rule 0, 1 and 2 are
  /// equally safe in the yards, and 1 keeps a cell of margin for a map a frame late [cells].
  int sure_obstacle_growth_cells = 1;
  /// Eq. (18) weights from this YAML file (`autoshovel train weights`); empty: Table 1's.
  std::string shovel_weights;
  /// Vary the scenario's piles as a restocked yard (plant::VaryPiles, seeded by `seed`): each
  /// pile's height scaled by up to this fraction down; 0: the scenario as written [-].
  double yard_variation = 0;
  double curvature_reserve = 0.9;  ///< paths are planned at most at this fraction of κmax
  double handover_distance = 2.0;  ///< path left when the scoop cycle takes over [m]
  double max_cycle_time = 120.0;   ///< a cycle running longer is aborted [s]
  double map_rate = 7.0;           ///< map update and selection [Hz]
  double decision_rate = 20.0;     ///< navigation state machine and safety check [Hz]
  double control_rate = 100.0;     ///< [Hz]
  bool figures = true;             ///< per-cycle PNGs for the report
  /// Integrate the plant's energy audit (plant/energy_audit.h) and return it with each cycle
  /// (CycleOutcome::energy_audit_*). It never changes the run; it costs time.
  bool energy_audit = false;
  /// Record what the sensors delivered at every map update into this new folder
  /// (docs/recording_format.md), for `autoshovel replay`; empty: no recording.
  std::string record_dir;
  /// Print (and write profile.csv) where the run's wall time went: per executive task and
  /// component (docs/performance.md).
  bool profile = false;
};

/// What one cycle did (one row of the results database, plus what the figures need).
/// The machine and the pile when the bucket touched it (the crowd phase began): the start of
/// an optimal scoop on the same pile (runtime/optimal, `compare table5`).
struct ContactSnapshot {
  bool valid = false;
  double speed = 0;           ///< [m/s]
  std::array<double, 2> q{};  ///< boom, bucket [rad]
  double payload_volume = 0;  ///< already in the bucket [m³]
  std::string material;
  /// The terrain along the heading from the hinge, every `profile_spacing` from
  /// `profile_start` [m], heights above the ground under the hinge [m].
  double profile_start = 0, profile_spacing = 0.05;
  std::vector<double> profile_heights;
};

struct CycleOutcome {
  results::CycleRecord record;
  RunProfile profile;  ///< wall time per executive task and component
  ContactSnapshot contact;
  control::ScoopResult scoop;
  std::string failure;           ///< empty when completed
  bool no_shovel_point = false;  ///< failed before moving: no feasible candidate at the site
  double target_volume = 0;
  std::vector<std::filesystem::path> figures;  ///< written for this cycle
  std::vector<std::string> figure_titles;
  // The safety supervisor's answers to faults (safety_supervisor.h).
  int safe_stops = 0;          ///< stops it held (watchdog, obstacle on the path, abandons)
  int recoveries = 0;          ///< of those, the ones it drove on from
  double stop_travel_m = 0;    ///< farthest the hinge moved after a stop began [m]
  double speed_at_stop = 0;    ///< speed when the last stop began [m/s]
  long refused_frames = 0;     ///< late or out-of-order sensor frames not used
  double masked_fraction = 0;  ///< most of the camera image masked for lens dirt [-]
  bool blind_sector = false;   ///< a LiDAR was found blind in some sector
  /// With ShovelRunOptions::energy_audit: where the cycle's energy went, per plant phase
  /// ("travel" before the scoop cycle, then the scoop cycle's phases), and after every tick.
  std::map<std::string, plant::EnergyAudit> energy_audit_by_phase;
  std::vector<plant::EnergyAuditSample> energy_audit_trace;
};

/// The yard, the machine, the map and the models of one run; cycles are run one after another.
class ShovelJob {
 public:
  /// Loads everything; throws core::InputError / std::runtime_error / std::invalid_argument
  /// naming the file or option at fault.
  explicit ShovelJob(const ShovelRunOptions& options);
  ~ShovelJob();

  /// Runs cycle `index` at the next site in turn (sites()), skipping sites where no shovel point
  /// is feasible. `figures_dir`: where its PNGs go (empty: none). `progress`: phase changes and
  /// the summary line (may be null).
  CycleOutcome RunCycle(int index, const std::filesystem::path& figures_dir,
                        std::ostream* progress);

  /// Where cycles dig, in turn: bins holding piles, and "yard" for piles outside bins.
  const std::vector<std::string>& sites() const;
  const std::string& scenario_name() const;
  const std::string& machine_name() const;
  const model::MachineDescription& machine() const;
  /// The resolved configuration, as YAML (config.yaml of the run folder).
  std::string ConfigYaml() const;
  /// Empty, or why the predictor does not fit the scoop profile: its training speeds end below
  /// the attack speed (it would extrapolate V2 for a machine it never saw).
  std::string PredictorMismatch() const;
  /// Empty, or why the predictor may not fit this machine: it was trained on another machine
  /// (name or description SHA-256 differs) or its provenance does not say
  /// (prediction::ProvenanceMismatch, runtime/prediction/model_provenance.h). Commands driving
  /// the job print it as a warning; it is not an error.
  std::string PredictorMachineMismatch() const;
  /// Writes the recording's tables and manifest (ShovelRunOptions::record_dir); the recording is
  /// complete only after this. Nothing without a recording. Throws core::OutputError.
  void FinishRecording();

 private:
  CycleOutcome RunCycleAt(int index, int site, const std::filesystem::path& figures_dir,
                          std::ostream* progress);
  struct State;
  std::unique_ptr<State> state_;
};

/// `autoshovel run`: a run folder (config.yaml, results.sqlite, log.txt, figures/, report.html)
/// under `out_dir` (empty: runs/<UTC timestamp>). Returns 0 when every cycle completed, 1 when
/// some did not, 2 on bad input.
int RunShovelCommand(const ShovelRunOptions& options, const std::filesystem::path& out_dir,
                     std::ostream& out, std::ostream& err);

}  // namespace autoshovel::app
