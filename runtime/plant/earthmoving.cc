#include "runtime/plant/earthmoving.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "runtime/model/plant_constants.h"

namespace autoshovel::plant {

namespace {

double Cot(double x) { return std::cos(x) / std::sin(x); }

// The denominator D and N_γ at failure angle β; +∞ where the wedge is not admissible (D ≤ 0).
double NGamma(double alpha, double beta, double phi, double delta) {
  const double d = std::cos(alpha + delta) + std::sin(alpha + delta) * Cot(beta + phi);
  if (!(d > 1e-9)) return std::numeric_limits<double>::infinity();
  return (Cot(alpha) + Cot(beta)) / (2.0 * d);
}

}  // namespace

ReeceFactors ComputeReeceFactors(double rake_angle, double friction_angle,
                                 double interface_friction_angle) {
  constexpr double kDeg = std::numbers::pi / 180.0;
  const double alpha = std::clamp(rake_angle, 10.0 * kDeg, 90.0 * kDeg);
  const double phi = friction_angle, delta = interface_friction_angle;
  // N_γ(β) has one minimum on the admissible range of β: a 1° scan brackets it and a
  // golden-section search refines it (a one-dimensional problem needs no optimisation library).
  double best_beta = 45.0 * kDeg, best = std::numeric_limits<double>::infinity();
  for (int i = 1; i < 90; ++i) {
    const double beta = i * kDeg;
    const double value = NGamma(alpha, beta, phi, delta);
    if (value < best) best = value, best_beta = beta;
  }
  double lo = std::max(best_beta - kDeg, 1e-3), hi = std::min(best_beta + kDeg, 89.999 * kDeg);
  const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
  for (int i = 0; i < 60; ++i) {
    const double a = hi - ratio * (hi - lo), b = lo + ratio * (hi - lo);
    if (NGamma(alpha, a, phi, delta) < NGamma(alpha, b, phi, delta)) {
      hi = b;
    } else {
      lo = a;
    }
  }
  const double beta = (lo + hi) / 2.0;
  const double d = std::cos(alpha + delta) + std::sin(alpha + delta) * Cot(beta + phi);
  ReeceFactors factors;
  factors.failure_angle = beta;
  factors.n_gamma = (Cot(alpha) + Cot(beta)) / (2.0 * d);
  factors.n_c = (1.0 + Cot(beta) * Cot(beta + phi)) / d;
  factors.n_q = (Cot(alpha) + Cot(beta)) / d;
  factors.n_a = (1.0 - Cot(alpha) * Cot(beta + phi)) / d;
  return factors;
}

namespace {
constexpr double kTableStepDeg = 0.5;
constexpr double kTableMinDeg = 10.0, kTableMaxDeg = 90.0;
}  // namespace

ReeceTable::ReeceTable(double friction_angle, double interface_friction_angle)
    : friction_angle_(friction_angle), interface_friction_angle_(interface_friction_angle) {
  constexpr double kDeg = std::numbers::pi / 180.0;
  for (double a = kTableMinDeg; a <= kTableMaxDeg + 1e-9; a += kTableStepDeg) {
    entries_.push_back(ComputeReeceFactors(a * kDeg, friction_angle, interface_friction_angle));
  }
}

ReeceFactors ReeceTable::At(double rake_angle) const {
  constexpr double kDeg = std::numbers::pi / 180.0;
  const double f =
      (std::clamp(rake_angle / kDeg, kTableMinDeg, kTableMaxDeg) - kTableMinDeg) / kTableStepDeg;
  const std::size_t i = std::min(static_cast<std::size_t>(f), entries_.size() - 2);
  const double t = f - static_cast<double>(i);
  const ReeceFactors &a = entries_[i], &b = entries_[i + 1];
  auto mix = [t](double x, double y) { return (1 - t) * x + t * y; };
  return {mix(a.n_gamma, b.n_gamma), mix(a.n_c, b.n_c), mix(a.n_q, b.n_q), mix(a.n_a, b.n_a),
          mix(a.failure_angle, b.failure_angle)};
}

CuttingResistance ComputeCuttingResistance(const CuttingInput& in) {
  CuttingResistance out;
  if (!(in.depth > 0) || !(in.width > 0)) return out;
  const ReeceFactors n = in.table != nullptr ? in.table->At(in.rake_angle)
                                             : ComputeReeceFactors(in.rake_angle, in.friction_angle,
                                                                   in.interface_angle);
  const double unit_weight = in.density * model::plant::kGravity;
  const double d = in.depth;
  out.total = in.width * (unit_weight * d * d * n.n_gamma + in.cohesion * d * n.n_c +
                          in.surcharge * d * n.n_q + in.adhesion * d * n.n_a);
  out.total = std::max(out.total, 0.0);
  constexpr double kDeg = std::numbers::pi / 180.0;
  const double alpha = std::clamp(in.rake_angle, 10.0 * kDeg, 90.0 * kDeg);
  out.along = out.total * std::sin(alpha + in.interface_angle);
  out.across = out.total * std::cos(alpha + in.interface_angle);
  return out;
}

}  // namespace autoshovel::plant
