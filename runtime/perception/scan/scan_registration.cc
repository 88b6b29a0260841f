// The PCL translation unit of the reference scan's registration (PCL headers stay out of headers).
#include "runtime/perception/scan/scan_registration.h"

#include <pcl/console/print.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "runtime/perception/scan/scan_ground.h"

namespace autoshovel::perception {

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

// Points relative to `centre` as floats: a georeferenced cloud (easting 500 000 m) would lose its
// millimetres in single precision, a cloud around its own centre keeps them.
Cloud::Ptr ToCloud(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& centre,
                   const Eigen::Isometry3d& T) {
  Cloud::Ptr cloud(new Cloud);
  cloud->reserve(points.size());
  for (const auto& p : points) {
    const Eigen::Vector3d q = T * p - centre;
    cloud->emplace_back(static_cast<float>(q.x()), static_cast<float>(q.y()),
                        static_cast<float>(q.z()));
  }
  return cloud;
}

Cloud::Ptr Thin(const Cloud::Ptr& cloud, double voxel) {
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  grid.setInputCloud(cloud);
  const float leaf = static_cast<float>(voxel);
  grid.setLeafSize(leaf, leaf, leaf);
  Cloud::Ptr thin(new Cloud);
  grid.filter(*thin);
  return thin;
}

}  // namespace

ScanRegistration RegisterScans(const std::vector<Eigen::Vector3d>& source,
                               const std::vector<Eigen::Vector3d>& target,
                               const Eigen::Isometry3d& initial,
                               const ScanRegistrationOptions& options) {
  if (source.size() < 100 || target.size() < 100) {
    throw std::invalid_argument("registration needs at least 100 points in each scan");
  }
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& p : target) centre += p;
  centre /= static_cast<double>(target.size());
  const double extent = ScanExtent(target);
  ScanRegistration result;
  result.voxel = options.voxel > 0 ? options.voxel : std::max(0.002, 0.004 * extent);
  const double start = options.start_distance > 0 ? options.start_distance : 0.08 * extent;
  result.final_distance = options.final_distance > 0 ? options.final_distance : 3 * result.voxel;
  const double final_distance = std::min(result.final_distance, start);

  pcl::console::setVerbosityLevel(pcl::console::L_ERROR);
  const Cloud::Ptr target_cloud = ToCloud(target, centre, Eigen::Isometry3d::Identity());
  const Cloud::Ptr source_thin =
      Thin(ToCloud(source, centre, Eigen::Isometry3d::Identity()), result.voxel);
  const Cloud::Ptr target_thin = Thin(target_cloud, result.voxel);

  // In the centred frame the initial guess is C⁻¹ · initial · C, C the shift by `centre`.
  Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
  shift.translation() = centre;
  Eigen::Isometry3d T = shift.inverse() * initial * shift;  // centred target ← centred source
  pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> gicp;
  gicp.setInputSource(source_thin);
  gicp.setInputTarget(target_thin);
  gicp.setMaximumIterations(options.iterations_per_stage);
  gicp.setTransformationEpsilon(1e-10);
  const int stages = std::max(1, options.stages);
  for (int k = 0; k < stages; ++k) {
    const double f = stages == 1 ? 1.0 : static_cast<double>(k) / (stages - 1);
    const double distance = start * std::pow(final_distance / start, f);
    gicp.setMaxCorrespondenceDistance(distance);
    Cloud aligned;
    gicp.align(aligned, T.matrix().cast<float>());
    if (!gicp.hasConverged() && k == 0) continue;  // nothing matched yet: keep the guess
    const Eigen::Matrix4d m = gicp.getFinalTransformation().cast<double>();
    if (!m.allFinite()) break;
    T.matrix() = m;
    // Re-orthonormalise: single-precision products drift off SO(3).
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(T.linear(),
                                                Eigen::ComputeFullU | Eigen::ComputeFullV);
    T.linear() = svd.matrixU() * svd.matrixV().transpose();
  }
  result.T_target_source = shift * T * shift.inverse();

  // How well they agree: every thinned source point against the full target.
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(target_cloud);
  std::vector<int> index(1);
  std::vector<float> squared(1);
  long close = 0;
  double sum_squared = 0;
  for (const auto& p : *source_thin) {
    const Eigen::Vector3d q = T * Eigen::Vector3d(p.x, p.y, p.z);
    const pcl::PointXYZ query(static_cast<float>(q.x()), static_cast<float>(q.y()),
                              static_cast<float>(q.z()));
    if (tree.nearestKSearch(query, 1, index, squared) == 1 &&
        squared[0] <= final_distance * final_distance) {
      ++close;
      sum_squared += squared[0];
    }
  }
  result.overlap = source_thin->empty()
                       ? 0.0
                       : static_cast<double>(close) / static_cast<double>(source_thin->size());
  result.rms = close > 0 ? std::sqrt(sum_squared / static_cast<double>(close)) : 0.0;
  const Eigen::Isometry3d moved = result.T_target_source * initial.inverse();
  result.rotation = Eigen::AngleAxisd(moved.linear()).angle();
  result.translation = moved.translation().norm();
  return result;
}

}  // namespace autoshovel::perception
