// Step 2 of truck recognition (excavator seed §4.1): line segments from neighbouring scanlines
// that lie in one plane are grouped into planar regions. Neighbouring scanlines are neighbouring
// vertical cut planes (§2: the scan circle is panned), so a flat surface shows up as a ladder of
// nearly parallel segments, one per scanline, and a region is grown along that ladder.
//
// Growing, not pairwise clustering: a candidate segment must agree both with the segment it is
// reached from (nearly parallel, overlapping, close, jointly coplanar) and with the plane of the
// whole region so far, so that a gently curved surface (a dirt pile) cannot drift into one
// "plane" by small steps.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "runtime/perception/truck/line_segmentation.h"
#include "runtime/perception/truck/point_moments.h"

namespace autoshovel::perception {

struct PlanarRegionParams {
  /// Segments are linked across at most this many scanlines (2: one scanline may have lost its
  /// segment to a noise spike or a dropout cluster). This can bridge the gap between a truck's
  /// body and a flush cab side; bed_fit.h cuts such merges apart again.
  int max_scanline_gap = 2;
  /// Largest distance between the lines of two linked segments [m]: a few scanline spacings
  /// (0.6° pan steps are 10 cm apart at 10 m range), well under the 0.3 m or more that separate
  /// a truck's bed from its cab.
  double max_link_distance = 0.5;
  double max_link_angle_deg = 15;  ///< between the directions of two linked segments
  /// A segment joins a region only if both its end points lie within this distance of the
  /// region's plane [m] (as the segmentation tolerance, 4σ).
  double plane_tolerance = 0.12;
  /// and the region's RMS distance from its plane stays within this [m] (≈ 1.5σ).
  double max_plane_rms = 0.045;
  /// Regions with fewer segments or returns are dropped: too small to be a model face.
  int min_segments = 3;
  int min_points = 20;
};

/// Throws std::invalid_argument naming the offending field.
void Validate(const PlanarRegionParams& params);

struct PlanarRegion {
  /// Unit normal, oriented toward the mean beam origin of the region's scanlines: the side of the
  /// surface the scanner saw.
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  double rms_residual = 0;  ///< [m]
  int num_points = 0;
  int num_scanlines = 0;      ///< distinct scanlines contributing
  std::vector<int> segments;  ///< indices into the segment vector the region was grown from
  PointMoments moments;
  Eigen::Vector3d p_world_sensor_mean = Eigen::Vector3d::Zero();
  /// In-plane axes: for steep planes (|n_z| < 0.7) u is horizontal (z × n) and v points up the
  /// plane; for flat planes u is the direction of largest spread. v = n × u.
  Eigen::Vector3d axis_u = Eigen::Vector3d::UnitX();
  Eigen::Vector3d axis_v = Eigen::Vector3d::UnitY();
  /// Extent of the segments' end points along u and v, relative to the centroid [m].
  double u_min = 0, u_max = 0, v_min = 0, v_max = 0;
  double z_min = 0, z_max = 0;  ///< world height range of the end points [m]
  /// Median over segments of the higher end point's z: the top edge of a wall [m].
  double top_z = 0;
  /// Median over segments of the lower end point's z: the bottom edge of a wall [m].
  double bottom_z = 0;

  double USize() const { return u_max - u_min; }
  double VSize() const { return v_max - v_min; }
  /// The two end points of the extent along u, at the centroid (world) [m].
  Eigen::Vector3d UMinPoint() const { return centroid + u_min * axis_u; }
  Eigen::Vector3d UMaxPoint() const { return centroid + u_max * axis_u; }
};

/// Regions, largest (most returns) first. Segments that end up in no kept region are simply not
/// referenced. Throws std::invalid_argument on invalid parameters.
std::vector<PlanarRegion> GroupPlanarRegions(const std::vector<LineSegment>& segments,
                                             const PlanarRegionParams& params = {});

/// The ground: the flat (|n_z| ≥ cos max_tilt) region with the most returns. Trucks stand on it
/// and the scan circle (§2) hits it in every scanline, so it dwarfs any other flat surface.
struct GroundEstimate {
  bool found = false;
  int region = -1;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit, up
  double offset = 0;                                  ///< normal · p on the ground [m]

  /// Height of `p_world` above the ground plane along its normal [m] (NaN if not found).
  double HeightAbove(const Eigen::Vector3d& p_world) const;
};

GroundEstimate EstimateGround(const std::vector<PlanarRegion>& regions, double max_tilt_deg = 5);

}  // namespace autoshovel::perception
