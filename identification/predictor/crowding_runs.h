// Plant crowding runs for the penetration predictor (wheel-loader seed §6.1, §7.4.1: the seed
// trains on 991 real loads; we generate them in the simulated yard).
//
// One run: a randomised pile (shape cone / irregular / low, height, material, lateral offset and
// yaw) in front of a loader standing with its bucket flat on the floor, a randomised approach
// speed v0 ∈ [0.5, 1.25] m/s and a randomised trigger volume. The loader accelerates to v0 (a PI
// speed loop on the drive command, saturating at full drive once the pile slows it: the
// crowding phase), keeps the bucket on the floor from first contact on, and at the 20 Hz state
// machine rate computes V1 (Eq. 19) from the pre-contact height map and the tip path. The scoop
// is triggered when V1 reaches the run's trigger volume, when the machine all but stalls
// (< 0.1 m/s) or 8 s after contact. At the trigger the sample is taken (v, V1, material,
// h1..h6 on the current surface); then the "Just in & out" scoop runs: the tilt valve fully
// open until the bucket is racked back, the drive held meanwhile; then drive off, brake on and
// the boom lifted. The target is the machine's forward travel from the trigger until it stops;
// the final payload (plant ground truth) checks the volume prediction.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "generated/machine_functions.h"
#include "runtime/model/description.h"
#include "runtime/prediction/penetration_predictor.h"
#include "runtime/prediction/volume_estimation.h"

namespace autoshovel::predictor {

struct CrowdingRunOptions {
  double tick = 0.01;      ///< plant/control step [s] (100 Hz low-level control)
  int decision_every = 5;  ///< ticks between trigger checks (20 Hz state machine)
  /// v0 range [m/s]: the controller's operating envelope. The scoop cycle attacks at 1 m/s
  /// (`ScoopCycleOptions::attack_speed`) and only slows in the pile, so the shipped model is
  /// trained up to 1.25 m/s. Up to commit ac3d5bc it was 2 m/s: the faster runs glide through
  /// low piles past the 3 m the six heights describe, and they were the whole tail of the error
  /// buckets for speeds the machine never attacks at (identification/predictor/README.md).
  double min_speed = 0.5;
  double max_speed = 1.25;
  double min_trigger_fraction = 0.02;  ///< trigger V1 as a fraction of the rated capacity [-]
  double max_trigger_fraction = 0.4;
  double stall_speed = 0.1;       ///< trigger when slower than this after contact [m/s]
  double max_crowd_time = 8.0;    ///< trigger at the latest this long after contact [s]
  double max_scoop_time = 10.0;   ///< the run ends at the latest this long after the trigger [s]
  double rack_back_margin = 0.1;  ///< curl until the bucket joint is this far below its max [rad]
  double boom_lift = 0.35;        ///< boom joint travel of the lift [rad]
  /// 0 (the shipped model): once the bucket moves the drive is released and the machine runs on
  /// into the pile on its momentum. > 0: the speed reference falls from v0 at this rate [m/s²]
  /// and the drive keeps pushing after it, as the scoop cycle's `scoop_deceleration` does
  /// (crowding while curling, docs/scooping_control.md).
  double scoop_deceleration = 0;
  /// Share of runs whose pile a previous scoop has dug into (a revisit): a bucket-wide cut at
  /// floor level from the toe in along the approach, its face and sides at the angle of
  /// repose. 0 (the shipped model): every pile is fresh. Drawn after every other field of the
  /// spec, so the fresh runs' specs do not change with it.
  double dug_face_fraction = 0;
  double min_dug_depth = 1.0;  ///< range of the cut's length from the toe [m]
  double max_dug_depth = 3.0;
  /// Period of CrowdingRun::travel_after_trigger [s] (a multiple of `tick`).
  double travel_sample_period = 0.05;
  double map_resolution = 0.05;  ///< of the yard grid [m]
  double map_margin = 2.0;       ///< kept around the tip path in the stored map [m]
};

/// The randomised inputs of one run, drawn from its seed.
struct CrowdingRunSpec {
  int index = 0;
  std::uint64_t seed = 0;
  std::string shape;          ///< cone | irregular | low
  std::string material;       ///< material name
  double height = 0;          ///< pile peak [m]
  double approach_speed = 0;  ///< v0 [m/s]
  double trigger_volume = 0;  ///< V1 at which the scoop is triggered [m³]
  double dug_depth = 0;       ///< 0: a fresh pile; > 0: cut this far in from the toe [m]
};

struct CrowdingRun {
  CrowdingRunSpec spec;
  bool ok = false;                           ///< contact made and the scoop completed
  std::string failure;                       ///< why not
  prediction::PenetrationFeatures features;  ///< at the trigger
  double penetration = 0;                    ///< travel from trigger to stop [m] (the target)
  double contact_to_trigger = 0;             ///< travel from first contact to the trigger [m]
  std::string trigger_cause;                 ///< volume (V1 reached the spec's), stall or time_out
  double payload = 0;             ///< bucket volume at the end of the run [m³] (plant truth)
  double payload_at_trigger = 0;  ///< [m³]
  prediction::HeightGrid map;     ///< pre-contact heights around the path (cropped)
  std::vector<Eigen::Vector3d> past_path;  ///< tip path from first contact to the trigger
  prediction::MachineAtTrigger at_trigger;
  prediction::ScoopPlan plan;
  /// Forward travel of the hinge from the trigger [m], sampled every `travel_sample_period`
  /// from the trigger on (first 0): the travel curve's targets (train_predictor --travel-curve).
  std::vector<double> travel_after_trigger;
  double travel_sample_period = 0;  ///< [s]
  double simulated_time = 0;        ///< [s]
};

/// The run's travel `t` seconds after the trigger [m]: linear between samples, the last sample
/// after the end of the run.
double TravelAt(const CrowdingRun& run, double t);

/// Draws the spec of run `index` from `seed` (deterministic).
CrowdingRunSpec DrawSpec(const model::MachineDescription& machine,
                         const CrowdingRunOptions& options, std::uint64_t seed, int index);

/// Runs one crowding run in its own yard (thread-safe: nothing shared is written).
CrowdingRun RunCrowding(const model::MachineDescription& machine,
                        const generated::MachineFunctions& functions,
                        const CrowdingRunOptions& options, const CrowdingRunSpec& spec);

/// Runs `count` runs with indices first..first+count−1 on `threads` std::threads; `progress` (if
/// given) is called from the workers, serialised, after each run.
std::vector<CrowdingRun> RunCrowdingBatch(
    const model::MachineDescription& machine, const generated::MachineFunctions& functions,
    const CrowdingRunOptions& options, std::uint64_t seed, int first, int count, int threads,
    const std::function<void(const CrowdingRun&, int done)>& progress = {});

}  // namespace autoshovel::predictor
