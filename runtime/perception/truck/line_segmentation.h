// Step 1 of truck recognition (excavator seed §4.1): each scanline is cut into straight line
// segments. The seed names the step, not the method; we use split-and-merge (iterative end-point
// fit, then merging neighbours whose joint least-squares line still fits), the usual choice for
// ordered range scans, on runs of consecutive returns that are not separated by a range jump.
//
// Each segment's ends are then trimmed: returns more than half the tolerance off the line through
// the segment's core (its middle 80 %) are dropped. A corner return, or a few returns from the
// next surface that stayed within the chord tolerance, would otherwise tilt the segment (a tilted
// segment at a wall's end no longer fits the wall's plane, and the wall comes out short).
//
// Tolerances are tied to the range noise σ: a point belongs to a segment while its distance from
// the line is within `split_tolerance` (4σ by default: with σ = 3 cm a straight wall of 100
// returns is cut by noise alone with probability below 1 %, while the 90° corners of a truck
// bed, which deviate by tens of centimetres a few points away from the corner, are always cut).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "runtime/perception/truck/point_moments.h"
#include "runtime/perception/truck/scanline.h"

namespace autoshovel::perception {

struct LineSegmentationParams {
  /// Largest distance of a point from its segment's line [m]. Default 4σ for σ = 3 cm.
  double split_tolerance = 0.12;
  /// Consecutive usable returns farther apart than jump_distance + jump_range_fraction · range
  /// start a new run (an occluding edge: the beam left one surface for another). The range term
  /// lets returns from a far, grazed ground stay together: at 15 m and 0.45° steps they lie
  /// 0.35 m apart, 0.7 m across one dropout [m, -].
  double jump_distance = 0.25;
  double jump_range_fraction = 0.04;
  /// Shorter segments, or ones with fewer returns, carry too little to fit a plane to [-, m].
  int min_points = 5;
  double min_length = 0.15;
};

/// Throws std::invalid_argument naming the offending field.
void Validate(const LineSegmentationParams& params);

struct LineSegment {
  int scanline = -1;  ///< index of its scanline in the input sequence
  Eigen::Vector3d p_world_sensor = Eigen::Vector3d::Zero();  ///< beam origin of that scanline
  /// End points: the first and last return projected onto the fitted line, in scan order [m].
  Eigen::Vector3d p_world_start = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_world_end = Eigen::Vector3d::Zero();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  ///< unit, start to end
  double rms_residual = 0;                               ///< [m]
  std::vector<Eigen::Vector3d> points;  ///< the returns it was fitted to (world) [m]
  PointMoments moments;                 ///< of `points`

  double Length() const { return (p_world_end - p_world_start).norm(); }
};

/// Segments of one scanline (`index` is stored in each segment). Unusable returns (invalid or
/// non-finite) are skipped. Throws std::invalid_argument on invalid parameters or a non-finite
/// sensor origin.
std::vector<LineSegment> SegmentScanline(const Scanline& scanline, int index,
                                         const LineSegmentationParams& params = {});

/// Segments of all scanlines, in scanline order.
std::vector<LineSegment> SegmentScanlines(const std::vector<Scanline>& scanlines,
                                          const LineSegmentationParams& params = {});

}  // namespace autoshovel::perception
