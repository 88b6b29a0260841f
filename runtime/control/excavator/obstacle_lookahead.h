// Look-ahead obstacle detection (excavator seed §4.5): predict the linkage over the next 2–3 s
// with the joint models together with a simulation of the loading script itself, evaluated at
// the script's own 10 Hz; place points on the underside of the linkage for every predicted state
// (Fig. 15) and compare each with the elevation-map cell beneath it. A point below its cell's
// height is a predicted collision, reported at once so that the caller stops the machine: every
// joint brakes to rest (ExcavatorCommand::stop).
//
// The horizon is 2.5 s (the seed found 2–3 s), extended whenever a stop issued now would take
// longer than that to bring a joint to rest from the fastest it moves in the prediction (latency
// plus speed over braking): only then does the first report come early enough for the stop to
// end short of what was seen. For the 25 t machine's swing (0.28 s latency, about 0.34 rad/s²
// braking) that is 2.4 s at its peak speed in a 90° pass, so the extension acts only for slower
// braking or faster swings.
//
// The underside is tested at every integration step of the prediction (20 ms by default), not
// only at the 10 Hz script evaluations: a swing at 0.8 rad/s moves the bucket 9 m from the axis
// about 0.7 m per 0.1 s, more than a person's width, but 0.15 m per 20 ms. Unknown cells (NaN or
// outside the map) do not block by default (the seed is silent; the count is reported so that the
// caller can refuse to move into an unseen region); `unknown_blocks` makes them obstacles.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>

#include "runtime/control/excavator/excavator_simulator.h"
#include "runtime/control/excavator/height_grid.h"
#include "runtime/control/excavator/linkage_envelope.h"
#include "runtime/control/excavator/loading_script.h"

namespace autoshovel::control {

struct LookAheadSettings {
  double horizon = 2.5;  ///< prediction time, the seed's 2–3 s (extended, see above) [s]
  double integration_step = 0.02;  ///< joint models' step inside the prediction [s]
  double height_margin = 0.0;      ///< collision when a point is below cell + margin [m]
  bool unknown_blocks = false;     ///< unknown cells count as obstacles
  double stop_time_limit = 10.0;   ///< CheckStop gives up after this long [s]
};

/// Throws std::invalid_argument naming the field.
void Validate(const LookAheadSettings& settings);

enum class LookAheadVerdict { kClear, kCollision, kInvalidState };

struct PredictedCollision {
  double time = 0;                                    ///< from now [s]
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();  ///< the underside point [m]
  LinkageLink link = LinkageLink::kBucket;
  double cell_height = 0;  ///< of the cell under it (NaN: unknown, with unknown_blocks) [m]
  JointVector q = JointVector::Zero();  ///< predicted joint positions then
};

struct LookAheadResult {
  LookAheadVerdict verdict = LookAheadVerdict::kClear;
  std::optional<PredictedCollision> collision;  ///< the first one predicted
  std::string reason;                           ///< for a stop
  int states_checked = 0;
  double horizon = 0;       ///< how far it predicted: the horizon, extended to cover a stop [s]
  long unknown_points = 0;  ///< points over unknown cells (not blocking unless unknown_blocks)
  /// Anything but kClear means: command the stop now.
  bool stop() const { return verdict != LookAheadVerdict::kClear; }
};

class ObstacleLookAhead {
 public:
  /// Copies the envelope. Throws std::invalid_argument on invalid settings.
  explicit ObstacleLookAhead(const LinkageEnvelope& envelope,
                             const LookAheadSettings& settings = {});

  /// Predicts from the `measured` state with the commands in flight held by `commands` (the
  /// controller's mirror of what it sent: an ExcavatorSimulator it commands alongside the
  /// machine), running `script` (its state after this tick's evaluation; nullptr: no script, the
  /// last commands are held) with its first evaluation `next_evaluation` seconds from now.
  /// A non-finite measured state gives kInvalidState (stop), never a prediction.
  LookAheadResult Check(const ExcavatorState& measured, const ExcavatorSimulator& commands,
                        const LoadingScript* script, double next_evaluation, const HeightGrid& map,
                        const Eigen::Isometry3d& T_world_base) const;

  /// The same check for a stop issued now, until every joint is at rest: whether the machine
  /// would come to rest clear of the map (what a stop leaves of the linkage).
  LookAheadResult CheckStop(const ExcavatorState& measured, const ExcavatorSimulator& commands,
                            const HeightGrid& map, const Eigen::Isometry3d& T_world_base) const;

  const LookAheadSettings& settings() const { return settings_; }
  const LinkageEnvelope& envelope() const { return envelope_; }

 private:
  /// Tests one predicted state; true (and fills `result`) on a collision.
  bool Collides(const JointVector& q, double time, const HeightGrid& map,
                const Eigen::Isometry3d& T_world_base, std::vector<EnvelopePoint>& scratch,
                LookAheadResult& result) const;
  /// The prediction's copy of the mirror, at the measured state, or the reason it cannot be.
  std::optional<ExcavatorSimulator> Prepare(const ExcavatorState& measured,
                                            const ExcavatorSimulator& commands,
                                            LookAheadResult& result) const;

  LinkageEnvelope envelope_;
  LookAheadSettings settings_;
};

}  // namespace autoshovel::control
