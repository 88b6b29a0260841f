// The PCL translation unit of the per-point features (normals, ground plane, clusters).
#include "identification/camera_lidar/cloud_features.h"

#include <pcl/ModelCoefficients.h>
#include <pcl/features/normal_3d.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/conditional_euclidean_clustering.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace autoshovel::identification {

namespace {

// Planes off the cloud one after the other (no up axis): label[i] = plane index + 1 or 0.
int ExtractPlanes(const pcl::PointCloud<pcl::PointXYZ>::Ptr& cloud,
                  const CloudFeatureOptions& options, std::vector<int>& label) {
  const std::size_t n = cloud->size();
  label.assign(n, 0);
  const std::size_t min_points = std::max<std::size_t>(
      50, static_cast<std::size_t>(options.min_plane_fraction * static_cast<double>(n)));
  pcl::SACSegmentation<pcl::PointXYZ> sac;  // random = false: a fixed seed
  sac.setOptimizeCoefficients(true);
  sac.setModelType(pcl::SACMODEL_PLANE);
  sac.setMethodType(pcl::SAC_RANSAC);
  sac.setDistanceThreshold(options.plane_threshold);
  sac.setMaxIterations(300);
  sac.setInputCloud(cloud);
  pcl::IndicesPtr remaining(new pcl::Indices(n));
  for (std::size_t i = 0; i < n; ++i) (*remaining)[i] = static_cast<int>(i);
  int planes = 0;
  while (planes < options.max_planes && remaining->size() >= min_points) {
    sac.setIndices(remaining);
    pcl::PointIndices inliers;
    pcl::ModelCoefficients plane;
    sac.segment(inliers, plane);
    if (inliers.indices.size() < min_points) break;
    ++planes;
    for (const int i : inliers.indices) label[static_cast<std::size_t>(i)] = planes;
    pcl::IndicesPtr next(new pcl::Indices);
    for (const int i : *remaining) {
      if (label[static_cast<std::size_t>(i)] == 0) next->push_back(i);
    }
    remaining = next;
  }
  return planes;
}

}  // namespace

CloudFeatures ComputeCloudFeatures(const std::vector<Eigen::Vector3f>& points,
                                   const std::optional<Eigen::Vector3d>& up_axis,
                                   const CloudFeatureOptions& options) {
  CloudFeatures features;
  const std::size_t n = points.size();
  features.normals.assign(n, Eigen::Vector3f::UnitZ());
  features.segment.assign(n, 0);
  features.num_segments = 2;
  if (n < 10) return features;
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->reserve(n);
  for (const auto& p : points) cloud->emplace_back(p.x(), p.y(), p.z());
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
  tree->setInputCloud(cloud);

  pcl::PointCloud<pcl::Normal> normals;
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> estimation;
  estimation.setInputCloud(cloud);
  estimation.setSearchMethod(tree);
  estimation.setKSearch(options.normal_neighbours);
  estimation.setViewPoint(0, 0, 0);  // flips every normal towards the sensor
  estimation.compute(normals);
  for (std::size_t i = 0; i < n; ++i) {
    const auto& m = normals[i];
    if (std::isfinite(m.normal_x) && std::isfinite(m.normal_y) && std::isfinite(m.normal_z)) {
      features.normals[i] = Eigen::Vector3f(m.normal_x, m.normal_y, m.normal_z);
    }
  }

  std::vector<char> is_ground(n, 0);
  int next = 1;
  if (!up_axis) {
    // No up axis: planes are classes 1..P, the rest is clustered after them (header).
    std::vector<int> plane_label;
    const int planes = ExtractPlanes(cloud, options, plane_label);
    for (std::size_t i = 0; i < n; ++i) {
      if (plane_label[i] > 0) {
        features.segment[i] = plane_label[i];
        is_ground[i] = 3;  // taken: not clustered below
      }
    }
    next = planes + 1;
  }
  const Eigen::Vector3d up_lidar = up_axis.value_or(Eigen::Vector3d::UnitZ());
  // Ground: the largest plane within ground_max_tilt of horizontal.
  pcl::SACSegmentation<pcl::PointXYZ> sac;  // random = false: a fixed seed
  sac.setOptimizeCoefficients(true);
  sac.setModelType(pcl::SACMODEL_PERPENDICULAR_PLANE);
  sac.setAxis(up_lidar.cast<float>());
  sac.setEpsAngle(options.ground_max_tilt);
  sac.setMethodType(pcl::SAC_RANSAC);
  sac.setDistanceThreshold(options.ground_threshold);
  sac.setMaxIterations(200);
  sac.setInputCloud(cloud);
  pcl::PointIndices ground;
  pcl::ModelCoefficients plane;
  if (up_axis) sac.segment(ground, plane);
  features.ground_points = 0;
  if (plane.values.size() == 4) {
    Eigen::Vector3f normal(plane.values[0], plane.values[1], plane.values[2]);
    float offset = plane.values[3];
    const float norm = normal.norm();
    normal /= norm;
    offset /= norm;
    if (normal.dot(up_lidar.cast<float>()) < 0) {
      normal = -normal;
      offset = -offset;
    }
    // Least-squares refits on ever closer inliers: RANSAC's inliers (±ground_threshold) include
    // the feet of piles and walls, which lift and tilt its least-squares plane by centimetres.
    for (const double band : {0.5 * options.ground_threshold, 2 * options.ground_class_threshold}) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
      double count = 0;
      for (const auto& p : points) {
        if (std::abs(normal.dot(p) + offset) >= band) continue;
        const Eigen::Vector3d q = p.cast<double>();
        sum += q;
        outer += q * q.transpose();
        ++count;
      }
      if (count < 3) break;
      const Eigen::Vector3d mean = sum / count;
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(outer / count -
                                                               mean * mean.transpose());
      Eigen::Vector3d refit = eig.eigenvectors().col(0);
      if (refit.dot(up_lidar) < 0) refit = -refit;
      normal = refit.cast<float>();
      offset = static_cast<float>(-refit.dot(mean));
    }
    std::vector<float> heights(n);
    for (std::size_t i = 0; i < n; ++i) heights[i] = normal.dot(points[i]) + offset;
    // The floor's own noise, robustly: σ = 1.4826 · median |h| over the points near the plane.
    std::vector<float> near_plane;
    for (const float h : heights) {
      if (std::abs(h) < 0.5 * options.ground_threshold) near_plane.push_back(std::abs(h));
    }
    if (!near_plane.empty()) {
      const auto middle = near_plane.begin() + static_cast<std::ptrdiff_t>(near_plane.size() / 2);
      std::nth_element(near_plane.begin(), middle, near_plane.end());
      features.ground_noise = 1.4826 * *middle;
    }
    // Average k neighbours so that ground_noise_sigmas · σ / √k fits in the ground band
    // (header: an unsmoothed noisy floor splits asymmetrically; a smoothed noise-free one pulls
    // the floor next to an object into it, so no more smoothing than the noise asks for).
    const double ratio =
        options.ground_noise_sigmas * features.ground_noise / options.ground_class_threshold;
    features.ground_smoothing_neighbours =
        static_cast<int>(std::clamp(std::ceil(ratio * ratio), 1.0,
                                    static_cast<double>(options.max_ground_smoothing_neighbours)));
    std::vector<float> smoothed = heights;
    if (features.ground_smoothing_neighbours > 1) {
      std::vector<int> neighbours;
      std::vector<float> distances;
      for (std::size_t i = 0; i < n; ++i) {
        tree->nearestKSearch(static_cast<int>(i), features.ground_smoothing_neighbours, neighbours,
                             distances);
        if (neighbours.empty()) continue;
        double sum = 0;
        for (const int j : neighbours) sum += heights[static_cast<std::size_t>(j)];
        smoothed[i] = static_cast<float>(sum / static_cast<double>(neighbours.size()));
      }
    }
    for (std::size_t i = 0; i < n; ++i) {
      const float height = smoothed[i];
      if (std::abs(height) < options.ground_class_threshold) {
        is_ground[i] = 1;
        ++features.ground_points;
      } else if (height < options.object_min_height) {
        is_ground[i] = 2;  // the ambiguous band: a pile's foot, a wall's base, noise: no class
      }
    }
  }
  // The rest: Euclidean clustering, cut at creases too when cluster_normal_angle < π.
  pcl::PointCloud<pcl::PointNormal>::Ptr rest(new pcl::PointCloud<pcl::PointNormal>);
  std::vector<int> rest_index;
  for (std::size_t i = 0; i < n; ++i) {
    if (is_ground[i] != 0) continue;
    pcl::PointNormal q;
    q.x = points[i].x();
    q.y = points[i].y();
    q.z = points[i].z();
    q.normal_x = features.normals[i].x();
    q.normal_y = features.normals[i].y();
    q.normal_z = features.normals[i].z();
    rest->push_back(q);
    rest_index.push_back(static_cast<int>(i));
  }
  std::vector<int> label(rest->size(), -1);
  if (!rest->empty()) {
    const float cos_max = static_cast<float>(std::cos(options.cluster_normal_angle));
    pcl::ConditionalEuclideanClustering<pcl::PointNormal> clustering;
    clustering.setInputCloud(rest);
    clustering.setConditionFunction([cos_max](const pcl::PointNormal& a, const pcl::PointNormal& b,
                                              float) {
      return a.normal_x * b.normal_x + a.normal_y * b.normal_y + a.normal_z * b.normal_z >= cos_max;
    });
    clustering.setClusterTolerance(static_cast<float>(options.cluster_tolerance));
    clustering.setMinClusterSize(options.min_cluster_points);
    clustering.setMaxClusterSize(static_cast<int>(rest->size()));
    pcl::IndicesClusters clusters;
    clustering.segment(clusters);
    for (const auto& cluster : clusters) {
      for (const int j : cluster.indices) label[j] = next;
      ++next;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (is_ground[i] == 2) features.segment[i] = -1;
  }
  for (std::size_t j = 0; j < rest_index.size(); ++j) {
    features.segment[rest_index[j]] = label[j];  // −1: unclustered
  }
  features.num_segments = next;
  return features;
}

}  // namespace autoshovel::identification
