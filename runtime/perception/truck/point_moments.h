// Least-squares line and plane fits (principal component analysis of the scatter matrix) from
// accumulated first and second moments. Keeping the sums rather than the points makes the fit of a
// union (two line segments merged in §4.1's split-and-merge, a planar region growing by one
// segment) an O(1) update instead of a pass over all points.
#pragma once

#include <Eigen/Core>

namespace autoshovel::perception {

/// Σp and Σp pᵀ of a point set. Coordinates of a few tens of metres and centimetre noise keep the
/// cancellation in Σp pᵀ/n − μ μᵀ far above double precision.
class PointMoments {
 public:
  void Add(const Eigen::Vector3d& p);
  void Add(const PointMoments& other);

  int count() const { return count_; }
  Eigen::Vector3d Mean() const;
  /// Population covariance (divided by n). Zero for fewer than two points.
  Eigen::Matrix3d Covariance() const;

 private:
  int count_ = 0;
  Eigen::Vector3d sum_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d sum_outer_ = Eigen::Matrix3d::Zero();
};

/// Total-least-squares line: through the centroid along the direction of largest spread.
struct LineFit {
  bool ok = false;  ///< at least two points with a non-zero spread
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  ///< unit
  double rms_residual = 0;  ///< RMS perpendicular distance of the points from the line [m]
};

/// Total-least-squares plane: through the centroid, normal along the direction of least spread.
struct PlaneFit {
  bool ok = false;  ///< at least three points that are not (nearly) collinear
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit; sign arbitrary
  double rms_residual = 0;  ///< RMS distance of the points from the plane [m]
  /// Standard deviation of the points along the in-plane direction of least spread: tells a plane
  /// spanned by the points from a line that leaves the plane undetermined [m].
  double minor_spread = 0;
};

LineFit FitLine(const PointMoments& moments);
/// `min_minor_spread` [m]: below it the points are taken as collinear and ok stays false.
PlaneFit FitPlane(const PointMoments& moments, double min_minor_spread = 1e-3);

}  // namespace autoshovel::perception
