// Per-point attributes the consistency score of seed Eq. (6) needs besides reflectivity
// (Algorithm 1, "positional information, normal vectors, reflectivity, and segment class"):
//
// - Normal: PCA of the k nearest neighbours (pcl::NormalEstimation), flipped towards the sensor
//   (origin of the LiDAR frame) so that the pairwise inner products of F_N compare oriented
//   normals.
// - Segment class: the ground plane (RANSAC, pcl::SACSegmentation with a plane perpendicular to
//   the nominal `up` axis, the largest surface of any yard view and of SAM's largest mask) is
//   class 0; the rest is split by conditional Euclidean clustering (pcl::
//   ConditionalEuclideanClustering): neighbours within `cluster_tolerance` join when their
//   normals differ by less than `cluster_normal_angle`, a region growing that cuts at creases —
//   walls from piles, piles from the floor, a parked loader's faces apart — where a plain
//   Euclidean clustering would merge a pile with the wall it leans on. Clusters smaller than
//   `min_cluster_points` share one last "unclustered" class.
// - Heights between `ground_class_threshold` and `object_min_height` above the ground get no class
//   (−1, they enter no F_S histogram). The band (formerly 1.5–15 cm) is off by default
//   (object_min_height = ground_class_threshold): it sits only at the *bottom* of every object, so
//   moving near structure down in the image cost F_S nothing at the bottom edges while it cleaned
//   the top edges, and the F_S optimum moved 7 cm up; without it the 6-DOF optimum moved from
//   41 mm to 28 mm off the truth (area lookup on, docs "Limits").
#pragma once

#include <Eigen/Core>
#include <vector>

namespace autoshovel::identification {

struct CloudFeatureOptions {
  int normal_neighbours = 12;             ///< k of the normal PCA [-]
  double ground_threshold = 0.08;         ///< RANSAC inlier distance of the ground [m]
  double ground_class_threshold = 0.015;  ///< |height| below: class ground [m]
  double object_min_height = 0.015;       ///< between the two: no class [m]; = ground: none
  double ground_max_tilt = 0.35;          ///< ground normal within this of `up` [rad]
  double cluster_tolerance = 0.3;         ///< neighbour radius of the clustering [m]
  double cluster_normal_angle = 3.1416;   ///< ≥ π: plain Euclidean clustering [rad]
  int min_cluster_points = 20;            ///< smaller clusters are "unclustered" [-]
};

struct CloudFeatures {
  std::vector<Eigen::Vector3f> normals;  ///< unit, towards the sensor
  std::vector<int> segment;              ///< 0 ground, 1..n−1 clusters, −1 no class
  int num_segments = 0;
  int ground_points = 0;
};

/// `up_lidar`: the gravity-up axis in the LiDAR frame (from the description's mounting pose).
CloudFeatures ComputeCloudFeatures(const std::vector<Eigen::Vector3f>& points_lidar,
                                   const Eigen::Vector3d& up_lidar,
                                   const CloudFeatureOptions& options = {});

}  // namespace autoshovel::identification
