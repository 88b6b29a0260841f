#include "runtime/perception/truck/truck_model.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

namespace autoshovel::perception {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
// How far the near wall's bottom edge may lie above the floor's top [m]: the bottom edge is the
// last return above a range jump, a return spacing (a few cm) above the true edge.
constexpr double kFloorEdgeTolerance = 0.1;

Eigen::Vector3d Horizontal(const Eigen::Vector3d& v) {
  const Eigen::Vector3d h(v.x(), v.y(), 0.0);
  const double norm = h.norm();
  return norm > 1e-9 ? Eigen::Vector3d(h / norm) : Eigen::Vector3d::UnitX();
}

struct Tolerances {
  double sin_angle;
  double cos_angle;
  double distance;
};

Tolerances TolerancesOf(const TruckBedModel& model) {
  const double angle = model.angle_tolerance_deg * kDegToRad;
  return {std::sin(angle), std::cos(angle), model.distance_tolerance};
}

bool IsVertical(const PlanarRegion& r, const Tolerances& tol) {
  return std::abs(r.normal.z()) <= tol.sin_angle;
}

// The extent of a region's u axis projected onto `direction`, as an ordered pair.
std::pair<double, double> ProjectedExtent(const PlanarRegion& r, const Eigen::Vector3d& direction) {
  const double a = r.UMinPoint().dot(direction);
  const double b = r.UMaxPoint().dot(direction);
  return {std::min(a, b), std::max(a, b)};
}

double Overlap(std::pair<double, double> a, std::pair<double, double> b) {
  return std::min(a.second, b.second) - std::max(a.first, b.first);
}

// Near outside and far inside: parallel, one bed width (plus the near wall's thickness) apart
// along the normal, side by side along the bed, rims at one height.
bool NearFar(const TruckBedModel& m, const Tolerances& tol, const PlanarRegion& near,
             const PlanarRegion& far) {
  if (Horizontal(near.normal).dot(Horizontal(far.normal)) < tol.cos_angle) return false;
  const Eigen::Vector3d n = Horizontal(near.normal + far.normal);
  const double separation = (near.centroid - far.centroid).dot(n);
  if (separation < m.inner_width.min + m.wall_thickness.min - tol.distance ||
      separation > m.inner_width.max + m.wall_thickness.max + tol.distance) {
    return false;
  }
  const Eigen::Vector3d along = Eigen::Vector3d::UnitZ().cross(n);
  if (Overlap(ProjectedExtent(near, along), ProjectedExtent(far, along)) <= 0) return false;
  return std::abs(near.top_z - far.top_z) <= tol.distance;
}

// A side wall and the floor: the floor lies behind the near outside / in front of the far inside,
// within one bed width, a wall height below the side's rim.
bool SideFloor(const TruckBedModel& m, const Tolerances& tol, const PlanarRegion& side, bool near,
               const PlanarRegion& floor) {
  const Eigen::Vector3d n = Horizontal(side.normal);
  const double offset = (floor.centroid - side.centroid).dot(n);
  // The floor's centroid lies inside the bed, on the inner side of the wall, within a width.
  const double reach = m.inner_width.max + (near ? m.wall_thickness.max : 0.0) + tol.distance;
  if (near ? (offset < -reach || offset > 0) : (offset < 0 || offset > reach)) return false;
  if (!m.wall_height.Contains(side.top_z - floor.centroid.z(), tol.distance)) return false;
  if (near) {
    // The near outside face spans the whole bed: the floor seen must lie along it.
    const double u = (floor.centroid - side.centroid).dot(side.axis_u);
    if (u < side.u_min - tol.distance || u > side.u_max + tol.distance) return false;
    // and it covers the floor's edge: its bottom edge is no higher than the floor (else the
    // "floor" is something under the body, such as the tops of the wheels).
    if (side.bottom_z > floor.centroid.z() + kFloorEdgeTolerance) return false;
  }
  return true;
}

// An end wall's inside and a side wall: perpendicular; the side reaches into the bed from the end
// wall (the end's normal points into the bed); the end wall lies between the side planes; its top
// is at the rim or, for a headboard, up to max_headboard_rise above it (a tailgate: at most
// max_tailgate_rise).
bool EndSide(const TruckBedModel& m, const Tolerances& tol, const PlanarRegion& end, bool headboard,
             const PlanarRegion& side, bool near) {
  const Eigen::Vector3d n_end = Horizontal(end.normal);
  const Eigen::Vector3d n_side = Horizontal(side.normal);
  if (std::abs(n_end.dot(n_side)) > tol.sin_angle) return false;
  const double end_plane = end.centroid.dot(n_end);
  const auto [side_lo, side_hi] = ProjectedExtent(side, n_end);
  if (near) {
    if (side_hi - end_plane < m.min_near_side_length) return false;
  } else {
    // The far inside face ends at the end wall's inside: it cannot continue behind it (by more
    // than stray returns at the corner, where a scanline may run on a little into the cab).
    if (side_hi - end_plane <= 0 || side_lo - end_plane < -(tol.distance + m.wall_thickness.max)) {
      return false;
    }
  }
  // The inside of an end wall stops at the floor, at most a wall height below the rim: this
  // tells a headboard from the back of a cab, which reaches down toward the chassis.
  if (end.z_min < side.top_z - m.wall_height.max - tol.distance) return false;
  const auto [end_lo, end_hi] = ProjectedExtent(end, n_side);
  const double side_plane = side.centroid.dot(n_side);
  if (near ? end_hi > side_plane + tol.distance : end_lo < side_plane - tol.distance) return false;
  const double rise = end.top_z - side.top_z;
  return rise >= -tol.distance &&
         rise <= (headboard ? m.max_headboard_rise + tol.distance : m.max_tailgate_rise);
}

// An end wall's inside and the floor: the floor lies in front of the end wall, a wall height down.
bool EndFloor(const TruckBedModel& m, const Tolerances& tol, const PlanarRegion& end,
              const PlanarRegion& floor) {
  // The floor's centroid lies inside the bed, on the inner side of the end wall (a flat surface
  // just beyond it is the chassis seen through the gap to the cab).
  const double offset = (floor.centroid - end.centroid).dot(Horizontal(end.normal));
  if (offset < 0 || offset > m.inner_length.max + tol.distance) return false;
  if (end.z_min < floor.centroid.z() - tol.distance) return false;
  const double height = end.top_z - floor.centroid.z();
  return height >= m.wall_height.min - tol.distance &&
         height <= m.wall_height.max + m.max_headboard_rise + tol.distance;
}

// Headboard and tailgate insides: facing each other one bed length apart, across the same bed;
// the tailgate no higher than the headboard.
bool HeadTail(const TruckBedModel& m, const Tolerances& tol, const PlanarRegion& head,
              const PlanarRegion& tail) {
  const Eigen::Vector3d n = Horizontal(head.normal);
  if (n.dot(Horizontal(tail.normal)) > -tol.cos_angle) return false;
  if (tail.top_z > head.top_z + m.max_tailgate_rise) return false;
  const double separation = (tail.centroid - head.centroid).dot(n);
  if (!m.inner_length.Contains(separation, tol.distance)) return false;
  const Eigen::Vector3d across = Eigen::Vector3d::UnitZ().cross(n);
  return Overlap(ProjectedExtent(head, across), ProjectedExtent(tail, across)) > 0;
}

bool IsEnd(BedFace face) { return face == BedFace::kHeadboard || face == BedFace::kTailgate; }

}  // namespace

std::string_view BedFaceName(BedFace face) {
  switch (face) {
    case BedFace::kNearSide:
      return "near side";
    case BedFace::kFarSide:
      return "far side";
    case BedFace::kFloor:
      return "floor";
    case BedFace::kHeadboard:
      return "headboard";
    case BedFace::kTailgate:
      return "tailgate";
  }
  return "?";
}

void Validate(const TruckBedModel& model) {
  const auto check_range = [](const ParameterRange& range, const std::string& name) {
    if (!std::isfinite(range.min) || !std::isfinite(range.max) || range.min < 0 ||
        range.min > range.max) {
      throw std::invalid_argument("TruckBedModel: " + name +
                                  " must be a finite, non-negative range with min <= max");
    }
  };
  check_range(model.inner_length, "inner_length");
  check_range(model.inner_width, "inner_width");
  check_range(model.wall_height, "wall_height");
  check_range(model.floor_height, "floor_height");
  check_range(model.wall_thickness, "wall_thickness");
  const auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("TruckBedModel: " + what);
  };
  require(model.inner_length.min > 0 && model.inner_width.min > 0 && model.wall_height.min > 0,
          "inner_length, inner_width and wall_height must have a positive minimum");
  require(model.wall_thickness.Contains(model.nominal_wall_thickness),
          "nominal_wall_thickness must lie in wall_thickness");
  require(std::isfinite(model.max_headboard_rise) && model.max_headboard_rise >= 0,
          "max_headboard_rise must be finite and non-negative");
  require(std::isfinite(model.max_tailgate_rise) && model.max_tailgate_rise >= 0,
          "max_tailgate_rise must be finite and non-negative");
  require(std::isfinite(model.min_near_side_length) && model.min_near_side_length >= 0,
          "min_near_side_length must be finite and non-negative");
  require(std::isfinite(model.angle_tolerance_deg) && model.angle_tolerance_deg > 0 &&
              model.angle_tolerance_deg < 45,
          "angle_tolerance_deg must lie in (0, 45)");
  require(std::isfinite(model.distance_tolerance) && model.distance_tolerance >= 0,
          "distance_tolerance must be finite and non-negative");
  require(model.min_matched_faces >= 2 && model.min_matched_faces <= kNumBedFaces,
          "min_matched_faces must lie in [2, 5]");
}

bool IsRequired(BedFace face) { return face == BedFace::kNearSide || face == BedFace::kFarSide; }

// §4.1: ranges on the sizes of the planar regions (and here their orientation and height).
bool UnaryConsistent(const TruckBedModel& m, BedFace face, const PlanarRegion& r,
                     const GroundEstimate& ground) {
  const Tolerances tol = TolerancesOf(m);
  const double height = r.z_max - r.z_min;
  // Rim height above the ground of any wall top (headboards may rise above it).
  const auto top_in_range = [&](double rise) {
    if (!ground.found) return true;
    const Eigen::Vector3d top(r.centroid.x(), r.centroid.y(), r.top_z);
    const double h = ground.HeightAbove(top);
    return h >= m.floor_height.min + m.wall_height.min - tol.distance &&
           h <= m.floor_height.max + m.wall_height.max + rise + tol.distance;
  };
  switch (face) {
    case BedFace::kNearSide:
      // No bound on its height: in a scanline the near outside face is often collinear with the
      // wheels or fenders below it, so its segments (and region) may reach the ground.
      return IsVertical(r, tol) && r.USize() >= m.min_near_side_length &&
             r.USize() <= m.inner_length.max + 2 * m.wall_thickness.max + tol.distance &&
             top_in_range(0.0);
    case BedFace::kFarSide:
      // Up to a headboard's rise taller than a wall: segments at the front end may run onto it.
      return IsVertical(r, tol) && r.USize() <= m.inner_length.max + tol.distance &&
             height <= m.wall_height.max + m.max_headboard_rise + tol.distance && top_in_range(0.0);
    case BedFace::kHeadboard:
    case BedFace::kTailgate:
      return IsVertical(r, tol) && r.USize() <= m.inner_width.max + tol.distance &&
             height <= m.wall_height.max + m.max_headboard_rise + tol.distance &&
             top_in_range(m.max_headboard_rise);
    case BedFace::kFloor: {
      if (r.normal.z() < tol.cos_angle) return false;
      if (r.USize() > std::hypot(m.inner_length.max, m.inner_width.max) + tol.distance ||
          r.VSize() > m.inner_width.max + tol.distance) {
        return false;
      }
      return !ground.found || m.floor_height.Contains(ground.HeightAbove(r.centroid), tol.distance);
    }
  }
  return false;
}

// §4.1: ranges on the locations of the regions' centroids relative to each other and on the
// angles between the planes.
bool PairConsistent(const TruckBedModel& m, BedFace face_a, const PlanarRegion& a, BedFace face_b,
                    const PlanarRegion& b) {
  if (face_a == face_b) throw std::invalid_argument("PairConsistent: the two faces must differ");
  if (FaceIndex(face_a) > FaceIndex(face_b)) return PairConsistent(m, face_b, b, face_a, a);
  const Tolerances tol = TolerancesOf(m);
  // From here on face_a comes first in the order near, far, floor, headboard, tailgate.
  if (face_a == BedFace::kNearSide && face_b == BedFace::kFarSide) return NearFar(m, tol, a, b);
  if (face_b == BedFace::kFloor) return SideFloor(m, tol, a, face_a == BedFace::kNearSide, b);
  if (IsEnd(face_b) && face_a != BedFace::kFloor && !IsEnd(face_a)) {
    return EndSide(m, tol, b, face_b == BedFace::kHeadboard, a, face_a == BedFace::kNearSide);
  }
  if (face_a == BedFace::kFloor) return EndFloor(m, tol, b, a);
  return HeadTail(m, tol, a, b);
}

}  // namespace autoshovel::perception
