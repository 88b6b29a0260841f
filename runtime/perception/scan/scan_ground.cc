// The PCL translation unit of the scan's ground and walls (PCL headers stay out of headers).
#include "runtime/perception/scan/scan_ground.h"

#include <pcl/ModelCoefficients.h>
#include <pcl/console/print.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

namespace autoshovel::perception {

namespace {

Eigen::Vector3d Centroid(const std::vector<Eigen::Vector3d>& points,
                         const std::vector<int>& indices) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const int i : indices) c += points[static_cast<std::size_t>(i)];
  return c / static_cast<double>(std::max<std::size_t>(1, indices.size()));
}

// The robust σ of distances to a plane: 1.4826 · their median (the median absolute deviation
// of a normal distribution's σ); 0 for none.
double RobustSigma(std::vector<double> distances) {
  if (distances.empty()) return 0.0;
  auto middle = distances.begin() + static_cast<std::ptrdiff_t>(distances.size() / 2);
  std::nth_element(distances.begin(), middle, distances.end());
  return 1.4826 * *middle;
}

// Least-squares plane through `points[i]` for i in `indices`; normal oriented like `hint`.
ScanPlane Refit(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& indices,
                const Eigen::Vector3d& hint) {
  ScanPlane plane;
  const Eigen::Vector3d mean = Centroid(points, indices);
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const int i : indices) {
    const Eigen::Vector3d d = points[static_cast<std::size_t>(i)] - mean;
    scatter += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);
  plane.normal = eig.eigenvectors().col(0);
  if (plane.normal.dot(hint) < 0) plane.normal = -plane.normal;
  plane.offset = plane.normal.dot(mean);
  plane.inliers = static_cast<int>(indices.size());
  std::vector<double> distances;
  for (const int i : indices) {
    distances.push_back(
        std::abs(plane.normal.dot(points[static_cast<std::size_t>(i)]) - plane.offset));
  }
  plane.noise = RobustSigma(std::move(distances));
  return plane;
}

// The largest plane among `remaining` (RANSAC), its inliers in `inliers`. RANSAC runs on at
// most 10 000 of them (evenly strided: a plane holding 5 % of a scan still has 500 there);
// the inliers are then every remaining point within `threshold` of its plane.
bool LargestPlane(const pcl::PointCloud<pcl::PointXYZ>::Ptr& cloud,
                  const pcl::IndicesPtr& remaining, double threshold, std::vector<int>& inliers) {
  constexpr std::size_t kSample = 10000;
  pcl::IndicesPtr sample = remaining;
  if (remaining->size() > kSample) {
    sample.reset(new pcl::Indices);
    const std::size_t stride = (remaining->size() + kSample - 1) / kSample;
    for (std::size_t k = 0; k < remaining->size(); k += stride) sample->push_back((*remaining)[k]);
  }
  pcl::SACSegmentation<pcl::PointXYZ> sac;  // random = false: a fixed seed
  sac.setOptimizeCoefficients(true);
  sac.setModelType(pcl::SACMODEL_PLANE);
  sac.setMethodType(pcl::SAC_RANSAC);
  sac.setDistanceThreshold(threshold);
  sac.setMaxIterations(500);
  sac.setInputCloud(cloud);
  sac.setIndices(sample);
  pcl::PointIndices found;
  pcl::ModelCoefficients coefficients;
  sac.segment(found, coefficients);
  inliers.clear();
  if (coefficients.values.size() != 4 || found.indices.empty()) return false;
  Eigen::Vector4d plane(coefficients.values[0], coefficients.values[1], coefficients.values[2],
                        coefficients.values[3]);
  plane /= plane.head<3>().norm();
  for (const int i : *remaining) {
    const auto& p = (*cloud)[static_cast<std::size_t>(i)];
    if (std::abs(plane.x() * p.x + plane.y() * p.y + plane.z() * p.z + plane.w()) < threshold) {
      inliers.push_back(i);
    }
  }
  return !inliers.empty();
}

// The ground frame on `plane`: z along its normal; x the scanner's direction of view projected on
// it (so the pictures look the way the scanner looked); origin on the plane below `centroid`.
Eigen::Isometry3d GroundFrame(const ScanPlane& plane, const Eigen::Vector3d& centroid,
                              const Eigen::Vector3d& scanner_origin) {
  const Eigen::Vector3d z = plane.normal;
  Eigen::Vector3d view = centroid - scanner_origin;
  view -= view.dot(z) * z;
  if (view.norm() < 1e-6) view = z.unitOrthogonal();
  const Eigen::Vector3d x = view.normalized(), y = z.cross(x);
  Eigen::Isometry3d T_scan_ground = Eigen::Isometry3d::Identity();
  T_scan_ground.linear() << x, y, z;
  T_scan_ground.translation() = centroid - (z.dot(centroid) - plane.offset) * z;
  return T_scan_ground.inverse();
}

// The user's floor n·p = d: unit normal facing the scanner (or `up`); its noise from the points
// within `threshold` of it, if the scan shows any of it.
ScanPlane GivenFloor(const Eigen::Vector4d& given, const std::vector<Eigen::Vector3d>& points,
                     const Eigen::Vector3d& scanner_origin,
                     const std::optional<Eigen::Vector3d>& up, double threshold,
                     std::vector<int>& inliers) {
  const double norm = given.head<3>().norm();
  if (!given.allFinite() || !(norm > 0)) {
    throw std::invalid_argument("the floor plane needs a finite, non-zero normal");
  }
  ScanPlane plane;
  plane.normal = given.head<3>() / norm;
  plane.offset = given.w() / norm;
  const double side = up ? plane.normal.dot(*up) : plane.normal.dot(scanner_origin) - plane.offset;
  if (side < 0) {
    plane.normal = -plane.normal;
    plane.offset = -plane.offset;
  }
  std::vector<double> distances;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double d = std::abs(plane.normal.dot(points[i]) - plane.offset);
    if (d < threshold) {
      inliers.push_back(static_cast<int>(i));
      distances.push_back(d);
    }
  }
  plane.inliers = static_cast<int>(inliers.size());
  if (distances.size() >= 3) plane.noise = RobustSigma(std::move(distances));
  return plane;
}

struct FloorCandidate {
  ScanPlane plane;
  std::vector<int> inliers;
  double above = 0;  // share of all points on the plane or on its upper side
};

// The floor's candidates: the largest planes, taken off one after the other, up to the first
// with the scene above it (planes come off largest first, so that one is the floor). A heap that
// covers most of a bin's floor offers a large, gently sloping plane of its own, with the floor
// and the walls' feet below it; the floor has (almost) everything on its scanner side. With `up`
// given, planes steeper than 30° to it are passed over.
std::vector<FloorCandidate> FloorCandidates(const std::vector<Eigen::Vector3d>& points,
                                            const pcl::PointCloud<pcl::PointXYZ>::Ptr& cloud,
                                            const Eigen::Vector3d& scanner_origin,
                                            const ScanGroundOptions& options, double threshold) {
  std::vector<FloorCandidate> candidates;
  std::vector<char> taken(points.size(), 0);
  for (int attempt = 0; attempt < options.floor_candidates; ++attempt) {
    pcl::IndicesPtr remaining(new pcl::Indices);
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (!taken[i]) remaining->push_back(static_cast<int>(i));
    }
    std::vector<int> found;
    if (remaining->size() < options.min_ground_fraction * static_cast<double>(points.size()) ||
        !LargestPlane(cloud, remaining, threshold, found) ||
        found.size() < options.min_ground_fraction * static_cast<double>(points.size())) {
      break;
    }
    for (const int i : found) taken[static_cast<std::size_t>(i)] = 1;
    const Eigen::Vector3d hint = options.up.value_or(scanner_origin - Centroid(points, found));
    ScanPlane plane = Refit(points, found, hint);
    std::vector<int> close;
    for (const int i : found) {
      if (std::abs(plane.normal.dot(points[static_cast<std::size_t>(i)]) - plane.offset) <
          0.5 * threshold) {
        close.push_back(i);
      }
    }
    if (close.size() >= 3) plane = Refit(points, close, hint);
    plane.inliers = static_cast<int>(found.size());
    if (options.up && plane.normal.dot(options.up->normalized()) < std::cos(0.5236)) continue;
    FloorCandidate c{plane, std::move(found), 0};
    long above = 0;
    for (const auto& p : points) {
      above += plane.normal.dot(p) - plane.offset > -2 * threshold ? 1 : 0;
    }
    c.above = static_cast<double>(above) / static_cast<double>(points.size());
    candidates.push_back(std::move(c));
    // Planes come off largest first: the first with the scene above it is the floor.
    if (candidates.back().above >= options.floor_min_above) break;
  }
  return candidates;
}

// Walls: further large planes, steep to the floor (normal `up`), after the floor's `inliers`.
// Gentler planes (slabs of a heap's flanks, which stand no steeper than the material's angle of
// repose) are taken off and passed over.
std::vector<ScanPlane> FindWalls(const std::vector<Eigen::Vector3d>& points,
                                 const pcl::PointCloud<pcl::PointXYZ>::Ptr& cloud,
                                 const std::vector<int>& inliers, const Eigen::Vector3d& up,
                                 const Eigen::Vector3d& scanner_origin,
                                 const ScanGroundOptions& options, double threshold) {
  std::vector<ScanPlane> walls;
  std::vector<char> taken(points.size(), 0);
  for (const int i : inliers) taken[static_cast<std::size_t>(i)] = 1;
  for (int k = 0; k < 3 * options.max_walls && static_cast<int>(walls.size()) < options.max_walls;
       ++k) {
    pcl::IndicesPtr next(new pcl::Indices);
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (!taken[i]) next->push_back(static_cast<int>(i));
    }
    if (next->size() < options.min_plane_fraction * static_cast<double>(points.size())) break;
    std::vector<int> wall_inliers;
    if (!LargestPlane(cloud, next, threshold, wall_inliers)) break;
    if (wall_inliers.size() < options.min_plane_fraction * static_cast<double>(points.size())) {
      break;
    }
    for (const int i : wall_inliers) taken[static_cast<std::size_t>(i)] = 1;
    const ScanPlane wall =
        Refit(points, wall_inliers, scanner_origin - Centroid(points, wall_inliers));
    if (std::acos(std::min(1.0, std::abs(wall.normal.dot(up)))) >= options.wall_min_tilt) {
      walls.push_back(wall);
    }
  }
  return walls;
}

}  // namespace

double ScanExtent(const std::vector<Eigen::Vector3d>& points) {
  if (points.empty()) return 0.0;
  Eigen::Vector3d lo = points.front(), hi = points.front();
  for (const auto& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return (hi - lo).norm();
}

ScanGround FindScanGround(const std::vector<Eigen::Vector3d>& points,
                          const Eigen::Vector3d& scanner_origin, const ScanGroundOptions& options) {
  ScanGround ground;
  if (points.size() < 100) {
    ground.failure = "too few points (" + std::to_string(points.size()) + ") to find a floor";
    return ground;
  }
  const double extent = ScanExtent(points);
  ground.threshold =
      options.threshold > 0 ? options.threshold : std::clamp(0.005 * extent, 0.005, 0.05);
  // RANSAC on a scan meets degenerate samples by the thousand; PCL warns about each one.
  pcl::console::setVerbosityLevel(pcl::console::L_ERROR);
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->reserve(points.size());
  for (const auto& p : points) {
    cloud->emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()),
                        static_cast<float>(p.z()));
  }

  std::vector<int> inliers;
  if (options.floor) {
    ground.floor =
        GivenFloor(*options.floor, points, scanner_origin, options.up, ground.threshold, inliers);
    ground.floor_given = true;
    ground.ok = true;
  } else {
    const std::vector<FloorCandidate> candidates =
        FloorCandidates(points, cloud, scanner_origin, options, ground.threshold);
    // The largest candidate with the scene standing on it.
    const FloorCandidate* chosen = nullptr;
    const FloorCandidate* largest = nullptr;
    for (const FloorCandidate& c : candidates) {
      ground.best_above = std::max(ground.best_above, c.above);
      if (largest == nullptr || c.plane.inliers > largest->plane.inliers) largest = &c;
      if (c.above < options.floor_min_above) continue;
      if (chosen == nullptr || c.plane.inliers > chosen->plane.inliers) chosen = &c;
    }
    if (largest == nullptr) {
      ground.failure = "no floor: no plane holds " +
                       std::to_string(static_cast<int>(100 * options.min_ground_fraction)) +
                       " % of the " + std::to_string(points.size()) +
                       " points; scan some ground around the heap, or give --reference "
                       "(a scan of the empty place)";
      return ground;
    }
    if (chosen == nullptr) {
      // No plane bounds the scene: the scan shows no floor (see the header).
      char text[400];
      std::snprintf(text, sizeof text,
                    "no floor in view: no plane has the scene above it (the best has %.1f %% of "
                    "the points above it, a floor %.0f %%); the scan shows one surface, the top "
                    "of a heap that hides the floor. Its relief and form are mapped; for its "
                    "volume give the floor (--floor a,b,c,d: the plane a x + b y + c z = d in "
                    "the first cloud's frame) or a scan of the empty place (--reference)",
                    100 * ground.best_above, 100 * options.floor_min_above);
      ground.failure = text;
      // The surface's mean plane: least squares over every point (the largest RANSAC plane may
      // be one flank of the heap).
      std::vector<int> all(points.size());
      for (std::size_t i = 0; i < points.size(); ++i) all[i] = static_cast<int>(i);
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (const auto& p : points) mean += p;
      mean /= static_cast<double>(points.size());
      ScanPlane surface = Refit(points, all, options.up.value_or(scanner_origin - mean));
      surface.inliers = largest->plane.inliers;
      surface.noise = largest->plane.noise;
      ground.surface = surface;
      ground.T_ground_scan = GroundFrame(surface, mean, scanner_origin);
      return ground;
    }
    ground.floor = chosen->plane;
    ground.ok = true;
    inliers = chosen->inliers;
  }
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  if (!inliers.empty()) {
    centroid = Centroid(points, inliers);
  } else {  // a given floor the scan does not show: below the points' centroid
    for (const auto& p : points) centroid += p;
    centroid /= static_cast<double>(points.size());
  }
  ground.T_ground_scan = GroundFrame(ground.floor, centroid, scanner_origin);
  const Eigen::Vector3d z = ground.floor.normal;

  ground.walls = FindWalls(points, cloud, inliers, z, scanner_origin, options, ground.threshold);
  return ground;
}

}  // namespace autoshovel::perception
