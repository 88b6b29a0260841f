#include "runtime/perception/truck/bed_fit.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string>
#include <tuple>

namespace autoshovel::perception {
namespace {

// Segments whose centroid lies this far inside the ends count for the rim (not the headboard's
// raised sides, not the cab) [m].
constexpr double kRimEndMargin = 0.15;
// The scanline spacing at a wall's end is the median of this many gaps between scanlines.
constexpr std::size_t kEndGaps = 3;
// Fewer wall segments between the ends than this give no rim estimate of their own.
constexpr std::size_t kMinRimSegments = 3;
// Side-wall segments farther than the thickest wall plus this beyond a matched end wall's inside
// are not the bed's [m].
constexpr double kEndWallSlack = 0.1;
// A gap between scanlines along a side wall wider than this many local spacings (the median of
// up to kLocalGaps gaps on either side), and at least kMinRunBreak, ends the wall [-, m].
constexpr double kRunBreakSpacings = 2.5;
constexpr double kMinRunBreak = 0.2;
constexpr std::size_t kLocalGaps = 4;
// Unmatched regions within this angle and distance of the far wall's plane are fragments of it
// (a segment lost in two neighbouring scanlines splits a wall) [deg, m].
constexpr double kFragmentAngleDeg = 3.0;
constexpr double kFragmentDistance = 0.1;
// A single segment joins the near wall if it is within this angle of the wall's plane, its
// centroid within kFragmentDistance and its ends within twice that (looser than for regions:
// short segments at a wall's end are noisier) [deg].
constexpr double kSegmentAngleDeg = 10.0;

double Median(std::vector<double> values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

// Plan scatter of one face's returns about their own centroid (not divided by n: faces with more
// returns weigh more in the orientation fit).
Eigen::Matrix2d PlanScatter(const std::vector<LineSegment>& segments,
                            const std::vector<int>& region_segments) {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  Eigen::Matrix2d outer = Eigen::Matrix2d::Zero();
  int count = 0;
  for (int s : region_segments) {
    for (const Eigen::Vector3d& p : segments[s].points) {
      const Eigen::Vector2d q = p.head<2>();
      sum += q;
      outer.noalias() += q * q.transpose();
      ++count;
    }
  }
  if (count == 0) return Eigen::Matrix2d::Zero();
  const Eigen::Vector2d mean = sum / count;
  return outer - count * mean * mean.transpose();
}

double MeanProjection(const std::vector<LineSegment>& segments, const std::vector<int>& seg_ids,
                      const Eigen::Vector2d& axis) {
  double sum = 0;
  int count = 0;
  for (int s : seg_ids) {
    for (const Eigen::Vector3d& p : segments[s].points) {
      sum += axis.dot(p.head<2>());
      ++count;
    }
  }
  return count > 0 ? sum / count : std::numeric_limits<double>::quiet_NaN();
}

// Scanline positions along `axis`, in increasing order, with the scanline: each scanline is at
// the position of its segment with the most returns (a wall and the wheel below it may be two
// segments of one scanline; the wheel's face, set back from the wall's, is cut elsewhere by the
// oblique scan plane).
std::vector<std::pair<double, int>> ScanlinePositions(const std::vector<LineSegment>& segments,
                                                      const std::vector<int>& seg_ids,
                                                      const Eigen::Vector2d& axis) {
  std::map<int, int> dominant;  // scanline → segment with the most returns
  for (int s : seg_ids) {
    const LineSegment& seg = segments[static_cast<std::size_t>(s)];
    const auto [it, inserted] = dominant.emplace(seg.scanline, s);
    if (!inserted &&
        seg.points.size() > segments[static_cast<std::size_t>(it->second)].points.size()) {
      it->second = s;
    }
  }
  std::vector<std::pair<double, int>> positions;
  for (const auto& [line, s] : dominant) {
    positions.emplace_back(axis.dot(segments[static_cast<std::size_t>(s)].centroid.head<2>()),
                           line);
  }
  std::sort(positions.begin(), positions.end());
  return positions;
}

// Keeps the contiguous run of scanlines along `axis` that holds most of the `core` segments'
// returns (those of the matched region). Scanlines hit a wall at a spacing that changes only
// slowly along it, so a gap of several local spacings (the median of the neighbouring gaps)
// separates the body's side from a cab side or other coplanar surface that region growing or
// fragment absorption joined to it; one scanline missing (a gap of two spacings) does not.
void KeepCoreRun(const std::vector<LineSegment>& segments, const Eigen::Vector2d& axis,
                 const std::vector<int>& core, std::vector<int>& ids) {
  const std::vector<std::pair<double, int>> positions = ScanlinePositions(segments, ids, axis);
  if (positions.size() < 3) return;
  std::vector<double> gaps;
  for (std::size_t i = 1; i < positions.size(); ++i) {
    gaps.push_back(positions[i].first - positions[i - 1].first);
  }
  // run[i]: the run scanline i belongs to.
  std::vector<int> run(positions.size(), 0);
  for (std::size_t i = 0; i < gaps.size(); ++i) {
    std::vector<double> around;
    for (std::size_t j = i >= kLocalGaps ? i - kLocalGaps : 0;
         j < std::min(gaps.size(), i + kLocalGaps + 1); ++j) {
      if (j != i) around.push_back(gaps[j]);
    }
    const bool cut = gaps[i] > std::max(kMinRunBreak, kRunBreakSpacings * Median(around));
    run[i + 1] = run[i] + (cut ? 1 : 0);
  }
  std::map<int, int> run_of_line;
  for (std::size_t i = 0; i < positions.size(); ++i) run_of_line[positions[i].second] = run[i];
  std::map<int, std::size_t> core_returns;  // run → returns of core segments
  for (int s : core) {
    const auto it = run_of_line.find(segments[static_cast<std::size_t>(s)].scanline);
    if (it != run_of_line.end()) {
      core_returns[it->second] += segments[static_cast<std::size_t>(s)].points.size();
    }
  }
  if (core_returns.empty()) return;
  const int keep =
      std::max_element(core_returns.begin(), core_returns.end(), [](const auto& a, const auto& b) {
        return a.second < b.second;
      })->first;
  std::erase_if(ids, [&](int s) {
    return run_of_line.at(segments[static_cast<std::size_t>(s)].scanline) != keep;
  });
}

std::vector<int> SegmentsOf(const std::vector<PlanarRegion>& regions,
                            const std::vector<int>& region_ids) {
  std::vector<int> out;
  for (int r : region_ids)
    out.insert(out.end(), regions[r].segments.begin(), regions[r].segments.end());
  return out;
}

// Extreme scanline positions of a face along `axis`, each pushed outward by half the local
// scanline spacing there (the median of the last few gaps between scanlines: spacing grows toward
// a wall's far end, where the beam grazes it).
std::pair<double, double> ExtentAlong(const std::vector<LineSegment>& segments,
                                      const std::vector<int>& seg_ids,
                                      const Eigen::Vector2d& axis) {
  const std::vector<std::pair<double, int>> positions = ScanlinePositions(segments, seg_ids, axis);
  std::vector<double> gaps;
  for (std::size_t i = 1; i < positions.size(); ++i) {
    gaps.push_back(positions[i].first - positions[i - 1].first);
  }
  if (gaps.empty()) return {positions.front().first, positions.back().first};
  const std::size_t n = std::min<std::size_t>(kEndGaps, gaps.size());
  const double low_half = 0.5 * Median(std::vector<double>(gaps.begin(), gaps.begin() + n));
  const double high_half = 0.5 * Median(std::vector<double>(gaps.end() - n, gaps.end()));
  return {positions.front().first - low_half, positions.back().first + high_half};
}

// Regions (far wall) and single segments (near wall) that belong to a matched side wall but were
// not part of its region.
void AbsorbFragments(const Interpretation& interpretation, const std::vector<PlanarRegion>& regions,
                     const std::vector<LineSegment>& segments, const TruckBedModel& model,
                     const GroundEstimate& ground, BedFit& fit) {
  const auto index = [](BedFace face) { return static_cast<std::size_t>(FaceIndex(face)); };
  // Far wall: whole regions that could be the far wall and lie in its plane.
  const double cos_fragment = std::cos(kFragmentAngleDeg * std::numbers::pi / 180.0);
  const PlanarRegion& far_wall = regions[interpretation[BedFace::kFarSide]];
  for (int r = 0; r < static_cast<int>(regions.size()); ++r) {
    if (std::find(interpretation.region.begin(), interpretation.region.end(), r) !=
        interpretation.region.end()) {
      continue;
    }
    if (UnaryConsistent(model, BedFace::kFarSide, regions[r], ground) &&
        regions[r].normal.dot(far_wall.normal) >= cos_fragment &&
        std::abs(far_wall.normal.dot(regions[r].centroid - far_wall.centroid)) <=
            kFragmentDistance) {
      fit.face_regions[index(BedFace::kFarSide)].push_back(r);
    }
  }
  for (BedFace face : kAllBedFaces) {
    fit.face_segments[index(face)] = SegmentsOf(regions, fit.face_regions[index(face)]);
  }
  // Near wall: single segments in its plane, whatever region they fell into (region growing may
  // have split the wall or given its end to a flush cab side, cut off again by KeepCoreRun).
  // Their tops must be at the rim or up to a headboard's rise above it: not wheels.
  const PlanarRegion& near_wall = regions[interpretation[BedFace::kNearSide]];
  std::vector<bool> taken(segments.size(), false);
  for (const std::vector<int>& ids : fit.face_segments) {
    for (int id : ids) taken[static_cast<std::size_t>(id)] = true;
  }
  const double sin_segment = std::sin(kSegmentAngleDeg * std::numbers::pi / 180.0);
  const auto off_plane = [&near_wall](const Eigen::Vector3d& p) {
    return std::abs(near_wall.normal.dot(p - near_wall.centroid));
  };
  for (int id = 0; id < static_cast<int>(segments.size()); ++id) {
    const LineSegment& seg = segments[static_cast<std::size_t>(id)];
    if (taken[static_cast<std::size_t>(id)]) continue;
    const double top = std::max(seg.p_world_start.z(), seg.p_world_end.z());
    if (std::abs(seg.direction.dot(near_wall.normal)) <= sin_segment &&
        off_plane(seg.centroid) <= kFragmentDistance &&
        off_plane(seg.p_world_start) <= 2 * kFragmentDistance &&
        off_plane(seg.p_world_end) <= 2 * kFragmentDistance &&
        top >= near_wall.top_z - model.distance_tolerance &&
        top <= near_wall.top_z + model.max_headboard_rise + model.distance_tolerance) {
      fit.face_segments[index(BedFace::kNearSide)].push_back(id);
    }
  }
}

// The bed's plan axes and ends from the current face segments.
struct PlanAxes {
  Eigen::Vector2d n = Eigen::Vector2d::UnitX();  ///< side-wall normal, toward the sensor
  Eigen::Vector2d f = Eigen::Vector2d::UnitY();  ///< along the bed, toward the front
  double front = 0;                              ///< f · p of the front end's inside [m]
  double rear = 0;                               ///< f · p of the rear end's inside [m]
};

PlanAxes SolvePlanAxes(const Interpretation& interpretation,
                       const std::vector<PlanarRegion>& regions,
                       const std::vector<LineSegment>& segments, const TruckBedModel& model,
                       const BedFit& fit) {
  const auto segs = [&fit](BedFace face) -> const std::vector<int>& {
    return fit.face_segments[static_cast<std::size_t>(FaceIndex(face))];
  };
  const auto matched = [&interpretation](BedFace face) { return interpretation[face] >= 0; };
  // Orientation: rectangle fit over all wall returns (see the header).
  const Eigen::Matrix2d side_scatter = PlanScatter(segments, segs(BedFace::kNearSide)) +
                                       PlanScatter(segments, segs(BedFace::kFarSide));
  const Eigen::Matrix2d end_scatter = PlanScatter(segments, segs(BedFace::kHeadboard)) +
                                      PlanScatter(segments, segs(BedFace::kTailgate));
  Eigen::Matrix2d rot90;
  rot90 << 0, -1, 1, 0;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(
      side_scatter + rot90.transpose() * end_scatter * rot90);
  PlanAxes axes;
  axes.n = solver.eigenvectors().col(0).normalized();
  if (axes.n.dot(regions[interpretation[BedFace::kNearSide]].normal.head<2>()) < 0) {
    axes.n = -axes.n;
  }
  axes.f = Eigen::Vector2d(-axes.n.y(), axes.n.x());  // z × n
  // An end wall's inside faces into the bed: the headboard's rearward, the tailgate's forward.
  if (matched(BedFace::kHeadboard)) {
    if (axes.f.dot(regions[interpretation[BedFace::kHeadboard]].normal.head<2>()) > 0) {
      axes.f = -axes.f;
    }
  } else if (matched(BedFace::kTailgate)) {
    if (axes.f.dot(regions[interpretation[BedFace::kTailgate]].normal.head<2>()) < 0) {
      axes.f = -axes.f;
    }
  }
  // Ends: matched end walls, otherwise the near outside face's extent.
  std::tie(axes.rear, axes.front) = ExtentAlong(segments, segs(BedFace::kNearSide), axes.f);
  if (matched(BedFace::kHeadboard)) {
    axes.front = MeanProjection(segments, segs(BedFace::kHeadboard), axes.f);
  } else if (matched(BedFace::kTailgate)) {
    // The front is known to be this end: the near outside face runs over the headboard's end.
    axes.front -= model.nominal_wall_thickness;
  }
  if (matched(BedFace::kTailgate)) {
    axes.rear = MeanProjection(segments, segs(BedFace::kTailgate), axes.f);
  }
  return axes;
}

// Median top of the side-wall segments between the ends (not the raised headboard sides). The
// beam that last hits a wall grazes the top of its plate, so the top return is at the rim itself.
double EstimateRim(const std::vector<LineSegment>& segments, const BedFit& fit,
                   const PlanAxes& axes, double fallback) {
  std::vector<double> estimates;
  for (BedFace face : {BedFace::kNearSide, BedFace::kFarSide}) {
    std::vector<double> tops;
    for (int s : fit.face_segments[static_cast<std::size_t>(FaceIndex(face))]) {
      const LineSegment& seg = segments[static_cast<std::size_t>(s)];
      const double along = axes.f.dot(seg.centroid.head<2>());
      if (along < axes.rear + kRimEndMargin || along > axes.front - kRimEndMargin) continue;
      tops.push_back(std::max(seg.p_world_start.z(), seg.p_world_end.z()));
    }
    if (tops.size() >= kMinRimSegments) estimates.push_back(Median(tops));
  }
  if (estimates.empty()) return fallback;
  double sum = 0;
  for (double z : estimates) sum += z;
  return sum / static_cast<double>(estimates.size());
}

}  // namespace

double BedFit::YawRad() const {
  const Eigen::Vector3d x = T_world_bed.linear().col(0);
  return std::atan2(x.y(), x.x());
}

std::array<Eigen::Vector3d, 4> BedFit::CornersWorld() const {
  const double hl = 0.5 * length;
  const double hw = 0.5 * width;
  return {T_world_bed * Eigen::Vector3d(hl, hw, 0), T_world_bed * Eigen::Vector3d(hl, -hw, 0),
          T_world_bed * Eigen::Vector3d(-hl, -hw, 0), T_world_bed * Eigen::Vector3d(-hl, hw, 0)};
}

void BedFit::Reverse() {
  T_world_bed.linear() =
      T_world_bed.linear() * Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitZ()).matrix();
  std::swap(front_measured, rear_measured);
}

void BedFit::TrimFront(double amount) {
  length -= amount;
  T_world_bed.translation() -= 0.5 * amount * T_world_bed.linear().col(0);
}

// §4.1: the corner points of the bed opening give the bed's position and orientation.
BedFit FitBed(const Interpretation& interpretation, const std::vector<PlanarRegion>& regions,
              const std::vector<LineSegment>& segments, const TruckBedModel& model,
              const GroundEstimate& ground) {
  for (BedFace face : kAllBedFaces) {
    const int r = interpretation[face];
    if (r >= static_cast<int>(regions.size())) {
      throw std::invalid_argument("FitBed: the " + std::string(BedFaceName(face)) +
                                  " names region " + std::to_string(r) + " of " +
                                  std::to_string(regions.size()));
    }
  }
  if (interpretation[BedFace::kNearSide] < 0 || interpretation[BedFace::kFarSide] < 0) {
    throw std::invalid_argument("FitBed: the interpretation needs both side walls");
  }
  const auto index = [](BedFace face) { return static_cast<std::size_t>(FaceIndex(face)); };
  BedFit fit;
  for (BedFace face : kAllBedFaces) {
    if (interpretation[face] >= 0) fit.face_regions[index(face)] = {interpretation[face]};
  }
  AbsorbFragments(interpretation, regions, segments, model, ground, fit);
  fit.front_measured = interpretation[BedFace::kHeadboard] >= 0;
  fit.rear_measured = interpretation[BedFace::kTailgate] >= 0;
  fit.front_from_end_wall = fit.front_measured || fit.rear_measured;

  PlanAxes axes = SolvePlanAxes(interpretation, regions, segments, model, fit);
  // The near outside face is one contiguous wall: drop what lies beyond a gap (a flush cab side).
  std::vector<int>& near_ids = fit.face_segments[index(BedFace::kNearSide)];
  const std::size_t near_before = near_ids.size();
  KeepCoreRun(segments, axes.f, regions[interpretation[BedFace::kNearSide]].segments, near_ids);
  bool refit = near_ids.size() != near_before;
  // Side-wall segments beyond a matched end wall belong to something in the wall's plane (a cab
  // side flush with the body).
  const double reach = model.wall_thickness.max + kEndWallSlack;
  for (BedFace face : {BedFace::kNearSide, BedFace::kFarSide}) {
    std::vector<int>& ids = fit.face_segments[index(face)];
    const auto beyond = [&](int id) {
      const double along = axes.f.dot(segments[static_cast<std::size_t>(id)].centroid.head<2>());
      return (fit.front_measured && along > axes.front + reach) ||
             (fit.rear_measured && along < axes.rear - reach);
    };
    const std::size_t before = ids.size();
    ids.erase(std::remove_if(ids.begin(), ids.end(), beyond), ids.end());
    refit = refit || ids.size() != before;
  }
  if (near_ids.empty() || fit.face_segments[index(BedFace::kFarSide)].empty()) return fit;
  if (refit) axes = SolvePlanAxes(interpretation, regions, segments, model, fit);

  // Across the bed: the near wall is seen from outside, the far wall from inside.
  const double near_inside =
      MeanProjection(segments, near_ids, axes.n) - model.nominal_wall_thickness;
  const double far_inside =
      MeanProjection(segments, fit.face_segments[index(BedFace::kFarSide)], axes.n);
  fit.width = near_inside - far_inside;
  fit.length = axes.front - axes.rear;
  const Eigen::Vector2d centre =
      0.5 * (near_inside + far_inside) * axes.n + 0.5 * (axes.front + axes.rear) * axes.f;
  fit.rim_z = EstimateRim(segments, fit, axes, regions[interpretation[BedFace::kNearSide]].top_z);
  if (interpretation[BedFace::kFloor] >= 0) {
    // The centroid's height: the floor is level within the model's tolerance, and a narrow strip's
    // tilt, extrapolated to the centre, would only add noise.
    fit.floor_z = regions[interpretation[BedFace::kFloor]].centroid.z();
  }
  if (ground.found) {
    fit.ground_z = (ground.offset - ground.normal.head<2>().dot(centre)) / ground.normal.z();
  }
  fit.T_world_bed = Eigen::Isometry3d::Identity();
  fit.T_world_bed.linear() =
      Eigen::AngleAxisd(std::atan2(axes.f.y(), axes.f.x()), Eigen::Vector3d::UnitZ()).matrix();
  fit.T_world_bed.translation() = Eigen::Vector3d(centre.x(), centre.y(), fit.rim_z);
  fit.ok = std::isfinite(fit.width) && std::isfinite(fit.length) && fit.width > 0 &&
           fit.length > 0 && std::isfinite(fit.rim_z);
  return fit;
}

}  // namespace autoshovel::perception
