// The path of one valve command from the controller to the spool reference: dead zone, then
// transport delay.
//
// SUNDIALS has no delay-differential solver, and the delay here acts on an input, not on the
// state, so none is needed: every command is stored with the instant it reaches the spool,
// t_effective = t_command + τ_d, and the plant integrates each interval between consecutive
// effective instants with the spool reference held constant, re-initialising CVODE exactly at
// each such instant (Plant::Advance). The spool therefore starts to move exactly τ_d after the
// command, with no interpolation error and no smoothing of the step.
#pragma once

#include <deque>
#include <limits>

namespace autoshovel::plant {

/// Valve dead zone (spool overlap): commands with |u| ≤ d give no opening; above it the opening
/// grows linearly and reaches full at |u| = 1, so u_eff = sign(u)·(|u| − d)/(1 − d).
double ApplyDeadZone(double duty, double dead_zone);

class DelayedValveCommand {
 public:
  DelayedValveCommand(double dead_zone, double transport_delay)
      : dead_zone_(dead_zone), transport_delay_(transport_delay) {}

  /// A new (validated) electrical command at time `t`.
  void Command(double t, double duty);
  /// Spool reference in force at time `t`: the last command whose effective instant is ≤ t.
  double EffectiveAt(double t) const;
  /// The first effective instant strictly after `t`, or +∞.
  double NextSwitchAfter(double t) const;
  /// Forgets entries superseded before `t` (keeps the one in force at t).
  void Prune(double t);

  double transport_delay() const { return transport_delay_; }
  double dead_zone() const { return dead_zone_; }
  void set_transport_delay(double delay) { transport_delay_ = delay; }

 private:
  struct Entry {
    double effective_time;
    double value;
  };
  double dead_zone_;
  double transport_delay_;
  double initial_value_ = 0.0;
  std::deque<Entry> history_;
};

}  // namespace autoshovel::plant
