// The simple closed-loop joint models of the excavator seed §4.4: for a desired joint position,
// how soon a joint starts moving (latency), how fast it can go and how hard it can speed up and
// brake, so that the motions of the joints can be coordinated. The script parameters'
// left-hand sides (§4.4) and the look-ahead (§4.5) both predict the machine with them.
//
// One joint, given a position command c issued at time t₀:
//   - nothing happens until t₀ + L (the latency: valve transport delay plus spool lag);
//   - then the joint servo asks for the rate
//       v* = sign(e) · min(|e| / τ, sqrt(2 a |e|)),  e = c − θ,
//     clamped to [−v_down, v_up]: the smaller of a proportional approach with time constant τ
//     (first-order term) and the largest rate from which braking at a still stops at the target
//     (sqrt term). The arm joints accelerate hard (a·τ > v), so they cruise and then close the
//     last v·τ (5°–56°) exponentially; the swing brakes weakly, so it follows the braking
//     parabola nearly to the end;
//   - the actual rate follows v* changing by at most a per second (speeding up and braking).
// A stop (§4.5) acts after the same latency: v* = 0, the joint brakes at a and holds. Arm joints
// stay within their joint limits (rate zeroed at a limit); the swing has none. The seed's "first
// order" is read as the leading effects (rate limit, acceleration, latency), not as a first-order
// linear system: one that never asks the swing to brake harder than it can would need a time
// constant of about 2 s (peak rate over braking) and take many seconds to settle.
#pragma once

#include <array>
#include <limits>
#include <string>

#include "generated/machine_functions.h"
#include "runtime/control/excavator/excavator_joints.h"
#include "runtime/model/description.h"

namespace autoshovel::control {

struct JointModelParams {
  double latency = 0;            ///< L, command to motion [s]
  double max_velocity_up = 0;    ///< v_up, towards larger angles [rad/s]
  double max_velocity_down = 0;  ///< v_down, towards smaller angles (a positive number) [rad/s]
  double max_acceleration = 0;   ///< a, speeding up and braking [rad/s²]
  double time_constant = 0;      ///< τ of the final proportional approach [s]
  double position_min = -std::numeric_limits<double>::infinity();  ///< joint limit [rad]
  double position_max = std::numeric_limits<double>::infinity();   ///< joint limit [rad]
};

/// Throws std::invalid_argument naming `joint_name` and the field when a value is not finite
/// and positive (latency may be 0) or the limits are inverted.
void Validate(const JointModelParams& params, const std::string& joint_name);

using ExcavatorJointModels = std::array<JointModelParams, kNumExcavatorJoints>;

void Validate(const ExcavatorJointModels& models);

/// One joint's position [rad] and rate [rad/s].
struct JointMotion {
  double position = 0;
  double velocity = 0;
};

/// Advances one joint by `dt` [s] under the command that is in effect (the latency is handled by
/// the caller, ExcavatorSimulator): towards `target`, or braking to rest when `stop`.
JointMotion StepJoint(const JointModelParams& params, const JointMotion& motion, double target,
                      bool stop, double dt);

/// Time [s] from a command issued at rest at `from` until the joint is within `tolerance` of `to`
/// and stays there, latency included, integrated with step `dt`. Throws when it never gets there
/// within 60 s.
double TimeToReach(const JointModelParams& params, double from, double to, double tolerance,
                   double dt = 0.01);

/// Position [rad] reached `elapsed` seconds after a command to `to` issued at rest at `from`.
double PositionAfter(const JointModelParams& params, double from, double to, double elapsed,
                     double dt = 0.01);

/// Angle [rad] and time [s] a joint moving at `speed` [rad/s] covers after a stop command
/// (latency, then braking at a): speed·L + speed²/(2a), L + speed/a.
double StoppingDistance(const JointModelParams& params, double speed);
double StoppingTime(const JointModelParams& params, double speed);

/// How the default models were obtained from a description, per joint (for the documentation and
/// for a reader who wants to check the numbers).
struct JointModelDerivation {
  std::string joint;
  double rated_flow = 0;      ///< valve flow at full spool [m³/s]
  double area_up = 0;         ///< area (or displacement) fed when the angle grows [m² or m³/rad]
  double area_down = 0;       ///< fed when it shrinks
  double lever = 0;           ///< dL/dq at the reference pose [m/rad] (1 for the motor)
  double inertia = 0;         ///< about the joint, reference pose, payload included [kg·m²]
  double drive_torque = 0;    ///< at relief pressure on the weaker side [N·m]
  double gravity_torque = 0;  ///< |gravity| at the reference pose [N·m]
  JointModelParams params;
};

struct ExcavatorModelDerivation {
  ExcavatorJointModels models;
  std::array<JointModelDerivation, kNumExcavatorJoints> joints;
  JointVector reference_pose = JointVector::Zero();
  double payload = 0;  ///< [kg]
};

/// The default joint models of an excavator from its description and generated code, at the
/// joint positions `reference_pose` with `payload` [kg] in the bucket (a loaded carry):
///   L      = valve transport delay + spool time constant (dead time plus the spool's lag);
///   v      = rated valve flow / fed area / |dL/dq| (pressure-compensated load sensing, as the
///            plant: a full spool passes its rated flow whatever the load), per direction: a
///            cylinder is fed on its cap side when it extends and on its annulus when it
///            retracts; the swing motor: flow / displacement both ways;
///   a      = the smaller of (relief Δp · weaker area · |dL/dq| − |gravity torque|) / inertia and,
///            for cylinders, v / spool time constant (the flow cannot rise faster than the spool
///            opens); the swing: relief Δp · displacement / inertia, the inertia of the upper
///            structure plus every arm body and the payload at its radius;
///   τ      = 2 L (a proportional loop around a dead time L is well damped for gain·L ≈ 0.5);
///   limits = the description's joint limits (none for the swing).
/// Throws std::invalid_argument when the description is not an excavator with boom, stick,
/// bucket and swing, or a derived value is not positive.
ExcavatorModelDerivation DeriveJointModels(const model::MachineDescription& machine,
                                           const generated::MachineFunctions& functions,
                                           const JointVector& reference_pose, double payload);

/// The reference pose used by default: boom 30°, stick −90°, bucket −120°, swing 0 (a loaded
/// bucket carried high, as in the middle of a loading pass).
JointVector DefaultReferencePose();

}  // namespace autoshovel::control
