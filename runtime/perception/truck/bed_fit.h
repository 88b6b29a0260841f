// Pose and size of the bed from one interpretation (excavator seed §4.1: the corner points of the
// bed opening give the truck's position and orientation, passed on to dump planning).
//
// Plan orientation: the side walls' returns lie on two parallel lines and the end walls' on lines
// perpendicular to them, so the bed axis is the direction that minimises the summed squared
// distances of all wall returns from such a rectangle: the eigenvector of least eigenvalue of
// S_side + R90ᵀ S_end R90 (S: plan scatter matrices, each wall about its own centroid). This uses
// every return on every matched wall at once and enforces the right angles exactly.
//
// Before the fit, fragments join the side walls: unmatched regions in the far wall's plane, and
// single segments in the near wall's plane whose tops are at its rim (region growing may have
// split the wall, or handed its end to a cab side flush with it). The near wall is then cut back
// to its contiguous run of scanlines (a gap of several spacings separates body and cab), and
// side-wall segments beyond a matched end wall are dropped.
//
// Offsets along the axes are mean projections of each wall's returns. The near side is seen from
// outside, so the nominal wall thickness is subtracted to reach the bed's inside edge. An end
// without a matched end wall is placed at the extreme scanline on the near outside face, pushed
// out by half the local scanline spacing (the true end lies, uniformly, between that scanline and
// the next); at the front the nominal thickness is taken off again, since every body has a
// headboard whose end the outside face covers. A rear without a matched tailgate is taken as open
// (the length comes out one tailgate thickness long if an unseen tailgate is there). The rim is
// the median top of the side-wall segments between the ends.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <limits>
#include <vector>

#include "runtime/perception/truck/interpretation_tree.h"
#include "runtime/perception/truck/line_segmentation.h"
#include "runtime/perception/truck/planar_regions.h"
#include "runtime/perception/truck/truck_model.h"

namespace autoshovel::perception {

struct BedFit {
  bool ok = false;
  /// Bed frame: origin at the centre of the bed opening on the rim plane, x along the bed toward
  /// the headboard (the cab), y to the left, z up (rotation about world z only).
  Eigen::Isometry3d T_world_bed = Eigen::Isometry3d::Identity();
  double length = 0;                                          ///< inside, headboard to tailgate [m]
  double width = 0;                                           ///< inside, side to side [m]
  double rim_z = 0;                                           ///< world z of the rim [m]
  double floor_z = std::numeric_limits<double>::quiet_NaN();  ///< world z, NaN if unseen [m]
  double ground_z = std::numeric_limits<double>::quiet_NaN();  ///< below the centre, NaN if unknown
  /// Which way is front was fixed by a matched headboard or tailgate; otherwise verification
  /// decides it from the cab (bed_verification.h).
  bool front_from_end_wall = false;
  bool front_measured = false;  ///< the front end comes from a headboard, not from an extent
  bool rear_measured = false;   ///< the rear end comes from a tailgate, not from an extent
  /// Regions that support each face: the matched one, plus fragments of the far wall.
  std::array<std::vector<int>, kNumBedFaces> face_regions;
  /// The segments each face was fitted to: those of face_regions plus single segments on the
  /// near wall's plane, less what lies beyond a gap in the near wall or beyond a matched end wall
  /// (e.g. a cab side flush with the body).
  std::array<std::vector<int>, kNumBedFaces> face_segments;

  double YawRad() const;
  /// The inside corners of the opening at rim height, world: front-left, front-right, rear-right,
  /// rear-left ("left" is bed +y).
  std::array<Eigen::Vector3d, 4> CornersWorld() const;
  /// Turns the bed frame by 180° about its z axis (front and rear swap, corners follow).
  void Reverse();
  /// Moves the front end back by `amount` (the centre follows by half of it).
  void TrimFront(double amount);
};

/// Throws std::invalid_argument if the interpretation lacks a side wall or names a region that
/// does not exist.
BedFit FitBed(const Interpretation& interpretation, const std::vector<PlanarRegion>& regions,
              const std::vector<LineSegment>& segments, const TruckBedModel& model,
              const GroundEstimate& ground);

}  // namespace autoshovel::perception
