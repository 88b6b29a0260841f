#include "runtime/perception/truck/point_moments.h"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace autoshovel::perception {

void PointMoments::Add(const Eigen::Vector3d& p) {
  ++count_;
  sum_ += p;
  sum_outer_.noalias() += p * p.transpose();
}

void PointMoments::Add(const PointMoments& other) {
  count_ += other.count_;
  sum_ += other.sum_;
  sum_outer_ += other.sum_outer_;
}

Eigen::Vector3d PointMoments::Mean() const {
  return count_ > 0 ? Eigen::Vector3d(sum_ / count_) : Eigen::Vector3d::Zero();
}

Eigen::Matrix3d PointMoments::Covariance() const {
  if (count_ < 2) return Eigen::Matrix3d::Zero();
  const Eigen::Vector3d mean = Mean();
  Eigen::Matrix3d covariance = sum_outer_ / count_ - mean * mean.transpose();
  return 0.5 * (covariance + covariance.transpose());
}

LineFit FitLine(const PointMoments& moments) {
  LineFit fit;
  fit.centroid = moments.Mean();
  if (moments.count() < 2) return fit;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(moments.Covariance());
  // Eigenvalues come sorted ascending: the last is the spread along the line, the first two the
  // variance across it.
  const Eigen::Vector3d values = solver.eigenvalues().cwiseMax(0.0);
  if (values(2) <= 0) return fit;
  fit.ok = true;
  fit.direction = solver.eigenvectors().col(2).normalized();
  fit.rms_residual = std::sqrt(values(0) + values(1));
  return fit;
}

PlaneFit FitPlane(const PointMoments& moments, double min_minor_spread) {
  PlaneFit fit;
  fit.centroid = moments.Mean();
  if (moments.count() < 3) return fit;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(moments.Covariance());
  const Eigen::Vector3d values = solver.eigenvalues().cwiseMax(0.0);
  fit.normal = solver.eigenvectors().col(0).normalized();
  fit.rms_residual = std::sqrt(values(0));
  fit.minor_spread = std::sqrt(values(1));
  fit.ok = fit.minor_spread >= min_minor_spread;
  return fit;
}

}  // namespace autoshovel::perception
