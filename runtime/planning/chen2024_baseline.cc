// Chen et al. (2024)'s four indicators, as read in chen2024_baseline.h.
#include "runtime/planning/chen2024_baseline.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace autoshovel::planning {

using perception::GridMap;
using perception::Index;

Chen2024Indicators Chen2024IndicatorsAt(const GridMap& map, const Eigen::Vector3d& plane,
                                        const CandidatePose& pose, const Eigen::Vector2d& hinge_xy,
                                        const Chen2024Config& config) {
  Chen2024Indicators out;
  out.distance = (pose.xy - hinge_xy).norm();
  const Eigen::Vector2d u(std::cos(pose.entry_heading), std::sin(pose.entry_heading));
  const Eigen::Vector2d v(-u.y(), u.x());
  std::vector<Eigen::Matrix<double, 6, 1>> rows;
  std::vector<double> z;
  const int reach = static_cast<int>(std::ceil(config.fit_radius / map.resolution()));
  Index c;
  if (!map.IndexOf(pose.xy, c)) return out;
  for (int dy = -reach; dy <= reach; ++dy) {
    for (int dx = -reach; dx <= reach; ++dx) {
      const Index i(c.x() + dx, c.y() + dy);
      if (!map.IsValid(i) || std::isnan(map.at("elevation", i))) continue;
      const Eigen::Vector2d d = map.PositionOf(i) - pose.xy;
      if (d.norm() > config.fit_radius) continue;
      const double a = d.dot(u), l = d.dot(v);
      Eigen::Matrix<double, 6, 1> row;
      row << a * a, a * l, l * l, a, l, 1.0;
      rows.push_back(row);
      z.push_back(PileHeightAboveGround(map, plane, i));
    }
  }
  if (rows.size() < 6) return out;
  Eigen::MatrixXd A(rows.size(), 6);
  Eigen::VectorXd b(rows.size());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    A.row(static_cast<Eigen::Index>(k)) = rows[k].transpose();
    b(static_cast<Eigen::Index>(k)) = z[k];
  }
  const Eigen::Matrix<double, 6, 1> q = A.colPivHouseholderQr().solve(b);
  const double grad = std::hypot(q(3), q(4));
  out.convexity = -2 * q(2);
  out.inclination = grad > 1e-9 ? q(3) / grad : 0.0;
  out.slope = std::atan(grad);
  return out;
}

std::vector<Chen2024Candidate> RankChen2024(const GridMap& map, const Eigen::Vector3d& plane,
                                            const std::vector<CandidatePose>& candidates,
                                            const Eigen::Vector2d& hinge_xy,
                                            const Chen2024Config& config) {
  std::vector<Chen2024Candidate> out;
  out.reserve(candidates.size());
  for (const CandidatePose& pose : candidates) {
    Chen2024Candidate c;
    c.pose = pose;
    c.raw = Chen2024IndicatorsAt(map, plane, pose, hinge_xy, config);
    out.push_back(c);
  }
  // Min–max over the candidates of each pile.
  constexpr double kInf = std::numeric_limits<double>::infinity();
  struct Range {
    Chen2024Indicators lo{kInf, kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf, -kInf};
  };
  std::map<int, Range> ranges;
  for (const Chen2024Candidate& c : out) {
    Range& r = ranges[c.pose.pile];
    r.lo.convexity = std::min(r.lo.convexity, c.raw.convexity);
    r.hi.convexity = std::max(r.hi.convexity, c.raw.convexity);
    r.lo.inclination = std::min(r.lo.inclination, c.raw.inclination);
    r.hi.inclination = std::max(r.hi.inclination, c.raw.inclination);
    r.lo.slope = std::min(r.lo.slope, c.raw.slope);
    r.hi.slope = std::max(r.hi.slope, c.raw.slope);
    r.lo.distance = std::min(r.lo.distance, c.raw.distance);
    r.hi.distance = std::max(r.hi.distance, c.raw.distance);
  }
  auto unit = [](double x, double lo, double hi) {
    return hi - lo > 1e-12 ? (x - lo) / (hi - lo) : 1.0;
  };
  for (Chen2024Candidate& c : out) {
    const Range& r = ranges[c.pose.pile];
    c.normalized.convexity = unit(c.raw.convexity, r.lo.convexity, r.hi.convexity);
    c.normalized.inclination = unit(c.raw.inclination, r.lo.inclination, r.hi.inclination);
    c.normalized.slope = unit(c.raw.slope, r.lo.slope, r.hi.slope);
    c.normalized.distance = r.hi.distance - r.lo.distance > 1e-12
                                ? 1 - unit(c.raw.distance, r.lo.distance, r.hi.distance)
                                : 1.0;
    c.score = config.w_convexity * c.normalized.convexity +
              config.w_inclination * c.normalized.inclination +
              config.w_slope * c.normalized.slope + config.w_distance * c.normalized.distance;
  }
  std::stable_sort(
      out.begin(), out.end(),
      [](const Chen2024Candidate& a, const Chen2024Candidate& b) { return a.score > b.score; });
  return out;
}

}  // namespace autoshovel::planning
