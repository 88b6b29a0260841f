#include "runtime/perception/truck/line_segmentation.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace autoshovel::perception {
namespace {

using Points = std::vector<Eigen::Vector3d>;

// The core line of a segment leaves 1/kCoreFraction of its returns off at each end.
constexpr int kCoreFraction = 10;

// Inclusive index interval [first, last] into a run's points. Neighbouring intervals share their
// end point (the corner belongs to both lines), as in the classic iterative end-point fit.
struct Interval {
  int first = 0;
  int last = 0;
};

double DistanceToChord(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                       const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double length = ab.norm();
  if (length < 1e-12) return (p - a).norm();
  return (p - a).cross(ab).norm() / length;
}

PointMoments MomentsOf(const Points& points, const Interval& interval) {
  PointMoments moments;
  for (int i = interval.first; i <= interval.last; ++i) moments.Add(points[i]);
  return moments;
}

// Largest perpendicular distance of the interval's points from its least-squares line.
double MaxResidual(const Points& points, const Interval& interval, const LineFit& fit) {
  double worst = 0;
  for (int i = interval.first; i <= interval.last; ++i) {
    const Eigen::Vector3d d = points[i] - fit.centroid;
    worst = std::max(worst, (d - d.dot(fit.direction) * fit.direction).norm());
  }
  return worst;
}

// Split: cut at the point farthest from the chord until every chord fits (iterative end-point
// fit; an explicit stack keeps deep recursion off long runs).
std::vector<Interval> Split(const Points& points, const Interval& run, double tolerance) {
  std::vector<Interval> done;
  std::vector<Interval> stack{run};
  while (!stack.empty()) {
    const Interval interval = stack.back();
    stack.pop_back();
    int worst_index = -1;
    double worst = tolerance;
    for (int i = interval.first + 1; i < interval.last; ++i) {
      const double d = DistanceToChord(points[i], points[interval.first], points[interval.last]);
      if (d > worst) {
        worst = d;
        worst_index = i;
      }
    }
    if (worst_index < 0) {
      done.push_back(interval);
    } else {
      // Push the right half first so that the left one is finished first: `done` stays ordered.
      stack.push_back({worst_index, interval.last});
      stack.push_back({interval.first, worst_index});
    }
  }
  return done;
}

// Merge: the chord test of the split is a cheap stand-in for the least-squares line; join
// neighbours as long as their joint least-squares line keeps every point within tolerance,
// best-fitting pair first.
std::vector<Interval> Merge(const Points& points, std::vector<Interval> intervals,
                            double tolerance) {
  while (intervals.size() > 1) {
    int best = -1;
    double best_rms = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i + 1 < intervals.size(); ++i) {
      const Interval joint{intervals[i].first, intervals[i + 1].last};
      const LineFit fit = FitLine(MomentsOf(points, joint));
      if (!fit.ok || fit.rms_residual >= best_rms) continue;
      if (MaxResidual(points, joint, fit) > tolerance) continue;
      best = static_cast<int>(i);
      best_rms = fit.rms_residual;
    }
    if (best < 0) break;
    intervals[best].last = intervals[best + 1].last;
    intervals.erase(intervals.begin() + best + 1);
  }
  return intervals;
}

double Residual(const Eigen::Vector3d& p, const LineFit& fit) {
  const Eigen::Vector3d d = p - fit.centroid;
  return (d - d.dot(fit.direction) * fit.direction).norm();
}

// Trim: a corner point, or a few returns from the next surface that stayed within the chord
// tolerance, tilt a segment's least-squares line. The line through the segment's core (a tenth
// of its returns left off at each end) is not tilted by them: end returns farther than
// `tolerance` (half the split tolerance, 2σ) from it are dropped, from each end inward.
Interval Trim(const Points& points, Interval interval, double tolerance, int min_points) {
  const int count = interval.last - interval.first + 1;
  const int skip = std::max(1, count / kCoreFraction);
  if (count - 2 * skip < std::max(min_points, 2)) return interval;
  const LineFit core = FitLine(MomentsOf(points, {interval.first + skip, interval.last - skip}));
  if (!core.ok) return interval;
  while (interval.last - interval.first + 1 > min_points &&
         Residual(points[interval.first], core) > tolerance) {
    ++interval.first;
  }
  while (interval.last - interval.first + 1 > min_points &&
         Residual(points[interval.last], core) > tolerance) {
    --interval.last;
  }
  return interval;
}

Eigen::Vector3d ProjectOntoLine(const Eigen::Vector3d& p, const LineFit& fit) {
  return fit.centroid + (p - fit.centroid).dot(fit.direction) * fit.direction;
}

}  // namespace

void Validate(const LineSegmentationParams& params) {
  const auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("LineSegmentationParams: " + what);
  };
  require(std::isfinite(params.split_tolerance) && params.split_tolerance > 0,
          "split_tolerance must be finite and positive");
  require(std::isfinite(params.jump_distance) && params.jump_distance > 0,
          "jump_distance must be finite and positive");
  require(std::isfinite(params.jump_range_fraction) && params.jump_range_fraction >= 0,
          "jump_range_fraction must be finite and non-negative");
  require(params.min_points >= 2, "min_points must be at least 2");
  require(std::isfinite(params.min_length) && params.min_length >= 0,
          "min_length must be finite and non-negative");
}

// §4.1: one scanline becomes a list of straight segments.
std::vector<LineSegment> SegmentScanline(const Scanline& scanline, int index,
                                         const LineSegmentationParams& params) {
  Validate(params);
  if (!scanline.p_world_sensor.allFinite()) {
    throw std::invalid_argument("SegmentScanline: scanline " + std::to_string(index) +
                                " has a non-finite sensor origin");
  }
  Points points;
  points.reserve(scanline.points.size());
  for (const ScanPoint& point : scanline.points) {
    if (IsUsable(point)) points.push_back(point.p_world);
  }

  // Runs of returns without a range jump: an occluding edge must never be bridged by a line.
  std::vector<Interval> runs;
  int run_start = 0;
  for (int i = 1; i <= static_cast<int>(points.size()); ++i) {
    bool cut = i == static_cast<int>(points.size());
    if (!cut) {
      const double range = (points[i] - scanline.p_world_sensor).norm();
      cut = (points[i] - points[i - 1]).norm() >
            params.jump_distance + params.jump_range_fraction * range;
    }
    if (cut) {
      if (i - run_start >= params.min_points) runs.push_back({run_start, i - 1});
      run_start = i;
    }
  }

  std::vector<LineSegment> segments;
  for (const Interval& run : runs) {
    const std::vector<Interval> pieces =
        Merge(points, Split(points, run, params.split_tolerance), params.split_tolerance);
    for (const Interval& merged : pieces) {
      const Interval piece = Trim(points, merged, 0.5 * params.split_tolerance, params.min_points);
      const int count = piece.last - piece.first + 1;
      if (count < params.min_points) continue;
      LineSegment segment;
      segment.moments = MomentsOf(points, piece);
      const LineFit fit = FitLine(segment.moments);
      if (!fit.ok) continue;
      segment.scanline = index;
      segment.p_world_sensor = scanline.p_world_sensor;
      segment.centroid = fit.centroid;
      segment.p_world_start = ProjectOntoLine(points[piece.first], fit);
      segment.p_world_end = ProjectOntoLine(points[piece.last], fit);
      if (segment.Length() < params.min_length) continue;
      segment.direction = (segment.p_world_end - segment.p_world_start).normalized();
      segment.rms_residual = fit.rms_residual;
      segment.points.assign(points.begin() + piece.first, points.begin() + piece.last + 1);
      segments.push_back(std::move(segment));
    }
  }
  return segments;
}

std::vector<LineSegment> SegmentScanlines(const std::vector<Scanline>& scanlines,
                                          const LineSegmentationParams& params) {
  Validate(params);
  std::vector<LineSegment> segments;
  for (std::size_t i = 0; i < scanlines.size(); ++i) {
    std::vector<LineSegment> more = SegmentScanline(scanlines[i], static_cast<int>(i), params);
    std::move(more.begin(), more.end(), std::back_inserter(segments));
  }
  return segments;
}

}  // namespace autoshovel::perception
