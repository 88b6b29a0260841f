// The path of one valve command from the controller to the spool reference (docs/simulation.md
// "Valve chain"):
//
//   u (electrical command) → pure delay τ_p + τ_d → pilot lag T_p → opening law → spool lag τ_s
//
// τ_p is the command-to-pilot-pressure delay, τ_d the pilot-to-spool (transport) delay, T_p the
// first-order lag of the pilot (EPPR) pressure; the opening law is the direction's opening curve
// or else the dead zone with the linear law (ApplyDeadZone). A pure delay commutes with a linear
// time-invariant lag, lag(u(t − τ_p))(t − τ_d) = lag(u(t − τ_p − τ_d))(t), so the plant delays the
// command by τ_p + τ_d at once and lags it after: the spool sees exactly what the pilot pressure
// shows τ_d earlier (PilotSignal). The opening law is static, so without a pilot stage (T_p = 0)
// it is applied before the delay, as it always was.
//
// SUNDIALS has no delay-differential solver, and the delay here acts on an input, not on the
// state, so none is needed: every command is stored with the instant it reaches the valve,
// t_effective = t_command + τ_p + τ_d, and the plant integrates each interval between
// consecutive effective instants with the held input constant, re-initialising CVODE exactly at
// each such instant (Plant::Advance). The spool (or pilot) therefore starts to move exactly
// τ_p + τ_d after the command, with no interpolation error and no smoothing of the step.
#pragma once

#include <deque>
#include <limits>
#include <vector>

#include "runtime/model/description.h"

namespace autoshovel::plant {

/// Valve dead zone (spool overlap): commands with |u| ≤ d give no opening; above it the opening
/// grows linearly and reaches full at |u| = 1, so u_eff = sign(u)·(|u| − d)/(1 − d).
double ApplyDeadZone(double duty, double dead_zone);

/// An opening curve at `duty` ≥ 0: 0 up to the first point, piecewise linear between points,
/// the last opening beyond the last point.
double InterpolateOpeningCurve(const std::vector<model::OpeningPoint>& curve, double duty);

/// The valve's opening law: x_ref = +curve_extend(π) for π > 0, −curve_retract(−π) for π < 0,
/// and ApplyDeadZone(π, dead_zone) for a direction without a curve. `pilot` in [−1, 1].
double ValveOpening(const model::Valve& valve, double pilot);

/// Whether the valve has a pilot stage (a lag state in the plant).
inline bool HasPilotStage(const model::Valve& valve) { return valve.pilot_time_constant > 0; }

class DelayedValveCommand {
 public:
  /// Dead zone, then transport delay (the chain without pilot stage and curves).
  DelayedValveCommand(double dead_zone, double transport_delay) {
    valve_.dead_zone = dead_zone;
    valve_.transport_delay = transport_delay;
  }
  /// The valve's chain up to the pilot lag: with a pilot stage the raw command is delayed by
  /// τ_p + τ_d (the plant lags it and applies the opening law); without one the opening law is
  /// applied first, then the delay.
  explicit DelayedValveCommand(const model::Valve& valve) : valve_(valve) {}

  /// A new (validated) electrical command at time `t`.
  void Command(double t, double duty);
  /// Held input in force at time `t`: the last command whose effective instant is ≤ t (the
  /// spool reference, or with a pilot stage the pilot stage's input).
  double EffectiveAt(double t) const;
  /// The first effective instant strictly after `t`, or +∞.
  double NextSwitchAfter(double t) const;
  /// Forgets entries superseded before `t` (keeps the one in force at t).
  void Prune(double t);

  double transport_delay() const { return valve_.transport_delay; }
  double pilot_delay() const { return valve_.pilot_delay; }
  double dead_zone() const { return valve_.dead_zone; }
  void set_transport_delay(double delay) { valve_.transport_delay = delay; }
  /// Whether EffectiveAt gives the raw command (the input of the plant's pilot lag state).
  bool raw() const { return HasPilotStage(valve_); }

 private:
  struct Entry {
    double effective_time;
    double value;
  };
  model::Valve valve_;
  double initial_value_ = 0.0;
  std::deque<Entry> history_;
};

/// The pilot (EPPR) pressure as a transducer on the pilot line shows it, as a fraction of the
/// full pilot pressure, signed by direction: π(t) = lag_{T_p}(u(t − τ_p)). The input is
/// piecewise constant, so between two of its switches π relaxes exactly,
/// π(t) = u + (π(t₀) − u)·exp(−(t − t₀)/T_p); T_p = 0 gives π(t) = u(t − τ_p). The spool path
/// sees the same signal τ_d later (the plant's pilot state).
class PilotSignal {
 public:
  PilotSignal(double pilot_delay, double time_constant)
      : delay_(pilot_delay), time_constant_(time_constant) {}

  void Command(double t, double duty);
  /// π at `t` (not before the last Prune).
  double At(double t) const;
  /// Folds the switches at or before `t` into the state.
  void Prune(double t);

 private:
  double Relax(double from, double input, double dt) const;
  struct Entry {
    double time;
    double value;
  };
  double delay_, time_constant_;
  double t0_ = 0, pi0_ = 0, input_ = 0;  // π(t0_) and the input in force from t0_
  std::deque<Entry> pending_;
};

}  // namespace autoshovel::plant
