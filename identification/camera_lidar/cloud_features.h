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
// - Ground and band are decided on the mean height of the k nearest points, not the point's own
//   height, with k from the floor's own noise. Range noise (σ ≈ 1 cm vertically in the simulated
//   yard) scatters floor points across the ±1.5 cm ground band: unsmoothed, the lower tail went
//   unclassified while the upper tail joined the object clusters next to it (7 % of the floor
//   each at σ = 1 cm), and that asymmetry pulled the F_S optimum ≈ 2 cm up. σ is
//   estimated robustly (1.4826 · median |h| of the points within ground_threshold / 2) and k is
//   the smallest with ground_noise_sigmas · σ / √k ≤ ground_class_threshold. 5σ: a normal tail
//   leaves fewer than 1 in 10⁶ floor points outside the band, under one per frame. More
//   smoothing than that is not free: averaging pulls the floor next to a wall's foot into the
//   wall, and on noise-free clouds k = 12 moved the optimum 2 cm down; so a clean cloud gets
//   k = 1. In the simulated yard k = 11 and the 6-DOF optimum moved from 22–28 mm to 10–15 mm
//   off the truth (docs/camera_lidar_calibration.md).
//
// Without an up axis (a standalone rig: no description says how the LiDAR is mounted, and real
// scenes need not have a dominant floor), the classes are planes and clusters instead: RANSAC
// planes are taken off the cloud one after the other, largest first, while one still holds
// `min_plane_fraction` of the points (at most `max_planes`), each a class; the rest is clustered
// as above. The public CalibAnything implementation segments the same way (plane extraction,
// then Euclidean clusters); it needs no notion of gravity, so a sloped, cluttered or
// wall-dominated scene is segmented as well as a yard.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

namespace autoshovel::identification {

struct CloudFeatureOptions {
  int normal_neighbours = 12;                ///< k of the normal PCA [-]
  double ground_threshold = 0.08;            ///< RANSAC inlier distance of the ground [m]
  double ground_class_threshold = 0.015;     ///< |height| below: class ground [m]
  double object_min_height = 0.015;          ///< between the two: no class [m]; = ground: none
  double ground_max_tilt = 0.35;             ///< ground normal within this of `up` [rad]
  double cluster_tolerance = 0.3;            ///< neighbour radius of the clustering [m]
  double cluster_normal_angle = 3.1416;      ///< ≥ π: plain Euclidean clustering [rad]
  int min_cluster_points = 20;               ///< smaller clusters are "unclustered" [-]
  double ground_noise_sigmas = 5;            ///< smooth until this many σ fit the ground band [-]
  int max_ground_smoothing_neighbours = 32;  ///< cap on k of the height smoothing [-]
  double plane_threshold = 0.1;              ///< no up axis: plane inlier distance [m]
  double min_plane_fraction = 0.02;          ///< no up axis: a plane holds this share [-]
  int max_planes = 12;                       ///< no up axis: planes taken off at most [-]
};

struct CloudFeatures {
  std::vector<Eigen::Vector3f> normals;  ///< unit, towards the sensor
  std::vector<int> segment;              ///< 0 ground, 1..n−1 clusters, −1 no class
  int num_segments = 0;
  int ground_points = 0;
  double ground_noise = 0;              ///< σ of the floor points' heights (robust, MAD) [m]
  int ground_smoothing_neighbours = 1;  ///< k the heights were averaged over (1: none) [-]
};

/// `up_lidar`: the gravity-up axis in the LiDAR frame (from the description's mounting pose);
/// nullopt: planes and clusters (above).
CloudFeatures ComputeCloudFeatures(const std::vector<Eigen::Vector3f>& points_lidar,
                                   const std::optional<Eigen::Vector3d>& up_lidar,
                                   const CloudFeatureOptions& options = {});

}  // namespace autoshovel::identification
