// `autoshovel run truck_loading`: the excavator seed end to end on the simulated 25 t excavator.
// The excavator stands on a bench and digs the face in front of it; a truck waits on the haul
// road 2 m below, on the operator's left (the seed's setting). Each pass:
//   dig       the refined planner's dig (§4.2) executed by the dig motion on the plant;
//   plan      the next dig: coarse region (Fig. 12 order) and the refined planner's search with
//             the plant as forward model; the next dump point: the template planner (§4.3) on
//             the bed's height map;
//   load      the Fig. 14 scripts with parameters computed for this pass (§4.4), evaluated at
//             10 Hz, joint servos at 100 Hz; swing to the truck, dump, swing back to the next
//             dig's approach pose; every 0.1 s the look-ahead (§4.5) predicts the linkage 2.5 s
//             ahead against the elevation map and stops the machine before a collision; it
//             resumes once a 10 s prediction from rest (the rest of the pass) has been clear
//             for `resume_after` seconds.
// The job books per pass: dig, swing (to the bucket opening), dump, return times and energies,
// the volume dug, dumped into the bed, the smallest clearance of the linkage's underside to the
// truck and to any person (ground truth, 20 Hz), and stops.
//
// The truck the scripts keep clear of is the one recognised from the left scanner's first-pass
// scan (truck_scan/: the head pans while the first dig is dug, and on across the truck during
// the first swing), as boxes: the bed's walls from the road to the rim and the cab ahead of it
// up to 0.6 m above the rim. The dump planner's bed map is what the same scanner saw: the first
// pass's scan and one on every swing back, fused (a cell keeps its last seen height; unseen
// cells are the planner's §4.3 business). Where the job is simpler than the seed, said here
// once: the look-ahead's elevation map is taken from the simulated world; the swing-back scan
// runs over the nominal swing (dump to dig at 42°/s), not the plant's profile.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "runtime/app/truck_scan/truck_placement.h"
#include "runtime/planning/dig/dig_action.h"
#include "runtime/planning/dump/bed_height_map.h"
#include "runtime/planning/dump/fill_summary.h"

namespace autoshovel::app {

/// A person walking into the yard during one pass: they appear at `from`, walk in a straight line
/// at constant speed to `to`, stand there for `stay` seconds and walk back to `from`, where they
/// stay. A 0.5 m × 0.5 m × 1.8 m box on the ground, in the world the look-ahead maps.
struct PersonWalk {
  int pass = 0;              ///< the pass (0-based) during whose loading phase they appear
  double start_delay = 1.0;  ///< after the loading phase starts [s]
  Eigen::Vector2d from = Eigen::Vector2d::Zero();         ///< world xy [m]
  Eigen::Vector2d to = Eigen::Vector2d::Zero();           ///< [m]
  double speed = 1.2;                                     ///< walking [m/s]
  double stay = std::numeric_limits<double>::infinity();  ///< at `to` [s]

  /// Where they are `t` seconds after appearing.
  Eigen::Vector2d At(double t) const;
};

/// A dust cloud hanging in the yard for the whole run: a sphere of uniform density that the
/// scanners see (§3); the machine's moving parts pass through it.
struct DustCloud {
  Eigen::Vector3d p_world_center = Eigen::Vector3d::Zero();  ///< [m]
  double radius = 3.0;                                       ///< [m]
  double extinction = 0.25;  ///< α [1/m]; visibility ≈ 3.9/α (0.25/m: ≈ 16 m)
};

/// The loading phase sampled at 20 Hz: where the bucket tip was (ground truth).
struct TraceSample {
  double t = 0;  ///< since the loading phase began [s]
  std::string phase;
  Eigen::Vector3d p_world_tip = Eigen::Vector3d::Zero();
  double ground_below_tip = 0;  ///< terrain height under the tip [m]
  bool stopped = false;         ///< held by the look-ahead
};

struct TruckLoadingOptions {
  std::string scenario = "truck_loading";  ///< name under <models_dir>/scenarios, or a path
  std::string models_dir;
  /// Passes to run; 0: until the bed holds the truck's rated payload (or `max_passes`).
  int passes = 0;
  int max_passes = 14;
  std::uint64_t seed = 1;
  TruckClass truck = TruckClass::kTipper20t;
  double truck_payload = 20000;   ///< rated payload [kg]
  double road_drop = 2.0;         ///< haul road below the bench [m]
  double road_edge_y = 4.0;       ///< the road begins at this world y [m]
  double truck_azimuth_deg = 90;  ///< bed centre seen from the swing axis [deg]
  double truck_radius = 5.9;      ///< bed centre from the swing axis [m]
  int dig_evaluations = 12;       ///< forward-model calls per dig plan
  double resume_after = 1.0;      ///< clear look-ahead before resuming after a stop [s]
  double max_pass_time = 120;     ///< a pass running longer is aborted [s]
  std::optional<PersonWalk> person;
  /// Recognise the truck from the left scanner's first-pass scan (§2, §4.1) and plan the passes
  /// around the recognised body; false: around the true one.
  bool recognise_truck = true;
  /// Dust clouds the scans see; their §3 warning slows the next pass (recognise_truck only).
  std::vector<DustCloud> dust;
  bool figures = true;
  /// Keep the rangefinder's scans and what recognition and the bed map made of them in this
  /// folder (docs/recording_format.md, "Truck loading"), for `autoshovel replay`; empty: none.
  /// The folder is complete after CloseRecording().
  std::string record_dir;
};

/// The first-pass scan's outcome against the truth.
struct TruckRecognitionCheck {
  bool done = false;                         ///< a scan was made (recognise_truck)
  double position_error = 0;                 ///< bed frame origin [m]
  double yaw_error = 0;                      ///< [rad]
  double length_error = 0, width_error = 0;  ///< inside dimensions, recognised − true [m]
  long pulses = 0;
};

struct PassOutcome {
  int index = 0;
  bool completed = false;
  std::string failure;
  planning::DigAction dig;
  double predicted_volume = 0;  ///< the forward model's, for the executed dig [m³]
  double dug_volume = 0;        ///< in the bucket at the end of the dig [m³]
  double dumped_volume = 0;     ///< added to the bed [m³]
  double dumped_mass = 0;       ///< [kg]
  double dig_time = 0, swing_time = 0, dump_time = 0, return_time = 0, total_time = 0;  ///< [s]
  double dig_energy = 0, swing_energy = 0, dump_energy = 0, return_energy = 0;          ///< [J]
  double min_truck_clearance = 0;   ///< linkage underside to the truck's boxes [m]
  double min_person_clearance = 0;  ///< to any person (+inf: none) [m]
  int collisions = 0;               ///< instants the underside was inside a box (must be 0)
  int safety_stops = 0;             ///< look-ahead stops
  int dig_evaluations = 0;          ///< forward-model calls for the next dig
  Eigen::Vector3d p_world_dump = Eigen::Vector3d::Zero();
  int bed_cells_seen = -1;  ///< by the swing back's scan (-1: none)
  /// §3: the scale of every joint's top rate during this pass's load phase, from the dust
  /// warning of the scan before it (1: clear air); `dust_warning`: the warning of this pass's own
  /// swing-back scan, which sets the next pass's scale.
  double speed_scale = 1.0;
  bool dust_warning = false;
  std::vector<TraceSample> trace;  ///< the loading phase
};

/// The yard, the machine and the planners of one run; passes run one after another.
class TruckLoadingJob {
 public:
  /// Builds the yard (road, truck) and plans the first dig. Throws core::InputError /
  /// std::runtime_error / std::invalid_argument naming what is wrong.
  explicit TruckLoadingJob(const TruckLoadingOptions& options);
  ~TruckLoadingJob();

  /// Writes the recording's tables and manifest (TruckLoadingOptions::record_dir). Throws
  /// core::OutputError. Nothing without a recording.
  void CloseRecording();

  /// Runs pass `index`: dig, plan, load. `progress` (may be null) gets one line per phase.
  PassOutcome RunPass(int index, std::ostream* progress);

  /// Material in the bed [kg] and whether it has reached the rated payload.
  double BedMass() const;
  bool TruckFull() const;
  /// The bed's height map: 15 cm cells, heights above the bed floor (the dump planner's input).
  planning::BedHeightMap BedMap() const;
  /// Its summary against the rim.
  planning::FillSummary Fill() const;
  /// PNG of the bed's height map (top view, colour = height above the floor).
  void WriteBedPng(const std::filesystem::path& path) const;
  const TruckPlacement& truck() const;
  const TruckRecognitionCheck& recognition() const;
  double BucketCapacity() const;  ///< rated, heaped [m³]
  const std::string& scenario_name() const;
  const std::string& machine_name() const;
  const std::string& material_name() const;
  std::string ConfigYaml() const;

  /// Whether `scenario` (name or path) is one for this job: its machine is an excavator.
  static bool IsTruckLoadingScenario(const std::string& scenario, const std::string& models_dir);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// The run folder for `autoshovel run truck_loading`: config.yaml, results.sqlite (one row per
/// pass), log.txt, figures/, report.html. Returns 0 when every pass completed without a
/// collision, 1 otherwise, 2 on bad input.
int RunTruckLoadingCommand(const TruckLoadingOptions& options, const std::filesystem::path& out_dir,
                           std::ostream& out, std::ostream& err);

}  // namespace autoshovel::app
