// The script parameters of the excavator seed §4.4, computed before every loading pass from the
// truck's location, the dig point and the dump point, and the loading script built from them
// (Fig. 14, one rule list per joint). Our scripts, the truck on the side of larger swing angles
// ("past X" means beyond X in the direction of the motion; the other side mirrors them):
//
//   swing   1) digging finished: hold ψ_start
//           2) boom past φ_swing:                        swing to the truck, ψ_dump
//           3) bucket past q₃_dumped:                    swing to dig, ψ_dig
//           4) swing within ε of ψ_dig:                  stop there, digging may start
//   boom    1) digging finished: raise to the clearance angle φ_clear
//           2) bucket past q₃_dumped:                    hold φ_clear (the swing is leaving)
//           3) swing back past ψ_return:                 lower to dig, φ_dig
//   stick   1) digging finished: hold q₂_start
//           2) swing past ψ_stick:                       move to the spill point, q₂_spill
//           3) bucket past q₃_sweep:                     move to the dump point, q₂_dump
//           4) swing back past ψ_return, bucket past q₃_dumped:  move to dig, q₂_dig
//   bucket  1) digging finished: curl to q₃_carry
//           2) swing past ψ_open and stick at q₂_spill:  open, q₃_open
//           3) swing back past ψ_return, bucket past q₃_dumped:  move to dig, q₃_dig
//
// Fig. 14 gives the boom two rules: raise, then lower to dig once θ₁ is below 60°. Taken in order
// (one active rule per joint), the second would fire as soon as the first is active, the swing
// being still at the dig; the figure means the swing on its way back. The stick's and bucket's
// scripts get that meaning from an earlier rule that needs the bucket opened (θ₄ > −30°, θ₁ > 60°);
// the boom gets the same from rule 2, a hold until the bucket has opened. The stick's and
// bucket's last rules also name the opened bucket: ψ_return lies close to ψ_dump when nothing
// stands in the way of lowering, and a real swing that stops a hundredth of a radian short of the
// truck is "past ψ_return" before it ever swung back (found on the plant: the bucket closed
// before it had dumped, and the swing, waiting for it to open, never left the truck). Rule
// conditions are written for the actual direction of the swing, so a truck on either side works.
//
// Right-hand sides, by geometry and kinematics (as §4.4 computes its commands):
//   ψ_dig, ψ_dump   azimuths of the dig and dump points (the swing takes the short way round);
//   φ_dig, q₂_dig, q₃_dig  inverse kinematics of the dig point raised by the approach height,
//                   the bucket at the dig attitude (the dig planner takes over from there);
//   q₃_carry/open   the bucket joint's limits less a margin (curled to carry, open to dump);
//   φ_clear, q₂_spill  the bucket pin above the dump point at the lowest height at which every
//                   configuration the pass can put over the truck clears it: boom φ_clear, the
//                   stick anywhere between its dig-end, spill and dump angles, the bucket curled
//                   (carrying) or anywhere between curled and open at the spill and dump stick
//                   angles. "Over the truck" is taken conservatively as any point whose distance
//                   from the swing axis is within the radial band occupied by the truck boxes the
//                   pass sweeps over (grown by the margin), so the test holds at every swing
//                   angle; such points must be `truck_clearance` above the highest of those boxes
//                   (and the soil at the dump point). The stick angles then follow from the
//                   radial distance of the truck (the dump point), as in the seed;
//   q₂_dump         q₂_spill pulled in by the dump sweep (the seed's spill → dump stick step).
// Left-hand sides, from the joint models (§4.4: their rates, accelerations and latencies are what
// lets the joints' motions be coordinated):
//   ψ_stick   where the predicted swing is when the stick, started then, arrives at q₂_spill as
//             the swing arrives at ψ_dump (at once if the stick is the slower);
//   ψ_open    where the swing is one bucket latency before it arrives, so the bucket starts
//             opening as the swing arrives;
//   q₃_dumped the bucket angle one swing latency of bucket travel short of open, so that the
//             swing starts back as the bucket finishes opening;
//   q₃_sweep  halfway between curled and open;
//   φ_swing   the lowest boom angle at which the swing may start so that the predicted pass
//             (script and joint models together, script_rollout.h) keeps every underside point
//             `truck_clearance` from the truck boxes in 3-D (LinkageClearance, plus its 3.5 cm
//             sampling allowance): found by bisection, so that swinging and raising
//             overlap without risk (§4.4). With overlap off it is φ_clear less ε (full raise
//             first);
//   ψ_return  the swing angle nearest the truck, on the way back, at which lowering may start so
//             that the predicted return still clears the truck (and the ground by
//             `ground_clearance` when a ground height is given): bisection as well.
// A threshold is only looked at every 0.1 s, so a machine slightly ahead of its model may cross
// it one evaluation earlier than predicted. The two bisected thresholds are therefore moved, after
// the bisection, by one period of travel of the joint they watch (boom at its full rate; swing at
// the return's peak rate) in the safe direction: then no such early crossing can start the swing
// or the lowering before the verified threshold would have.
// Every rollout is the same prediction the look-ahead makes (§4.5).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <vector>

#include "runtime/control/excavator/excavator_joints.h"
#include "runtime/control/excavator/joint_model.h"
#include "runtime/control/excavator/linkage_envelope.h"
#include "runtime/control/excavator/loading_script.h"
#include "runtime/control/excavator/obstacle_box.h"

namespace autoshovel::control {

/// Where a pass goes, in the excavator's base frame.
struct LoadingGoal {
  Eigen::Vector3d p_base_dig = Eigen::Vector3d::Zero();   ///< next dig's start, tip on the surface
  Eigen::Vector3d p_base_dump = Eigen::Vector3d::Zero();  ///< dump point (z: soil surface there)
  std::vector<ObstacleBox> truck;                         ///< truck body, cab… (§4.1)
  /// Ground height near the dig [m]; NaN: not checked. When given, the return must keep the
  /// underside `ground_clearance` above it.
  double ground_height = std::numeric_limits<double>::quiet_NaN();
};

struct ScriptSettings {
  double truck_clearance = 0.3;       ///< linkage to truck, everywhere in 3-D [m]
  double ground_clearance = 0.1;      ///< underside above `ground_height` on the return [m]
  double dig_approach_height = 0.5;   ///< the pass ends with the tip this far above the dig [m]
  double dig_attitude = -1.4;         ///< φ_bucket at the dig start (tip steeply down) [rad]
  double bucket_carry_margin = 0.17;  ///< curled: bucket joint minimum + this [rad]
  double bucket_open_margin = 0.17;   ///< open: bucket joint maximum − this [rad]
  double stick_dump_sweep = 0.17;     ///< stick pulled in while the bucket opens [rad]
  double arrival_tolerance = 0.035;   ///< ε of "θ = value" and of the pass's end [rad]
  double settle_velocity = 0.035;     ///< joints slower than this at the pass's end [rad/s]
  bool overlap_swing_and_raise = true;
  double prediction_step = 0.02;  ///< integration step of the predictions [s]
  double max_pass_time = 60;      ///< a prediction longer than this fails [s]
};

/// Throws std::invalid_argument naming the field.
void Validate(const ScriptSettings& settings);

struct ScriptParameters {
  double direction = 1;  ///< +1: the dump at a larger swing angle than the dig, −1 smaller
  // Right-hand sides [rad].
  double swing_start = 0, swing_dump = 0, swing_dig = 0;
  double boom_start = 0, boom_clear = 0, boom_dig = 0;  ///< boom_start: where digging left it
  double stick_start = 0, stick_spill = 0, stick_dump = 0, stick_dig = 0;
  double bucket_carry = 0, bucket_open = 0, bucket_dig = 0;
  // Left-hand sides [rad].
  double boom_swing_start = 0;   ///< φ_swing
  double swing_stick_out = 0;    ///< ψ_stick
  double swing_bucket_open = 0;  ///< ψ_open
  double bucket_sweep = 0;       ///< q₃_sweep
  double bucket_dumped = 0;      ///< q₃_dumped
  double swing_return = 0;       ///< ψ_return
  /// Where the boom starts lowering to carry when the dig left it above φ_clear; NaN when the
  /// boom rises out of the dig (the usual case, Fig. 14's script).
  double swing_boom_lower = std::numeric_limits<double>::quiet_NaN();
  // Geometry and prediction of the pass with these parameters.
  double dump_pin_height = 0;      ///< bucket pin above the ground at the spill point [m]
  double clearance_height = 0;     ///< what the underside must clear over the truck band [m]
  double predicted_pass_time = 0;  ///< until every joint has settled at the dig [s]
  double predicted_min_truck_clearance = 0;  ///< [m]
  double predicted_min_return_height = 0;    ///< above ground_height (NaN when not given) [m]
};

/// What a predicted pass shows (PredictPass).
struct PassPrediction {
  bool finished = false;
  double duration = 0;  ///< until LoadingScript::Finished, or how far it got [s]
  double min_truck_clearance = std::numeric_limits<double>::infinity();  ///< [m]
  /// Lowest underside point above the ground height on the way back [m] (NaN: not checked).
  double min_return_height = std::numeric_limits<double>::quiet_NaN();
  double swing_start_time = -1;  ///< when the swing rule 2 became active [s]
  double boom_at_swing_start = 0;
};

/// Parameters for the pass starting at `dig_end` (the state when digging finished). Throws
/// std::invalid_argument with the reason when an input is not finite, the dig or dump point is
/// out of reach, the truck cannot be cleared within the joint limits, or no prediction completes.
ScriptParameters ComputeScriptParameters(const LinkageEnvelope& envelope,
                                         const ExcavatorJointModels& models,
                                         const ExcavatorState& dig_end, const LoadingGoal& goal,
                                         const ScriptSettings& settings = {});

/// The Fig. 14 scripts for `params` (see the table above).
LoadingScript BuildLoadingScript(const ScriptParameters& params, const ScriptSettings& settings);

/// Runs `script` with the joint models from `start` until it finishes or `settings.max_pass_time`,
/// tracking the truck clearance (LinkageClearance, accurate to about 4 cm) and the return's
/// height when `ground_height` is finite. Ends early once the clearance drops below
/// `abandon_below` [m].
PassPrediction PredictPass(const LoadingScript& script, const ExcavatorJointModels& models,
                           const ExcavatorState& start, const LinkageEnvelope& envelope,
                           const std::vector<ObstacleBox>& truck, double ground_height,
                           const ScriptSettings& settings,
                           double abandon_below = -std::numeric_limits<double>::infinity());

}  // namespace autoshovel::control
