// Plan-view clearance between the loader footprint and obstacle boxes (safety_margin.h).
#include "runtime/app/safety_margin.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace autoshovel::app {

namespace {

Quad Rectangle(const Eigen::Vector2d& origin, double heading, double from, double to,
               double half_width) {
  const Eigen::Vector2d u(std::cos(heading), std::sin(heading)), n(-u.y(), u.x());
  return {origin + from * u - half_width * n, origin + to * u - half_width * n,
          origin + to * u + half_width * n, origin + from * u + half_width * n};
}

double PointSegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                            const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-18), 0.0, 1.0);
  return (a + t * ab - p).norm();
}

// Separating axis test over both quads' edge normals.
bool Overlap(const Quad& a, const Quad& b) {
  for (const Quad* q : {&a, &b}) {
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector2d e = (*q)[(i + 1) % 4] - (*q)[i];
      const Eigen::Vector2d axis(-e.y(), e.x());
      double a_lo = INFINITY, a_hi = -INFINITY, b_lo = INFINITY, b_hi = -INFINITY;
      for (const auto& p : a)
        a_lo = std::min(a_lo, p.dot(axis)), a_hi = std::max(a_hi, p.dot(axis));
      for (const auto& p : b)
        b_lo = std::min(b_lo, p.dot(axis)), b_hi = std::max(b_hi, p.dot(axis));
      if (a_hi < b_lo || b_hi < a_lo) return false;
    }
  }
  return true;
}

}  // namespace

std::array<Quad, 2> FootprintQuads(const perception::MachineFootprint& f) {
  return {
      Rectangle(f.hinge_xy, f.heading_front, 0.0, f.front_length, f.half_width),
      Rectangle(f.hinge_xy, f.heading_front - f.articulation, -f.rear_length, 0.0, f.half_width)};
}

Quad BoxQuad(const plant::OrientedBox& box) {
  const Eigen::Vector2d c = box.center.head<2>();
  return Rectangle(c - box.half_extents.x() * Eigen::Vector2d(std::cos(box.yaw), std::sin(box.yaw)),
                   box.yaw, 0.0, 2 * box.half_extents.x(), box.half_extents.y());
}

double QuadDistance(const Quad& a, const Quad& b) {
  if (Overlap(a, b)) return 0.0;
  double d = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      d = std::min(d, PointSegmentDistance(a[i], b[j], b[(j + 1) % 4]));
      d = std::min(d, PointSegmentDistance(b[j], a[i], a[(i + 1) % 4]));
    }
  }
  return d;
}

Clearance FootprintClearance(const perception::MachineFootprint& footprint,
                             const std::vector<plant::OrientedBox>& obstacles) {
  Clearance out;
  out.distance = std::numeric_limits<double>::infinity();
  const std::array<Quad, 2> quads = FootprintQuads(footprint);
  for (std::size_t k = 0; k < obstacles.size(); ++k) {
    const Quad box = BoxQuad(obstacles[k]);
    for (const Quad& q : quads) {
      const double d = QuadDistance(q, box);
      if (d < out.distance) out.distance = d, out.obstacle = static_cast<int>(k);
    }
  }
  return out;
}

}  // namespace autoshovel::app
