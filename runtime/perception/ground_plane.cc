#include "runtime/perception/ground_plane.h"

#include <pcl/ModelCoefficients.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <cmath>

namespace autoshovel::perception {

GroundPlane FitGroundPlane(const std::vector<Eigen::Vector3d>& points, double threshold,
                           int iterations) {
  GroundPlane plane;
  if (points.size() < 3) return plane;
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->reserve(points.size());
  for (const auto& p : points) {
    cloud->emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()),
                        static_cast<float>(p.z()));
  }
  pcl::SACSegmentation<pcl::PointXYZ> segmentation;  // random = false: a fixed seed
  segmentation.setOptimizeCoefficients(true);
  segmentation.setModelType(pcl::SACMODEL_PLANE);
  segmentation.setMethodType(pcl::SAC_RANSAC);
  segmentation.setDistanceThreshold(threshold);
  segmentation.setMaxIterations(iterations);
  segmentation.setInputCloud(cloud);
  pcl::PointIndices inliers;
  pcl::ModelCoefficients coefficients;
  segmentation.segment(inliers, coefficients);
  if (inliers.indices.size() < 3 || coefficients.values.size() != 4) return plane;
  const double a = coefficients.values[0], b = coefficients.values[1];
  const double c = coefficients.values[2], d = coefficients.values[3];
  if (std::abs(c) < 1e-6) return plane;  // a vertical plane is no ground
  plane.coefficients = Eigen::Vector3d(-a / c, -b / c, -d / c);
  double sum = 0;
  for (const int i : inliers.indices) {
    const Eigen::Vector3d& p = points[i];
    const double r = p.z() - (plane.coefficients.x() * p.x() + plane.coefficients.y() * p.y() +
                              plane.coefficients.z());
    sum += r * r;
  }
  plane.inliers = static_cast<int>(inliers.indices.size());
  plane.variance = sum / plane.inliers;
  plane.ok = true;
  return plane;
}

}  // namespace autoshovel::perception
