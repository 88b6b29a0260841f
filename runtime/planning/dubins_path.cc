// Dubins paths in closed form (Shkel & Lumelsky 2001, "Classification of the Dubins set"; the
// normalised formulation of A. Walker's dubins.c): with d = D κmax the distance between the
// start and goal in turning radii, θ the direction from start to goal, α = ψ0 − θ and
// β = ψ1 − θ, each word gives its three normalised segment lengths (t, p, q) or no solution.
#include "runtime/planning/dubins_path.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace autoshovel::planning {

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

double Mod2Pi(double angle) {
  double r = std::fmod(angle, kTwoPi);
  if (r < 0) r += kTwoPi;
  // A full turn from rounding (e.g. 2π − 1e-16) is no turn at all.
  return r > kTwoPi - 1e-10 ? 0.0 : r;
}

// Segment types of each word: +1 left, −1 right, 0 straight.
constexpr std::array<std::array<int, 3>, 6> kSegmentTypes = {{
    {+1, 0, +1},   // LSL
    {+1, 0, -1},   // LSR
    {-1, 0, +1},   // RSL
    {-1, 0, -1},   // RSR
    {-1, +1, -1},  // RLR
    {+1, -1, +1},  // LRL
}};

// Normalised (t, p, q) of one word, or nullopt when the word has no solution.
std::optional<std::array<double, 3>> Solve(DubinsWord word, double alpha, double beta, double d) {
  const double sa = std::sin(alpha), sb = std::sin(beta);
  const double ca = std::cos(alpha), cb = std::cos(beta);
  const double c_ab = std::cos(alpha - beta);
  switch (word) {
    case DubinsWord::kLSL: {
      const double p_sq = 2 + d * d - 2 * c_ab + 2 * d * (sa - sb);
      if (p_sq < -1e-12) return std::nullopt;
      // p = 0: both turning circles coincide, one arc (the straight's direction is undefined).
      if (p_sq < 1e-18) return std::array<double, 3>{0.0, 0.0, Mod2Pi(beta - alpha)};
      const double tmp = std::atan2(cb - ca, d + sa - sb);
      return std::array<double, 3>{Mod2Pi(tmp - alpha), std::sqrt(std::max(p_sq, 0.0)),
                                   Mod2Pi(beta - tmp)};
    }
    case DubinsWord::kRSR: {
      const double p_sq = 2 + d * d - 2 * c_ab + 2 * d * (sb - sa);
      if (p_sq < -1e-12) return std::nullopt;
      if (p_sq < 1e-18) return std::array<double, 3>{0.0, 0.0, Mod2Pi(alpha - beta)};
      const double tmp = std::atan2(ca - cb, d - sa + sb);
      return std::array<double, 3>{Mod2Pi(alpha - tmp), std::sqrt(std::max(p_sq, 0.0)),
                                   Mod2Pi(tmp - beta)};
    }
    case DubinsWord::kLSR: {
      const double p_sq = -2 + d * d + 2 * c_ab + 2 * d * (sa + sb);
      if (p_sq < -1e-12) return std::nullopt;
      const double p = std::sqrt(std::max(p_sq, 0.0));
      const double tmp = std::atan2(-ca - cb, d + sa + sb) - std::atan2(-2.0, p);
      return std::array<double, 3>{Mod2Pi(tmp - alpha), p, Mod2Pi(tmp - Mod2Pi(beta))};
    }
    case DubinsWord::kRSL: {
      const double p_sq = -2 + d * d + 2 * c_ab - 2 * d * (sa + sb);
      if (p_sq < -1e-12) return std::nullopt;
      const double p = std::sqrt(std::max(p_sq, 0.0));
      const double tmp = std::atan2(ca + cb, d - sa - sb) - std::atan2(2.0, p);
      return std::array<double, 3>{Mod2Pi(alpha - tmp), p, Mod2Pi(beta - tmp)};
    }
    case DubinsWord::kRLR: {
      const double tmp = (6 - d * d + 2 * c_ab + 2 * d * (sa - sb)) / 8;
      if (std::abs(tmp) > 1) return std::nullopt;
      const double phi = std::atan2(ca - cb, d - sa + sb);
      const double p = Mod2Pi(kTwoPi - std::acos(tmp));
      const double t = Mod2Pi(alpha - phi + Mod2Pi(p / 2));
      return std::array<double, 3>{t, p, Mod2Pi(alpha - beta - t + Mod2Pi(p))};
    }
    case DubinsWord::kLRL: {
      const double tmp = (6 - d * d + 2 * c_ab + 2 * d * (sb - sa)) / 8;
      if (std::abs(tmp) > 1) return std::nullopt;
      const double phi = std::atan2(ca - cb, d + sa - sb);
      const double p = Mod2Pi(kTwoPi - std::acos(tmp));
      const double t = Mod2Pi(-alpha - phi + p / 2);
      return std::array<double, 3>{t, p, Mod2Pi(Mod2Pi(beta) - alpha - t + Mod2Pi(p))};
    }
  }
  return std::nullopt;
}

// Pose after moving `length` metres from `pose` on a segment of type `type` (radius r).
Pose2 Advance(const Pose2& pose, int type, double length, double r) {
  Pose2 out = pose;
  if (type == 0) {
    out.xy += length * Eigen::Vector2d(std::cos(pose.heading), std::sin(pose.heading));
    return out;
  }
  const double dpsi = type * length / r;
  // Chord of the arc: exact for any angle.
  out.xy += Eigen::Vector2d(type * r * (std::sin(pose.heading + dpsi) - std::sin(pose.heading)),
                            type * r * (std::cos(pose.heading) - std::cos(pose.heading + dpsi)));
  out.heading = pose.heading + dpsi;
  return out;
}

}  // namespace

std::string_view ToString(DubinsWord word) {
  constexpr std::array<std::string_view, 6> kNames = {"LSL", "LSR", "RSL", "RSR", "RLR", "LRL"};
  return kNames[static_cast<int>(word)];
}

double DubinsPath::CurvatureAt(double s) const {
  const auto& types = kSegmentTypes[static_cast<int>(word)];
  s = std::clamp(s, 0.0, length());
  double end = 0;
  int last_nonzero = 0;
  for (int i = 0; i < 3; ++i) {
    if (lengths[i] <= 0) continue;
    last_nonzero = i;
    end += lengths[i];
    if (s < end) return types[i] / radius;
  }
  return types[last_nonzero] / radius;
}

Pose2 DubinsPath::At(double s) const {
  const auto& types = kSegmentTypes[static_cast<int>(word)];
  s = std::clamp(s, 0.0, length());
  Pose2 pose = start;
  for (int i = 0; i < 3 && s > 0; ++i) {
    const double step = std::min(s, lengths[i]);
    pose = Advance(pose, types[i], step, radius);
    s -= step;
  }
  pose.heading = std::remainder(pose.heading, kTwoPi);
  return pose;
}

std::vector<DubinsPath> AllDubinsPaths(const Pose2& start, const Pose2& goal, double kappa_max) {
  if (!(kappa_max > 0) || !std::isfinite(kappa_max)) {
    throw std::invalid_argument("AllDubinsPaths: kappa_max must be > 0, got " +
                                std::to_string(kappa_max));
  }
  if (!start.xy.allFinite() || !goal.xy.allFinite() || !std::isfinite(start.heading) ||
      !std::isfinite(goal.heading)) {
    throw std::invalid_argument("AllDubinsPaths: start and goal must be finite");
  }
  const double r = 1 / kappa_max;
  const Eigen::Vector2d delta = goal.xy - start.xy;
  const double d = delta.norm() / r;
  const double theta = d > 0 ? Mod2Pi(std::atan2(delta.y(), delta.x())) : 0.0;
  const double alpha = Mod2Pi(start.heading - theta), beta = Mod2Pi(goal.heading - theta);
  std::vector<DubinsPath> paths;
  for (int w = 0; w < 6; ++w) {
    const auto word = static_cast<DubinsWord>(w);
    const auto tpq = Solve(word, alpha, beta, d);
    if (!tpq) continue;
    DubinsPath path;
    path.start = start;
    path.word = word;
    path.radius = r;
    for (int i = 0; i < 3; ++i) path.lengths[i] = (*tpq)[i] * r;
    paths.push_back(path);
  }
  std::stable_sort(paths.begin(), paths.end(), [](const DubinsPath& a, const DubinsPath& b) {
    return a.length() < b.length();
  });
  return paths;
}

DubinsPath ShortestDubinsPath(const Pose2& start, const Pose2& goal, double kappa_max) {
  const std::vector<DubinsPath> paths = AllDubinsPaths(start, goal, kappa_max);
  if (paths.empty()) throw std::logic_error("ShortestDubinsPath: no word solved");  // not reached
  return paths.front();
}

std::vector<PathSample> SamplePath(const DubinsPath& path, double spacing) {
  if (!(spacing > 0)) {
    throw std::invalid_argument("SamplePath: spacing must be > 0 m, got " +
                                std::to_string(spacing));
  }
  const double length = path.length();
  const int n = static_cast<int>(std::floor(length / spacing));
  std::vector<PathSample> samples;
  samples.reserve(n + 2);
  auto add = [&](double s) {
    const Pose2 pose = path.At(s);
    samples.push_back({s, pose.xy, pose.heading, path.CurvatureAt(s)});
  };
  for (int k = 0; k <= n; ++k) add(k * spacing);
  if (length - n * spacing > 1e-9) add(length);
  return samples;
}

}  // namespace autoshovel::planning
