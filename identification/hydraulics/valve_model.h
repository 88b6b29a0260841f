// The valve–actuator model that hydraulic identification fits to a log (output error): the
// path of runtime/plant (plant.h, valve_command.h) from the valve command to the joint, reduced
// to what a step or chirp log can tell apart.
//
//   u_eff(t) = sign(u)·max(|u| − d, 0)/(1 − d)                 dead zone d (spool overlap)
//   r(t)     = u_eff(t − τ_d)                                    transport delay τ_d
//   τ_s ẋ_s  = r − x_s                                           first-order spool lag τ_s
//   Q        = Q_rated · x_s                                     pressure-compensated load
//                                                                sensing: flow ∝ opening
//   L̇        = Q / A_A (x_s > 0, extending), Q / A_B (x_s < 0)   cylinder length (A_B annulus)
//   q        = q(L)                                              generated kinematics
// (a motor: q̇ = Q / displacement). The load-independent flow is what the plant's compensators
// give; the oil's compressibility and the arm's inertia (a hydraulic resonance near 10 Hz on
// the loaders) are left out, which shifts the joint response by a few milliseconds.
//
// Wheel-loader seed §1 and §7.4: the ~0.6 s from a command to arm motion is the transport delay
// plus the spool lag, which is what this model separates.
//
// Smoothness in τ_d. The command is held between log rows (zero-order hold, as the controller
// that wrote it holds it for a tick), so the delayed reference is piecewise constant with
// switches at t_i + τ_d. Between switches the spool follows the exact exponential; its value at
// each sample is therefore a continuous function of τ_d, and the cylinder length, its integral,
// is continuously differentiable in τ_d. Shifting the command by a whole number of samples
// instead would make the cost a staircase in τ_d with zero gradient, which no least-squares
// solver can descend.
#pragma once

#include <cmath>
#include <span>
#include <vector>

#include "generated/machine_functions.h"
#include "runtime/model/description.h"

namespace autoshovel::identification {

/// What is identified per actuator, SI.
struct ValveParameters {
  double dead_zone = 0;            ///< d, fraction of full command [-]
  double transport_delay = 0;      ///< τ_d [s]
  double spool_time_constant = 0;  ///< τ_s [s]
  double rated_flow = 0;           ///< Q_rated at full spool [m³/s]
};

/// Cylinder length ↔ joint angle of one actuator through the generated kinematics, the other
/// joints held at `q_rest` (the loader's and excavator's cylinders span one joint each).
class ActuatorKinematics {
 public:
  ActuatorKinematics(const model::MachineDescription& machine,
                     const generated::MachineFunctions& functions, int actuator);

  /// Cylinder length [m] (a motor: the joint angle itself) at joint angle q [rad].
  double Length(double q) const;
  /// dL/dq [m/rad] (a motor: 1).
  double Lever(double q) const;
  /// Joint angle for a length; beyond the joint's range, extrapolated along the lever. Within
  /// it, interpolated in a table of the generated inverse (error below 1e-12 rad). `slope`,
  /// if given, receives dq/dL [rad/m].
  double Angle(double length, double* slope = nullptr) const;
  /// The generated inverse itself (a Newton iteration), within the joint's range.
  double ExactAngle(double length) const;
  /// Volume per unit length (area [m²], a motor: displacement [m³/rad]) extending / retracting.
  double area_extend() const { return area_extend_; }
  double area_retract() const { return area_retract_; }
  /// Lengths at the stroke ends [m] (a motor: ±∞).
  double length_min() const { return length_min_; }
  double length_max() const { return length_max_; }
  int joint() const { return joint_; }

 private:
  const generated::MachineFunctions& functions_;
  int actuator_;
  int joint_;
  bool motor_;
  std::vector<double> q_rest_;
  double area_extend_ = 0, area_retract_ = 0;
  double length_min_ = 0, length_max_ = 0;
  double q_low_ = 0, q_high_ = 0;                  ///< joint range [rad]
  double length_at_low_ = 0, length_at_high_ = 0;  ///< cylinder length there [m]
  double lever_at_low_ = 1, lever_at_high_ = 1;    ///< dL/dq there [m/rad]
  double table_origin_ = 0, table_step_ = 1;       ///< of the tables below [m]
  std::vector<double> table_angle_, table_slope_;  ///< q [rad], dq/dL [rad/m] at the nodes
};

/// Dead zone of valve_command.h, smooth in d away from |u| = d.
template <typename T>
T DeadZone(double u, const T& d) {
  const double magnitude = std::abs(u);
  if (magnitude <= d) return T(0.0);
  return (u > 0 ? 1.0 : -1.0) * (magnitude - d) / (1.0 - d);
}

/// Spool and signed flow integral over one interval of constant reference r, starting at x0:
/// x(t) = r + (x0 − r) e^{−t/τ}. Returns x at the end and adds ∫ max(x,0) and ∫ min(x,0) over
/// [0, span] to `positive` and `negative` (x changes sign at most once: it is monotonic).
template <typename T>
T PropagateSpool(const T& x0, const T& r, const T& tau, const T& span, T& positive, T& negative) {
  using std::exp;
  using std::log;
  if (!(span > 0.0)) return x0;
  const T decay = exp(-span / tau);
  const T x1 = r + (x0 - r) * decay;
  // ∫_a^b x dt over a piece [a, b] of the interval, from the closed form.
  auto integral = [&](const T& a, const T& b) {
    return r * (b - a) + (x0 - r) * tau * (exp(-a / tau) - exp(-b / tau));
  };
  const bool crosses = (x0 > 0.0 && x1 < 0.0) || (x0 < 0.0 && x1 > 0.0);
  if (!crosses) {
    // integral(0, span) with its two exponentials known (e^0 = 1, e^{−span/τ} = decay): the
    // same value, a third of the work, and the common case of every row of every evaluation.
    const T whole = r * span + (x0 - r) * tau * (1.0 - decay);
    if (x0 > 0.0 || x1 > 0.0) {
      positive += whole;
    } else {
      negative += whole;
    }
    return x1;
  }
  // x0 and r of opposite signs: zero at t* = τ ln((x0 − r)/(−r)).
  const T t_zero = tau * log((x0 - r) / (-r));
  const T first = integral(T(0.0), t_zero);
  const T second = integral(t_zero, span);
  if (x0 > 0.0) {
    positive += first;
    negative += second;
  } else {
    negative += first;
    positive += second;
  }
  return x1;
}

/// The model's response to one log: spool at every sample, and the cylinder length change
/// ∫ L̇ dt since the start of the log, for Q_rated = 1 split by direction so that the caller
/// scales by the rated flow and the areas: ΔL = Q_rated (P/A_A + N/A_B).
template <typename T>
struct ValveResponse {
  std::vector<T> spool;     ///< x_s at each sample [-1, 1]
  std::vector<T> positive;  ///< ∫ max(x_s, 0) dt from the first sample [s]
  std::vector<T> negative;  ///< ∫ min(x_s, 0) dt from the first sample [s]
};

/// Simulates the spool through the log's command history and hands it to `visit(j, x_s, P, N)`
/// at each of `count` instants `query(j)` (sorted; the log's own times, or shifted ones), with
/// the flow integrals as in ValveResponse. The log starts at rest: the spool sits at the
/// effective value of the first command, also before the first row. Nothing is stored: a fit
/// on a log of a million rows evaluates this tens of times.
/// `time` and `command` may be a tail of a log (a span from some row on): the spool then starts
/// at rest at that row's command, which after the delay and several spool time constants no
/// longer shows (the fit's per-segment residuals warm up so).
template <typename T, typename Query, typename Visit>
void ForEachValveSample(std::span<const double> time, std::span<const double> command,
                        std::size_t count, const Query& query, const T& dead_zone,
                        const T& transport_delay, const T& spool_time_constant,
                        const Visit& visit) {
  const std::size_t n = time.size();
  if (n == 0) return;
  T x = DeadZone(command[0], dead_zone);  // spool
  T r = x;                                // reference in force
  T clock(time[0]);                       // instant x refers to
  T positive(0.0), negative(0.0);
  std::size_t next = 1;  // next command switch: reaches the spool at time[next] + τ_d
  auto advance_to = [&](const T& t) {
    if (!(t > clock)) return;
    x = PropagateSpool(x, r, spool_time_constant, T(t - clock), positive, negative);
    clock = t;
  };
  for (std::size_t j = 0; j < count; ++j) {
    const T at = query(j);
    // Switches that reach the spool before this instant. Commands repeating the previous one
    // do not switch anything.
    while (next < n && time[next] + transport_delay <= at) {
      if (command[next] != command[next - 1]) {
        advance_to(time[next] + transport_delay);
        r = DeadZone(command[next], dead_zone);
      }
      ++next;
    }
    advance_to(at);
    visit(j, x, positive, negative);
  }
}

/// The response at `query` times (ForEachValveSample), stored.
template <typename T>
ValveResponse<T> SimulateValve(const std::vector<double>& time, const std::vector<double>& command,
                               const std::vector<T>& query, const T& dead_zone,
                               const T& transport_delay, const T& spool_time_constant) {
  ValveResponse<T> out;
  out.spool.resize(query.size());
  out.positive.resize(query.size());
  out.negative.resize(query.size());
  if (time.empty()) return out;
  ForEachValveSample(
      time, command, query.size(), [&](std::size_t j) { return query[j]; }, dead_zone,
      transport_delay, spool_time_constant,
      [&](std::size_t j, const T& x, const T& positive, const T& negative) {
        out.spool[j] = x;
        out.positive[j] = positive;
        out.negative[j] = negative;
      });
  return out;
}

/// The same, sampled at the log's times.
template <typename T>
ValveResponse<T> SimulateValve(const std::vector<double>& time, const std::vector<double>& command,
                               const T& dead_zone, const T& transport_delay,
                               const T& spool_time_constant) {
  std::vector<T> query(time.size());
  for (std::size_t j = 0; j < time.size(); ++j) query[j] = T(time[j]);
  return SimulateValve(time, command, query, dead_zone, transport_delay, spool_time_constant);
}

}  // namespace autoshovel::identification
