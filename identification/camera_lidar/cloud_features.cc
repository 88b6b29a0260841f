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

#include <cmath>

namespace autoshovel::identification {

CloudFeatures ComputeCloudFeatures(const std::vector<Eigen::Vector3f>& points,
                                   const Eigen::Vector3d& up_lidar,
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
  sac.segment(ground, plane);
  std::vector<char> is_ground(n, 0);
  for (const int i : ground.indices) is_ground[i] = 1;
  features.ground_points = static_cast<int>(ground.indices.size());

  // The rest: conditional Euclidean clustering (region growing that cuts at creases).
  pcl::PointCloud<pcl::PointNormal>::Ptr rest(new pcl::PointCloud<pcl::PointNormal>);
  std::vector<int> rest_index;
  for (std::size_t i = 0; i < n; ++i) {
    if (is_ground[i]) continue;
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
  int next = 1;
  std::vector<int> label(rest->size(), -1);
  if (!rest->empty()) {
    const float cos_max = static_cast<float>(std::cos(options.cluster_normal_angle));
    pcl::ConditionalEuclideanClustering<pcl::PointNormal> clustering;
    clustering.setInputCloud(rest);
    clustering.setConditionFunction([cos_max](const pcl::PointNormal& a, const pcl::PointNormal& b,
                                              float) {
      return a.normal_x * b.normal_x + a.normal_y * b.normal_y + a.normal_z * b.normal_z > cos_max;
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
  const int unclustered = next;
  for (std::size_t j = 0; j < rest_index.size(); ++j) {
    features.segment[rest_index[j]] = label[j] >= 0 ? label[j] : unclustered;
  }
  features.num_segments = unclustered + 1;
  return features;
}

}  // namespace autoshovel::identification
