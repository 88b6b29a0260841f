// The ground plane z' = a x + b y + c fitted by RANSAC (Fischler & Bolles 1981; PCL's
// SACSegmentation, deterministic seed) to the map cells at or below z0, and the variance σz² of
// the inliers about it (wheel-loader seed §4.3, before Eq. 10). PCL stays in the .cc.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace autoshovel::perception {

struct GroundPlane {
  bool ok = false;
  Eigen::Vector3d coefficients = Eigen::Vector3d::Zero();  ///< (a, b, c) of z = a x + b y + c
  double variance = 0;                                     ///< σz² of the inliers [m²]
  int inliers = 0;
};

GroundPlane FitGroundPlane(const std::vector<Eigen::Vector3d>& points, double threshold,
                           int iterations);

}  // namespace autoshovel::perception
