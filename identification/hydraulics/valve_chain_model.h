// The valve chain that `identify hydraulics` fits to a real machine's step logs, per actuator
// and command direction s = sign(u):
//
//   pilot:   p̂(t)  = p_0 + lag_{T_p}( a·max(0, s·u(t − τ_p) − u_0) )      command → pilot [bar]
//   motion:  π(t)  = lag_{T_p}( max(0, s·u(t − τ_p − τ_m)) )                pilot, command units
//            o(t)  = O(π(t))                                                flow characteristic
//            x(t)  = lag_{T_m + T_g·o/O_max}( o(t) )                       spool and flow build-up
//            f(t)  = lag_{T_f}( max(0, O(s·u(t − τ_f)) − Q₁) )              late supply
//            q̇(t)  = s·(min(x(t), Q₁) + f(t))·G(q)·L(p_L)                    joint rate
//
// lag_T is a first-order lag (unit gain), u the logged command held between rows. The pure
// delays commute with the linear pilot lag, so the motion path sees the pilot signal τ_m later:
// the command → motion delay is τ_p + τ_m. O is the steady joint rate [rad/s] over the
// command: zero up to the dead band d, then a monotone cubic through its values at knots (the
// duty levels of the logs), monotone by construction (its values are sums of non-negative
// increments), flat beyond the last knot (pump flow limit). This is the plant's chain
// (runtime/plant/valve_command.h, docs/simulation.md) in joint space.
//
// The lag grows with the opening asked for (T_g at full opening): on the real excavator a
// 50 % step reaches its rate within 0.1 s of moving and a 100 % step takes several tenths (the
// pump swivelling to a larger displacement takes longer than the spool to open); one lag for
// all levels made the fit trade the delay against it level by level.
// The late supply: on the real excavator's boom, a high-duty step first reaches a plateau and
// about 2 s later a second, twice as fast, while a low-duty step has one plateau (a second
// pump joining when the demand exceeds the first, or the engine leaving its idle speed). The
// first supply gives up to Q₁ at once; what the opening asks beyond Q₁ arrives after its own
// delay τ_f and lag T_f. Q₁ at or above the highest rate means no such stage (its delay and
// lag then say nothing and are flagged).
// G(q) = exp(c₁z + c₂z²), z = (q − q_c)/q_h ∈ [−1, 1] over the angles the logs cover: the
// cylinder's lever changes the joint rate over the stroke at a constant flow (up to 2× on the real
// boom), and is fitted from the data because the logs' machine need not be the description's
// (and its angle sensor need not share the description's zero).
// L(p_L) = √max(0.05, 1 + κ (p_L − p̄_L)/100 bar), p_L = p_A − α p_B the load pressure: the
// orifice law around the mean load; κ < 0 when a higher load slows the joint (meter-in,
// Q ∝ √(p_s − p_L): κ = −100 bar/(p_s − p̄_L)), κ > 0 when the load drives the flow
// (meter-out of a lowering boom). Without pressure channels L ≡ 1.
//
// Sub-sample delays: the delayed input is averaged over each sample interval (the held
// command's integral is piecewise linear in τ), and each lag is updated exactly for that
// mean, so the simulated output is continuous in every delay and the least-squares cost has
// a gradient in τ (a delay rounded to whole samples would give a staircase).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <vector>

namespace autoshovel::identification {

namespace chain_detail {
inline double Value(double x) { return x; }
template <typename J>
double Value(const J& x) {
  return x.a;
}
}  // namespace chain_detail

/// Mean over [a, b] (a < b) of f(u(t)), u held from each row to the next (u(time[0]) before
/// the first row, the last value after the last). `cursor` carries the row index between
/// calls with non-decreasing `a`.
template <typename T, typename F>
T HeldMean(std::span<const double> time, std::span<const double> command, const T& a, const T& b,
           const F& f, std::size_t& cursor) {
  using chain_detail::Value;
  const std::size_t n = time.size();
  while (cursor + 1 < n && time[cursor + 1] <= Value(a)) ++cursor;
  T total(0.0);
  T from = a;
  std::size_t j = cursor;
  bool before = Value(a) < time[0];  // the first command holds before the first row
  for (;;) {
    const double end =
        before ? time[0] : (j + 1 < n ? time[j + 1] : std::numeric_limits<double>::infinity());
    const T value = T(f(before ? command[0] : command[j]));
    if (Value(b) <= end) {
      total += value * (b - from);
      break;
    }
    total += value * (T(end) - from);
    from = T(end);
    if (before) {
      before = false;
      j = 0;
    } else {
      ++j;
    }
  }
  return total / (b - a);
}

/// Exact first-order lag step over h for an input held at `input`.
template <typename T>
T LagStep(const T& state, const T& input, double h, const T& time_constant) {
  using std::exp;
  const T decay = exp(-h / time_constant);
  return state * decay + input * (1.0 - decay);
}

/// O(π): the steady joint rate for a command-equivalent pilot π ≥ 0. Through the nodes
/// (d, 0), (knot_j, rate_j) a monotone cubic (Fritsch–Carlson: Hermite with weighted harmonic
/// mean slopes, Fritsch & Butland 1984), which follows a spool's S-shaped characteristic
/// between the logged levels better than straight lines and never overshoots: non-decreasing
/// node values give a non-decreasing curve. Zero below d, the last value beyond the last knot.
template <typename T>
T Opening(const T& pilot, const T& dead_band, std::span<const double> knots,
          std::span<const T> rates) {
  using chain_detail::Value;
  if (!(pilot > dead_band) || knots.empty()) return T(0.0);
  const std::size_t m = knots.size();
  if (Value(pilot) >= knots[m - 1]) return rates[m - 1];
  // Nodes: 0 is the dead band, i ≥ 1 the knots.
  auto x = [&](std::size_t i) { return i == 0 ? dead_band : T(knots[i - 1]); };
  auto y = [&](std::size_t i) { return i == 0 ? T(0.0) : rates[i - 1]; };
  std::size_t i = 0;  // interval [x_i, x_{i+1}]
  while (i + 1 < m && Value(pilot) > knots[i]) ++i;
  auto secant = [&](std::size_t a) { return (y(a + 1) - y(a)) / (x(a + 1) - x(a)); };
  auto slope = [&](std::size_t node) -> T {
    if (node == 0) return secant(0);
    if (node == m) return secant(m - 1);
    const T d0 = secant(node - 1), d1 = secant(node);
    if (!(d0 > 0.0) || !(d1 > 0.0)) return T(0.0);
    const T h0 = x(node) - x(node - 1), h1 = x(node + 1) - x(node);
    return 3.0 * (h0 + h1) / ((2.0 * h1 + h0) / d0 + (h1 + 2.0 * h0) / d1);
  };
  const T h = x(i + 1) - x(i);
  const T s = (pilot - x(i)) / h;
  const T s2 = s * s, s3 = s2 * s;
  return (2.0 * s3 - 3.0 * s2 + 1.0) * y(i) + (s3 - 2.0 * s2 + s) * h * slope(i) +
         (-2.0 * s3 + 3.0 * s2) * y(i + 1) + (s3 - s2) * h * slope(i + 1);
}

/// One log as the motion stage sees it (one command direction).
struct ChainSamples {
  std::span<const double> time;
  std::span<const double> command;  ///< signed [-1, 1]
  std::span<const double> angle;    ///< measured [rad]
  std::span<const double> load;     ///< p_L − p̄_L [Pa]; empty: no pressure
  std::vector<std::pair<std::size_t, std::size_t>> segments;  ///< integrated runs
  /// τ_p, held (the pilot stage's, fitted on the pilot channel; 0 without one): the motion path
  /// sees the command τ_p + τ_m late.
  double pilot_delay = 0;
  int joint_sense = 1;  ///< −1: a positive command lowers the joint angle (step_events.h)
};

/// Motion-stage parameters of one direction, as a flat vector (the fit's parameter block).
enum MotionIndex : int {
  kMotionDelay = 0,  ///< τ_m [s]
  kMotionLag,        ///< T_m [s]
  kPilotLag,         ///< T_p [s] (held at the pilot fit's value when the log has a pilot)
  kDeadBand,         ///< d [-]
  kLoadCoefficient,  ///< κ [-]
  kGainLinear,       ///< c₁
  kGainQuadratic,    ///< c₂
  kSupplyCapacity,   ///< Q₁: the rate the first supply gives at once [rad/s]
  kSupplyDelay,      ///< τ_f: its delay after the command [s]
  kSupplyLag,        ///< T_f: its lag [s]
  kMotionLagSlope,   ///< T_m grows by this at full opening [s]
  kMotionFixed,      ///< then one increment per knot [rad/s]
};

struct AngleScale {
  double center = 0;      ///< q_c [rad]
  double half_range = 1;  ///< q_h [rad]
};

/// Simulates the motion stage of direction `sign` over one log and calls
/// `visit(k, q̂_k, v̂_k)` at every sample of every segment; `segment_start[i]` is the angle at
/// the first sample of segment i.
template <typename T, typename Visit>
void SimulateMotion(const ChainSamples& log, int sign, const T* params,
                    std::span<const double> knots, const AngleScale& scale, const T* segment_start,
                    const Visit& visit) {
  using std::exp;
  using std::sqrt;
  const std::size_t n = log.time.size();
  if (n == 0 || log.segments.empty()) return;
  const std::size_t count = knots.size();
  std::vector<T> rates(count);
  T sum(0.0);
  for (std::size_t j = 0; j < count; ++j) {
    sum += params[kMotionFixed + j];
    rates[j] = sum;
  }
  const std::span<const T> rate_span(rates.data(), count);
  const T delay = params[kMotionDelay] + log.pilot_delay;  // τ_p + τ_m
  const T& motion_lag = params[kMotionLag];
  const T& pilot_lag = params[kPilotLag];
  const T& dead_band = params[kDeadBand];
  auto drive = [sign](double u) { return std::max(0.0, sign * u); };
  auto gain = [&](const T& q) {
    // Beyond the angles the logs cover G is held at its edge: a quadratic in the exponent
    // must not be extrapolated (a prediction that overshoots would run away).
    T z = (q - scale.center) / scale.half_range;
    if (z > 1.0) z = T(1.0);
    if (z < -1.0) z = T(-1.0);
    return exp(params[kGainLinear] * z + params[kGainQuadratic] * z * z);
  };
  auto load = [&](std::size_t k) {
    if (log.load.empty()) return T(1.0);
    const T inside = 1.0 + params[kLoadCoefficient] * (log.load[k] / 100e5);
    return sqrt(inside > 0.05 ? inside : T(0.05));
  };
  T pilot(drive(log.command[0]));
  T opening = Opening(pilot, dead_band, knots, rate_span);
  T spool = opening;
  // What the opening asks beyond the first supply's capacity arrives late.
  const T& capacity = params[kSupplyCapacity];
  auto demand = [&](double u) -> T {
    const T asked = Opening(T(drive(u)), dead_band, knots, rate_span);
    return asked > capacity ? asked - capacity : T(0.0);
  };
  T supply = demand(log.command[0]);
  std::size_t supply_cursor = 0;
  auto supplied = [&](const T& x, const T& late) { return (x < capacity ? x : capacity) + late; };
  std::size_t cursor = 0;
  std::size_t segment = 0;
  T q(0.0);
  for (std::size_t k = 0; k < n; ++k) {
    while (segment < log.segments.size() && k >= log.segments[segment].second) ++segment;
    if (segment >= log.segments.size()) return;
    const bool inside = k >= log.segments[segment].first;
    if (k == log.segments[segment].first) q = segment_start[segment];
    const T velocity = double(sign * log.joint_sense) * supplied(spool, supply) * gain(q) * load(k);
    if (inside) visit(k, q, velocity);
    if (k + 1 >= n) break;
    const double h = log.time[k + 1] - log.time[k];
    const T a = log.time[k] - delay;
    const T b = log.time[k + 1] - delay;
    const T mean = HeldMean(log.time, log.command, a, b, drive, cursor);
    pilot = LagStep(pilot, mean, h, pilot_lag);
    const T next_opening = Opening(pilot, dead_band, knots, rate_span);
    // The fit's bounds let every flow value reach 0: no division by it.
    const T top = rates.back() > 1e-9 ? rates.back() : T(1e-9);
    const T lag_now = motion_lag + params[kMotionLagSlope] * (next_opening / top);
    const T next_spool = LagStep(spool, T(0.5) * (opening + next_opening), h, lag_now);
    const T supply_mean =
        HeldMean(log.time, log.command, T(log.time[k] - params[kSupplyDelay]),
                 T(log.time[k + 1] - params[kSupplyDelay]), demand, supply_cursor);
    const T next_supply = LagStep(supply, supply_mean, h, params[kSupplyLag]);
    if (inside && k + 1 < log.segments[segment].second) {
      // Heun: the rate at the end of the step from an Euler predictor.
      const T predicted = q + h * velocity;
      const T end_velocity = double(sign * log.joint_sense) * supplied(next_spool, next_supply) *
                             gain(predicted) * load(k + 1);
      q = q + 0.5 * h * (velocity + end_velocity);
    }
    opening = next_opening;
    spool = next_spool;
    supply = next_supply;
  }
}

/// Pilot-stage parameters of one direction.
enum PilotIndex : int {
  kPilotDelay = 0,     ///< τ_p [s]
  kPilotTimeConstant,  ///< T_p [s]
  kPilotGain,          ///< a [bar per unit command]
  kPilotThreshold,     ///< u_0 [-]
  kPilotOffset,        ///< p_0 [bar]
  kPilotCount,
};

/// Simulates the pilot stage over one log: `visit(k, p̂_k)` [bar] at every sample.
template <typename T, typename Visit>
void SimulatePilot(std::span<const double> time, std::span<const double> command, int sign,
                   const T* params, const Visit& visit) {
  const std::size_t n = time.size();
  if (n == 0) return;
  const T& threshold = params[kPilotThreshold];
  // max(0, s·u − u_0)·a, u_0 a parameter: the held mean is linear in it per piece.
  auto mapped = [&](double u) -> T {
    const T x = sign * u - threshold;
    return x > 0.0 ? params[kPilotGain] * x : T(0.0);
  };
  T state = mapped(command[0]);
  std::size_t cursor = 0;
  for (std::size_t k = 0; k < n; ++k) {
    visit(k, params[kPilotOffset] + state);
    if (k + 1 >= n) break;
    const double h = time[k + 1] - time[k];
    const T a = time[k] - params[kPilotDelay];
    const T b = time[k + 1] - params[kPilotDelay];
    const T mean = HeldMean(time, command, a, b, mapped, cursor);
    state = LagStep(state, mean, h, params[kPilotTimeConstant]);
  }
}

}  // namespace autoshovel::identification
