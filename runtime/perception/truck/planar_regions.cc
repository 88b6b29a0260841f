#include "runtime/perception/truck/planar_regions.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <string>

namespace autoshovel::perception {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
// Planes steeper than this (|n_z| below) get a horizontal u axis: walls are measured along
// their length and up their height.
constexpr double kSteepNormalZ = 0.7;
// Two segments whose lines are closer than this span no plane (they are one line) [m].
constexpr double kMinPairSpread = 0.01;

// The scanline ladder test: nearly parallel, overlapping along their common direction, and close.
bool Linkable(const LineSegment& a, const LineSegment& b, double cos_max_angle,
              double max_distance) {
  const double c = a.direction.dot(b.direction);
  if (std::abs(c) < cos_max_angle) return false;
  const Eigen::Vector3d m =
      (c >= 0 ? a.direction + b.direction : Eigen::Vector3d(a.direction - b.direction))
          .normalized();
  const auto interval = [&m](const LineSegment& s) {
    const double p = s.p_world_start.dot(m);
    const double q = s.p_world_end.dot(m);
    return std::pair{std::min(p, q), std::max(p, q)};
  };
  const auto [a0, a1] = interval(a);
  const auto [b0, b1] = interval(b);
  if (std::min(a1, b1) - std::max(a0, b0) <= 0) return false;
  const Eigen::Vector3d d = b.centroid - a.centroid;
  return (d - d.dot(m) * m).norm() <= max_distance;
}

double PlaneDistance(const PlaneFit& plane, const Eigen::Vector3d& p) {
  return std::abs(plane.normal.dot(p - plane.centroid));
}

bool EndPointsOnPlane(const PlaneFit& plane, const LineSegment& s, double tolerance) {
  return PlaneDistance(plane, s.p_world_start) <= tolerance &&
         PlaneDistance(plane, s.p_world_end) <= tolerance;
}

PlanarRegion Describe(const std::vector<LineSegment>& segments, std::vector<int> members,
                      const PointMoments& moments) {
  PlanarRegion region;
  region.segments = std::move(members);
  region.moments = moments;
  region.num_points = moments.count();
  const PlaneFit fit = FitPlane(moments, 0.0);
  region.centroid = fit.centroid;
  region.rms_residual = fit.rms_residual;

  Eigen::Vector3d sensor = Eigen::Vector3d::Zero();
  std::vector<int> scanlines;
  for (int s : region.segments) {
    sensor += segments[s].p_world_sensor;
    scanlines.push_back(segments[s].scanline);
  }
  region.p_world_sensor_mean = sensor / static_cast<double>(region.segments.size());
  std::sort(scanlines.begin(), scanlines.end());
  region.num_scanlines =
      static_cast<int>(std::unique(scanlines.begin(), scanlines.end()) - scanlines.begin());

  region.normal = fit.normal;
  if (region.normal.dot(region.p_world_sensor_mean - region.centroid) < 0) {
    region.normal = -region.normal;
  }
  if (std::abs(region.normal.z()) < kSteepNormalZ) {
    region.axis_u = Eigen::Vector3d::UnitZ().cross(region.normal).normalized();
  } else {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(moments.Covariance());
    const Eigen::Vector3d major = solver.eigenvectors().col(2);
    region.axis_u = (major - major.dot(region.normal) * region.normal).normalized();
  }
  region.axis_v = region.normal.cross(region.axis_u);

  region.u_min = region.v_min = region.z_min = std::numeric_limits<double>::infinity();
  region.u_max = region.v_max = region.z_max = -std::numeric_limits<double>::infinity();
  std::vector<double> tops;
  std::vector<double> bottoms;
  for (int s : region.segments) {
    for (const Eigen::Vector3d& p : {segments[s].p_world_start, segments[s].p_world_end}) {
      const Eigen::Vector3d d = p - region.centroid;
      region.u_min = std::min(region.u_min, d.dot(region.axis_u));
      region.u_max = std::max(region.u_max, d.dot(region.axis_u));
      region.v_min = std::min(region.v_min, d.dot(region.axis_v));
      region.v_max = std::max(region.v_max, d.dot(region.axis_v));
      region.z_min = std::min(region.z_min, p.z());
      region.z_max = std::max(region.z_max, p.z());
    }
    tops.push_back(std::max(segments[s].p_world_start.z(), segments[s].p_world_end.z()));
    bottoms.push_back(std::min(segments[s].p_world_start.z(), segments[s].p_world_end.z()));
  }
  const auto median = [](std::vector<double>& values) {
    const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), mid, values.end());
    return *mid;
  };
  region.top_z = median(tops);
  region.bottom_z = median(bottoms);
  return region;
}

}  // namespace

void Validate(const PlanarRegionParams& params) {
  const auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("PlanarRegionParams: " + what);
  };
  require(params.max_scanline_gap >= 1, "max_scanline_gap must be at least 1");
  require(std::isfinite(params.max_link_distance) && params.max_link_distance > 0,
          "max_link_distance must be finite and positive");
  require(std::isfinite(params.max_link_angle_deg) && params.max_link_angle_deg > 0 &&
              params.max_link_angle_deg < 90,
          "max_link_angle_deg must lie in (0, 90)");
  require(std::isfinite(params.plane_tolerance) && params.plane_tolerance > 0,
          "plane_tolerance must be finite and positive");
  require(std::isfinite(params.max_plane_rms) && params.max_plane_rms > 0,
          "max_plane_rms must be finite and positive");
  require(params.min_segments >= 2, "min_segments must be at least 2");
  require(params.min_points >= 3, "min_points must be at least 3");
}

// §4.1: segments of different scanlines that lie in one plane make one planar region.
std::vector<PlanarRegion> GroupPlanarRegions(const std::vector<LineSegment>& segments,
                                             const PlanarRegionParams& params) {
  Validate(params);
  int max_scanline = -1;
  for (const LineSegment& s : segments) {
    if (s.scanline < 0) throw std::invalid_argument("GroupPlanarRegions: negative scanline index");
    max_scanline = std::max(max_scanline, s.scanline);
  }
  std::vector<std::vector<int>> by_scanline(static_cast<std::size_t>(max_scanline + 1));
  for (int i = 0; i < static_cast<int>(segments.size()); ++i) {
    by_scanline[segments[i].scanline].push_back(i);
  }

  // Seeds in order of decreasing support: a region starts from its most reliable segment.
  std::vector<int> order(segments.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&segments](int a, int b) {
    return segments[a].points.size() > segments[b].points.size();
  });

  const double cos_link = std::cos(params.max_link_angle_deg * kDegToRad);
  std::vector<bool> used(segments.size(), false);
  std::vector<PlanarRegion> regions;
  for (int seed : order) {
    if (used[seed]) continue;
    used[seed] = true;
    std::vector<int> members{seed};
    PointMoments moments = segments[seed].moments;
    PlaneFit plane;  // not ok until a second segment spans the plane
    for (std::size_t next = 0; next < members.size(); ++next) {
      const LineSegment& from = segments[members[next]];
      const int lo = std::max(0, from.scanline - params.max_scanline_gap);
      const int hi = std::min(max_scanline, from.scanline + params.max_scanline_gap);
      for (int line = lo; line <= hi; ++line) {
        if (line == from.scanline) continue;
        for (int candidate : by_scanline[line]) {
          if (used[candidate]) continue;
          const LineSegment& s = segments[candidate];
          if (!Linkable(from, s, cos_link, params.max_link_distance)) continue;
          if (plane.ok && !EndPointsOnPlane(plane, s, params.plane_tolerance)) continue;
          PointMoments joint = moments;
          joint.Add(s.moments);
          const PlaneFit joint_plane = FitPlane(joint, kMinPairSpread);
          if (!joint_plane.ok || joint_plane.rms_residual > params.max_plane_rms) continue;
          if (!EndPointsOnPlane(joint_plane, s, params.plane_tolerance) ||
              !EndPointsOnPlane(joint_plane, from, params.plane_tolerance)) {
            continue;
          }
          used[candidate] = true;
          members.push_back(candidate);
          moments = joint;
          plane = joint_plane;
        }
      }
    }
    if (static_cast<int>(members.size()) < params.min_segments ||
        moments.count() < params.min_points) {
      continue;
    }
    regions.push_back(Describe(segments, std::move(members), moments));
  }
  std::stable_sort(
      regions.begin(), regions.end(),
      [](const PlanarRegion& a, const PlanarRegion& b) { return a.num_points > b.num_points; });
  return regions;
}

double GroundEstimate::HeightAbove(const Eigen::Vector3d& p_world) const {
  if (!found) return std::numeric_limits<double>::quiet_NaN();
  return normal.dot(p_world) - offset;
}

GroundEstimate EstimateGround(const std::vector<PlanarRegion>& regions, double max_tilt_deg) {
  if (!std::isfinite(max_tilt_deg) || max_tilt_deg <= 0 || max_tilt_deg >= 90) {
    throw std::invalid_argument("EstimateGround: max_tilt_deg must lie in (0, 90)");
  }
  const double min_normal_z = std::cos(max_tilt_deg * kDegToRad);
  GroundEstimate ground;
  for (int i = 0; i < static_cast<int>(regions.size()); ++i) {
    const PlanarRegion& r = regions[i];
    if (std::abs(r.normal.z()) < min_normal_z) continue;
    if (ground.found && r.num_points <= regions[ground.region].num_points) continue;
    ground.found = true;
    ground.region = i;
    ground.normal = r.normal.z() > 0 ? r.normal : Eigen::Vector3d(-r.normal);
    ground.offset = ground.normal.dot(r.centroid);
  }
  return ground;
}

}  // namespace autoshovel::perception
