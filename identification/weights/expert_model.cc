#include "identification/weights/expert_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

namespace autoshovel::identification {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kSampleStep = 0.1;  // bite and corridor sampling [m]

double Wrap(double angle) { return std::remainder(angle, 2 * kPi); }

double NearestObstacle(const plant::World& world, const Eigen::Vector2d& xy) {
  double nearest = std::numeric_limits<double>::infinity();
  for (const plant::OrientedBox& box : world.obstacles) {
    nearest = std::min(nearest, FootprintDistance(box, xy));
  }
  return nearest;
}

// Material depth at a point: the terrain cell's depth above its floor, 0 outside the grid.
double DepthAt(const plant::Terrain& terrain, const Eigen::Vector2d& xy) {
  int ix, iy;
  return terrain.CellOf(xy.x(), xy.y(), ix, iy) ? terrain.depth(ix, iy) : 0.0;
}

}  // namespace

double FootprintDistance(const plant::OrientedBox& box, const Eigen::Vector2d& xy) {
  const Eigen::Vector2d d = xy - box.center.head<2>();
  const double c = std::cos(box.yaw), s = std::sin(box.yaw);
  const double along = std::max(std::abs(c * d.x() + s * d.y()) - box.half_extents.x(), 0.0);
  const double across = std::max(std::abs(-s * d.x() + c * d.y()) - box.half_extents.y(), 0.0);
  return std::hypot(along, across);
}

ExpertTerms ExpertView(const plant::World& world, const planning::CandidatePose& candidate,
                       const planning::Pose2& start, double bucket_width,
                       const ExpertModel& model) {
  ExpertTerms terms;
  const Eigen::Vector2d u(std::cos(candidate.entry_heading), std::sin(candidate.entry_heading));
  const Eigen::Vector2d left(-u.y(), u.x());
  const double cell = kSampleStep * kSampleStep;
  double v_left = 0, v_right = 0;
  for (double a = 0.5 * kSampleStep; a < model.bite_depth; a += kSampleStep) {
    for (double l = -0.5 * bucket_width + 0.5 * kSampleStep; l < 0.5 * bucket_width;
         l += kSampleStep) {
      const double v = DepthAt(world.terrain, candidate.xy + a * u + l * left) * cell;
      (l > 0 ? v_left : v_right) += v;
    }
  }
  terms.bite = v_left + v_right;
  terms.imbalance = terms.bite > 1e-9 ? std::abs(v_left - v_right) / terms.bite : 0.0;

  // The straight corridor from the loader to the end of the bite, as wide as the body.
  const Eigen::Vector2d end = candidate.xy + model.bite_depth * u;
  const Eigen::Vector2d run = end - start.xy;
  const double length = run.norm();
  const Eigen::Vector2d along = length > 1e-9 ? Eigen::Vector2d(run / length) : u;
  const Eigen::Vector2d across(-along.y(), along.x());
  terms.clearance = std::numeric_limits<double>::infinity();
  for (double a = 0; a <= length; a += 4 * kSampleStep) {
    for (const double l : {-model.body_half_width, 0.0, model.body_half_width}) {
      terms.clearance =
          std::min(terms.clearance, NearestObstacle(world, start.xy + a * along + l * across));
    }
  }

  const Eigen::Vector2d to_entry = candidate.xy - start.xy;
  const double bearing = std::atan2(to_entry.y(), to_entry.x());
  const double turning =
      std::abs(Wrap(bearing - start.heading)) + std::abs(Wrap(candidate.entry_heading - bearing));
  terms.effort = to_entry.norm() / model.effort_length + turning / kPi;
  terms.squareness = std::cos(candidate.entry_offset);
  return terms;
}

int ChooseLikeAnExpert(const plant::World& world,
                       const std::vector<planning::CandidatePose>& candidates,
                       const planning::Pose2& start, double bucket_width, const ExpertModel& model,
                       std::uint64_t seed) {
  std::vector<ExpertTerms> terms;
  terms.reserve(candidates.size());
  double best_bite = 0;
  for (const planning::CandidatePose& c : candidates) {
    terms.push_back(ExpertView(world, c, start, bucket_width, model));
    best_bite = std::max(best_bite, terms.back().bite);
  }
  std::mt19937_64 rng(seed);
  int chosen = -1;
  double best = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    // One Gumbel draw per candidate whether vetoed or not, so that a candidate's noise does not
    // depend on the others' vetoes. The uniform is in (0, 1): the top 53 bits, offset by half.
    const double uniform = (static_cast<double>(rng() >> 11) + 0.5) * 0x1.0p-53;
    const double gumbel = -std::log(-std::log(uniform));
    const ExpertTerms& t = terms[i];
    // Vetoes: too close to an obstacle, or a bite with almost nothing in it.
    if (t.clearance < model.veto_distance || !(t.bite > 0.05 * best_bite)) continue;
    const double utility = model.fill * t.bite / best_bite - model.balance * t.imbalance +
                           model.clearance * std::min(t.clearance / model.comfort_distance, 1.0) -
                           model.effort * t.effort + model.squareness * t.squareness +
                           model.noise * gumbel;
    if (utility > best) best = utility, chosen = static_cast<int>(i);
  }
  return chosen;
}

}  // namespace autoshovel::identification
