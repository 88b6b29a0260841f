#include "runtime/perception/truck/bed_verification.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

namespace autoshovel::perception {
namespace {

// Returns in the box ahead of an end wall start this far beyond its inside, past the wall itself
// and a raised headboard's top [m].
constexpr double kCabClearance = 0.1;
// The cab box spans this much either side of the bed and above/below the rim [m].
constexpr double kCabSideMargin = 0.3;
constexpr double kCabHalfHeight = 1.5;
// The floor's returns must lie within the outline grown by this (noise, corner returns) [m], all
// but a fraction [-].
constexpr double kFloorOutlineSlack = 0.1;
constexpr double kMinFloorInside = 0.9;

std::string Describe(const char* what, double value, const ParameterRange& range) {
  std::ostringstream out;
  out << what << " " << value << " m outside [" << range.min << ", " << range.max << "] m";
  return out.str();
}

// RMS distance of a face's returns from the line `axis · p = mean` in plan.
double PlanRms(const std::vector<LineSegment>& segments, const std::vector<int>& segment_ids,
               const Eigen::Vector2d& axis) {
  double sum = 0;
  double sum_sq = 0;
  int count = 0;
  for (int s : segment_ids) {
    for (const Eigen::Vector3d& p : segments[s].points) {
      const double d = axis.dot(p.head<2>());
      sum += d;
      sum_sq += d * d;
      ++count;
    }
  }
  if (count == 0) return 0;
  const double mean = sum / count;
  return std::sqrt(std::max(0.0, sum_sq / count - mean * mean));
}

// Where the segment from `o` to `p` crosses the plane `coordinate(axis) = value`.
Eigen::Vector3d Crossing(const Eigen::Vector3d& o, const Eigen::Vector3d& p, int axis,
                         double value) {
  return o + (value - o(axis)) / (p(axis) - o(axis)) * (p - o);
}

}  // namespace

void Validate(const VerificationParams& params) {
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("VerificationParams: ") + what);
  };
  require(std::isfinite(params.dimension_tolerance) && params.dimension_tolerance >= 0,
          "dimension_tolerance must be finite and non-negative");
  require(std::isfinite(params.max_face_rms) && params.max_face_rms > 0,
          "max_face_rms must be finite and positive");
  require(std::isfinite(params.min_near_coverage) && params.min_near_coverage >= 0 &&
              params.min_near_coverage <= 1,
          "min_near_coverage must lie in [0, 1]");
  require(std::isfinite(params.free_space_margin) && params.free_space_margin >= 0,
          "free_space_margin must be finite and non-negative");
  require(
      std::isfinite(params.free_space_height_above_rim) && params.free_space_height_above_rim >= 0,
      "free_space_height_above_rim must be finite and non-negative");
  require(params.max_violations >= 0, "max_violations must be non-negative");
  require(std::isfinite(params.max_violation_fraction) && params.max_violation_fraction >= 0,
          "max_violation_fraction must be finite and non-negative");
  require(std::isfinite(params.violation_penalty) && params.violation_penalty >= 0,
          "violation_penalty must be finite and non-negative");
  require(std::isfinite(params.ground_contact_height) && params.ground_contact_height >= 0,
          "ground_contact_height must be finite and non-negative");
  require(std::isfinite(params.max_ground_contact) && params.max_ground_contact >= 0 &&
              params.max_ground_contact <= 1,
          "max_ground_contact must lie in [0, 1]");
  require(std::isfinite(params.cab_weight) && params.cab_weight >= 0,
          "cab_weight must be finite and non-negative");
  require(std::isfinite(params.cab_search_length) && params.cab_search_length > 0,
          "cab_search_length must be finite and positive");
  require(params.min_cab_points >= 0, "min_cab_points must be non-negative");
}

namespace {

// §4.1, 1: the fitted length, width and heights within the model's ranges ("" or why not).
std::string CheckDimensions(const BedFit& fit, const TruckBedModel& model,
                            const VerificationParams& params) {
  const double tol = params.dimension_tolerance;
  if (!model.inner_length.Contains(fit.length, tol)) {
    return Describe("length", fit.length, model.inner_length);
  }
  if (!model.inner_width.Contains(fit.width, tol)) {
    return Describe("width", fit.width, model.inner_width);
  }
  if (std::isfinite(fit.floor_z) && !model.wall_height.Contains(fit.rim_z - fit.floor_z, tol)) {
    return Describe("wall height", fit.rim_z - fit.floor_z, model.wall_height);
  }
  if (std::isfinite(fit.floor_z) && std::isfinite(fit.ground_z) &&
      !model.floor_height.Contains(fit.floor_z - fit.ground_z, tol)) {
    return Describe("floor height", fit.floor_z - fit.ground_z, model.floor_height);
  }
  const ParameterRange rim_range{model.floor_height.min + model.wall_height.min,
                                 model.floor_height.max + model.wall_height.max};
  if (std::isfinite(fit.ground_z) && !rim_range.Contains(fit.rim_z - fit.ground_z, tol)) {
    return Describe("rim height", fit.rim_z - fit.ground_z, rim_range);
  }
  return "";
}

// §4.1, 2: planarity of the walls about the fitted rectangle ("" or why not).
std::string CheckPlanarity(const BedFit& fit, const std::vector<LineSegment>& segments,
                           const VerificationParams& params) {
  const Eigen::Vector2d along = fit.T_world_bed.linear().col(0).head<2>();
  const Eigen::Vector2d across = fit.T_world_bed.linear().col(1).head<2>();
  for (BedFace face : kAllBedFaces) {
    if (face == BedFace::kFloor) continue;
    const bool side = face == BedFace::kNearSide || face == BedFace::kFarSide;
    const double rms =
        PlanRms(segments, fit.face_segments[static_cast<std::size_t>(FaceIndex(face))],
                side ? across : along);
    if (rms > params.max_face_rms) {
      std::ostringstream out;
      out << "the " << BedFaceName(face) << " strays " << rms << " m (RMS) from the rectangle";
      return out.str();
    }
  }
  return "";
}

// §4.1, 3: the floor seen lies within the outline; coverage of the near outside face.
std::string CheckCoverage(const BedFit& fit, const std::vector<LineSegment>& segments,
                          const VerificationParams& params, BedVerification& v) {
  const Eigen::Isometry3d T_bed_world = fit.T_world_bed.inverse();
  const double half_length = 0.5 * fit.length;
  const double half_width = 0.5 * fit.width;
  // 3. Coverage of the near outside face; the floor seen lies within the outline.
  {
    int inside = 0;
    int total = 0;
    for (int s : fit.face_segments[static_cast<std::size_t>(FaceIndex(BedFace::kFloor))]) {
      for (const Eigen::Vector3d& p_world : segments[s].points) {
        const Eigen::Vector3d p = T_bed_world * p_world;
        inside += std::abs(p.x()) < half_length + kFloorOutlineSlack &&
                  std::abs(p.y()) < half_width + kFloorOutlineSlack;
        ++total;
      }
    }
    if (total > 0 && inside < kMinFloorInside * total) {
      std::ostringstream out;
      out << "only " << inside << " of " << total << " floor returns lie within the bed";
      return out.str();
    }
  }
  {
    double lo = half_length;
    double hi = -half_length;
    for (int s : fit.face_segments[static_cast<std::size_t>(FaceIndex(BedFace::kNearSide))]) {
      const double x =
          std::clamp((T_bed_world * segments[s].centroid).x(), -half_length, half_length);
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
    v.near_coverage = hi > lo ? (hi - lo) / fit.length : 0.0;
    if (v.near_coverage < params.min_near_coverage) {
      std::ostringstream out;
      out << "the near side covers only " << v.near_coverage << " of the bed length";
      return out.str();
    }
  }
  return "";
}

// §4.1, 5: a chassis under the bed: the near wall's scanlines must not all reach the ground.
std::string CheckChassis(const BedFit& fit, const std::vector<LineSegment>& segments,
                         const VerificationParams& params, BedVerification& v) {
  const Eigen::Isometry3d T_bed_world = fit.T_world_bed.inverse();
  const double half_length = 0.5 * fit.length;
  if (std::isfinite(fit.ground_z)) {
    std::map<int, double> lowest;  // scanline → lowest near-wall return, world z
    for (int s : fit.face_segments[static_cast<std::size_t>(FaceIndex(BedFace::kNearSide))]) {
      const LineSegment& seg = segments[s];
      if (std::abs((T_bed_world * seg.centroid).x()) > half_length) continue;
      const double z = std::min(seg.p_world_start.z(), seg.p_world_end.z());
      const auto [it, inserted] = lowest.emplace(seg.scanline, z);
      if (!inserted) it->second = std::min(it->second, z);
    }
    int touching = 0;
    for (const auto& [line, z] : lowest) {
      if (z - fit.ground_z < params.ground_contact_height) ++touching;
    }
    v.ground_contact = lowest.empty() ? 0.0 : static_cast<double>(touching) / lowest.size();
    if (v.ground_contact > params.max_ground_contact) {
      std::ostringstream out;
      out << "the near side reaches the ground along " << 100 * v.ground_contact
          << " % of its scanlines: no chassis under it";
      return out.str();
    }
  }
  return "";
}

// §4.1, 4 and 6: one pass over all returns, in the bed frame (rim plane z = 0): returns where an
// empty bed leaves free space, and returns of a cab beyond either end.
void CountFreeSpaceAndCab(const BedFit& fit, const std::vector<Scanline>& scanlines,
                          const TruckBedModel& model, const VerificationParams& params,
                          BedVerification& v) {
  const Eigen::Isometry3d T_bed_world = fit.T_world_bed.inverse();
  const double half_length = 0.5 * fit.length;
  const double half_width = 0.5 * fit.width;
  const double margin = params.free_space_margin;
  const auto inside_outline = [&](const Eigen::Vector3d& p) {
    return std::abs(p.x()) < half_length - margin && std::abs(p.y()) < half_width - margin;
  };
  // The free box starts above the floor seen or, unseen, above the shallowest possible floor.
  const double box_bottom = std::isfinite(fit.floor_z) ? fit.floor_z - fit.rim_z + margin
                                                       : -model.wall_height.min + margin;
  // No beam that came in through the opening gets below the floor seen or the lowest possible
  // one inside the outline: a wall height below the rim, but not lower than the least floor
  // height above the ground (a bed stands on a chassis: an open box on the ground is no truck).
  // Returns below it are fine in themselves: the chassis under the bed is seen from the side.
  double lowest_floor = -model.wall_height.max;
  if (std::isfinite(fit.ground_z)) {
    lowest_floor = std::max(lowest_floor, fit.ground_z + model.floor_height.min - fit.rim_z);
  }
  const double floor_bottom =
      (std::isfinite(fit.floor_z) ? fit.floor_z - fit.rim_z : lowest_floor) - margin;
  // The near wall's outside, as a rectangle in the plane y = near_y: at least the shallowest wall
  // deep, over the bed's length.
  const double near_depth = -model.wall_height.min + margin;
  const double cab_start = half_length + model.nominal_wall_thickness + kCabClearance;
  for (const Scanline& line : scanlines) {
    const Eigen::Vector3d o = T_bed_world * line.p_world_sensor;
    const double near_y = std::copysign(half_width + model.nominal_wall_thickness, o.y());
    for (const ScanPoint& point : line.points) {
      if (!IsUsable(point)) continue;
      const Eigen::Vector3d p = T_bed_world * point.p_world;
      if (inside_outline(p) && p.z() > box_bottom && p.z() < params.free_space_height_above_rim) {
        ++v.free_space_violations;
      } else if (p.z() < floor_bottom && o.z() > 0) {
        // Came in through the opening and left below the floor, both inside the (convex)
        // outline: the beam went through the floor.
        if (inside_outline(Crossing(o, p, 2, 0.0)) &&
            inside_outline(Crossing(o, p, 2, floor_bottom))) {
          ++v.free_space_violations;
        }
      }
      // Beyond the near wall (seen from the sensor's side) while the beam crossed its rectangle.
      if (std::abs(o.y()) > std::abs(near_y) &&
          std::copysign(1.0, o.y()) * p.y() < std::abs(near_y) - margin) {
        const Eigen::Vector3d c = Crossing(o, p, 1, near_y);
        if (std::abs(c.x()) < half_length - margin && c.z() < -margin && c.z() > near_depth) {
          ++v.free_space_violations;
        }
      }
      if (std::abs(p.y()) < half_width + kCabSideMargin && std::abs(p.z()) < kCabHalfHeight) {
        const double beyond = std::abs(p.x()) - cab_start;
        if (beyond > 0 && beyond < params.cab_search_length) {
          ++(p.x() > 0 ? v.cab_points_front : v.cab_points_rear);
        }
      }
    }
  }
}

}  // namespace

// §4.1: the verification of a complete interpretation, a closer check of the truck's parameters.
BedVerification VerifyBed(BedFit& fit, const std::vector<LineSegment>& segments,
                          const std::vector<Scanline>& scanlines, const TruckBedModel& model,
                          const VerificationParams& params) {
  BedVerification v;
  const auto fail = [&v](std::string reason) {
    v.passed = false;
    v.reason = std::move(reason);
    return v;
  };
  if (!fit.ok) return fail("the bed fit is degenerate");
  for (BedFace face : kAllBedFaces) {
    for (int s : fit.face_segments[static_cast<std::size_t>(FaceIndex(face))]) {
      v.support_points += static_cast<int>(segments[s].points.size());
    }
  }

  if (std::string why = CheckDimensions(fit, model, params); !why.empty()) return fail(why);
  if (std::string why = CheckPlanarity(fit, segments, params); !why.empty()) return fail(why);
  if (std::string why = CheckCoverage(fit, segments, params, v); !why.empty()) return fail(why);
  if (std::string why = CheckChassis(fit, segments, params, v); !why.empty()) return fail(why);
  CountFreeSpaceAndCab(fit, scanlines, model, params, v);
  const double allowed =
      std::max<double>(params.max_violations, params.max_violation_fraction * v.support_points);
  if (v.free_space_violations > allowed) {
    std::ostringstream out;
    out << v.free_space_violations << " returns where an empty bed leaves free space (at most "
        << allowed << ")";
    return fail(out.str());
  }
  if (!fit.front_from_end_wall) {
    if (v.cab_points_rear > v.cab_points_front) {
      fit.Reverse();
      std::swap(v.cab_points_front, v.cab_points_rear);
    }
    if (v.cab_points_front < params.min_cab_points) {
      std::ostringstream out;
      out << "no end wall matched and no cab seen at either end (" << v.cab_points_front
          << " returns)";
      return fail(out.str());
    }
    // Now that the front is known: the near outside face runs over the headboard's end.
    fit.TrimFront(model.nominal_wall_thickness);
  } else if (v.cab_points_rear >= params.min_cab_points &&
             v.cab_points_rear > 2 * v.cab_points_front) {
    std::ostringstream out;
    out << "the cab (" << v.cab_points_rear << " returns) is behind the tailgate, "
        << v.cab_points_front << " ahead of the headboard";
    return fail(out.str());
  }

  v.passed = true;
  v.score = v.support_points - params.violation_penalty * v.free_space_violations +
            params.cab_weight * (v.cab_points_front - v.cab_points_rear);
  return v;
}

}  // namespace autoshovel::perception
