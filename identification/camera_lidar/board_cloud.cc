// The PCL translation unit of the board detection in the point cloud (board_geometry.h).
#include <pcl/ModelCoefficients.h>
#include <pcl/features/boundary.h>
#include <pcl/filters/extract_indices.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <algorithm>
#include <cmath>
#include <nlopt.hpp>

#include "identification/camera_lidar/board_geometry.h"

namespace autoshovel::identification {

std::vector<Eigen::Vector3d> BoardGeometry::HoleCorners() const {
  std::vector<Eigen::Vector3d> corners;
  const double h = 0.5 * hole_side, o = hole_offset;
  const double centres[4][2] = {{-o, o}, {o, o}, {o, -o}, {-o, -o}};  // TL TR BR BL
  const double signs[4][2] = {{-1, 1}, {1, 1}, {1, -1}, {-1, -1}};
  for (const auto& c : centres) {
    for (const auto& s : signs) corners.emplace_back(c[0] + s[0] * h, c[1] + s[1] * h, 0.0);
  }
  return corners;
}

bool BoardGeometry::IsMaterial(double x, double y) const {
  const double s = 0.5 * side, h = 0.5 * hole_side;
  if (std::abs(x) > s || std::abs(y) > s) return false;
  return !(std::abs(std::abs(x) - hole_offset) < h && std::abs(std::abs(y) - hole_offset) < h);
}

std::string BoardGeometry::Check() const {
  if (!(side > 0) || !(hole_side > 0) || !(hole_offset > 0)) return "sizes must be > 0 m";
  if (hole_offset < 0.5 * hole_side + 0.02) return "holes overlap (hole_offset < hole_side/2)";
  if (hole_offset + 0.5 * hole_side > 0.5 * side - 0.02) return "holes reach the board's edge";
  return "";
}

namespace {

// Distance from p to the segment a–b.
double SegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                       const Eigen::Vector2d& b) {
  const Eigen::Vector2d d = b - a;
  const double t = std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
  return (a + t * d - p).norm();
}

struct TemplateFit {
  std::vector<Eigen::Vector2d> points;                // boundary points, plane coordinates [m]
  std::vector<std::array<Eigen::Vector2d, 2>> edges;  // template edges, board frame [m]
  double cap = 0.04;  // truncation of the point-to-edge distance [m]

  double Cost(const double* x) const {
    const double c = std::cos(x[2]), s = std::sin(x[2]);
    double sum = 0;
    for (const auto& p : points) {
      const Eigen::Vector2d d = p - Eigen::Vector2d(x[0], x[1]);
      const Eigen::Vector2d q(c * d.x() + s * d.y(), -s * d.x() + c * d.y());  // board frame
      double best = cap;
      for (const auto& e : edges) best = std::min(best, SegmentDistance(q, e[0], e[1]));
      sum += best * best;
    }
    return sum;
  }
};

}  // namespace

BoardCloudDetection DetectBoardInCloud(const std::vector<Eigen::Vector3f>& points_lidar,
                                       const BoardGeometry& board, const Eigen::Vector3d& up_lidar,
                                       const Eigen::Vector3d& boresight_lidar) {
  BoardCloudDetection out;
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  for (const auto& p : points_lidar) cloud->emplace_back(p.x(), p.y(), p.z());
  // Up to three planes by RANSAC, largest first; the board is the first one facing the sensor
  // (normal within 60° of the boresight): the floor, larger, is skipped.
  Eigen::Vector4d best_plane = Eigen::Vector4d::Zero();
  bool found = false;
  for (int k = 0; k < 3 && cloud->size() > 50 && !found; ++k) {
    pcl::SACSegmentation<pcl::PointXYZ> sac;  // random = false: a fixed seed
    sac.setOptimizeCoefficients(true);
    sac.setModelType(pcl::SACMODEL_PLANE);
    sac.setMethodType(pcl::SAC_RANSAC);
    sac.setDistanceThreshold(0.05);
    sac.setMaxIterations(300);
    sac.setInputCloud(cloud);
    pcl::PointIndices::Ptr inliers(new pcl::PointIndices);
    pcl::ModelCoefficients coefficients;
    sac.segment(*inliers, coefficients);
    if (inliers->indices.size() < 50 || coefficients.values.size() != 4) break;
    const Eigen::Vector4d plane(coefficients.values[0], coefficients.values[1],
                                coefficients.values[2], coefficients.values[3]);
    found = std::abs(plane.head<3>().normalized().dot(boresight_lidar.normalized())) > 0.5;
    pcl::PointCloud<pcl::PointXYZ>::Ptr part(new pcl::PointCloud<pcl::PointXYZ>);
    pcl::ExtractIndices<pcl::PointXYZ> extract;
    extract.setInputCloud(cloud);
    extract.setIndices(inliers);
    extract.setNegative(!found);  // the board's inliers, or everything but this plane
    extract.filter(*part);
    cloud = part;
    if (found) best_plane = plane;
  }
  if (!found) {
    out.failure = "no plane facing the sensor (the board) found in the cloud";
    return out;
  }
  // `cloud` now holds the board plane's inliers. Board frame axes.
  Eigen::Vector3d normal = best_plane.head<3>();
  const double norm = normal.norm();
  double d = best_plane.w() / norm;
  normal /= norm;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : *cloud) centroid += Eigen::Vector3d(p.x, p.y, p.z);
  centroid /= static_cast<double>(cloud->size());
  if (normal.dot(-centroid) < 0) {
    normal = -normal;
    d = -d;
  }
  Eigen::Vector3d y_axis = up_lidar - up_lidar.dot(normal) * normal;
  if (y_axis.norm() < 0.3) {
    out.failure = "the board plane is nearly horizontal";
    return out;
  }
  y_axis.normalize();
  const Eigen::Vector3d x_axis = y_axis.cross(normal);
  const Eigen::Vector3d origin = centroid - (normal.dot(centroid) + d) * normal;
  out.plane_inliers = static_cast<int>(cloud->size());

  // Boundary points of the board (outer edge and holes), the normals all the plane's.
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  normals->resize(cloud->size());
  for (auto& m : *normals) {
    m.normal_x = static_cast<float>(normal.x());
    m.normal_y = static_cast<float>(normal.y());
    m.normal_z = static_cast<float>(normal.z());
  }
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
  pcl::BoundaryEstimation<pcl::PointXYZ, pcl::Normal, pcl::Boundary> boundary;
  boundary.setInputCloud(cloud);
  boundary.setInputNormals(normals);
  boundary.setSearchMethod(tree);
  boundary.setKSearch(20);
  boundary.setAngleThreshold(M_PI / 2);
  pcl::PointCloud<pcl::Boundary> flags;
  boundary.compute(flags);
  TemplateFit fit;
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    if (!flags[i].boundary_point) continue;
    const Eigen::Vector3d p((*cloud)[i].x, (*cloud)[i].y, (*cloud)[i].z);
    fit.points.emplace_back((p - origin).dot(x_axis), (p - origin).dot(y_axis));
  }
  out.boundary_points = static_cast<int>(fit.points.size());
  if (fit.points.size() < 40) {
    out.failure =
        "too few boundary points on the board (" + std::to_string(fit.points.size()) + ")";
    return out;
  }
  const double s = 0.5 * board.side, h = 0.5 * board.hole_side, o = board.hole_offset;
  auto add_square = [&](double cx, double cy, double half) {
    const Eigen::Vector2d c[4] = {{cx - half, cy - half},
                                  {cx + half, cy - half},
                                  {cx + half, cy + half},
                                  {cx - half, cy + half}};
    for (int k = 0; k < 4; ++k) fit.edges.push_back({c[k], c[(k + 1) % 4]});
  };
  add_square(0, 0, s);
  for (const double sx : {-1.0, 1.0}) {
    for (const double sy : {-1.0, 1.0}) add_square(sx * o, sy * o, h);
  }
  // Start: an exhaustive search (chamfer matching) around the centroid of the boundary points
  // over ±0.2 m and ±40°, on a precomputed grid of the truncated distance to the template edges
  // (5 mm cells) and at most 300 of the points; the cost has local minima a hole's width apart,
  // too many for Nelder–Mead alone. Nelder–Mead on the exact distances refines the best cell.
  Eigen::Vector2d start = Eigen::Vector2d::Zero();
  for (const auto& p : fit.points) start += p;
  start /= static_cast<double>(fit.points.size());
  const double cell = 0.005, extent = s + 0.05;
  const int cells = static_cast<int>(std::ceil(2 * extent / cell)) + 1;
  std::vector<float> distance(static_cast<std::size_t>(cells) * cells);
  for (int iy = 0; iy < cells; ++iy) {
    for (int ix = 0; ix < cells; ++ix) {
      const Eigen::Vector2d q(-extent + ix * cell, -extent + iy * cell);
      double best = fit.cap;
      for (const auto& e : fit.edges) best = std::min(best, SegmentDistance(q, e[0], e[1]));
      distance[static_cast<std::size_t>(iy) * cells + ix] = static_cast<float>(best * best);
    }
  }
  std::vector<Eigen::Vector2d> sample;
  const std::size_t stride = std::max<std::size_t>(1, fit.points.size() / 300);
  for (std::size_t i = 0; i < fit.points.size(); i += stride) sample.push_back(fit.points[i]);
  std::vector<double> x = {start.x(), start.y(), 0.0};
  double best_cost = 1e300;
  const float outside = static_cast<float>(fit.cap * fit.cap);
  for (double theta = -0.7; theta <= 0.7; theta += 0.03) {
    const double c = std::cos(theta), sn = std::sin(theta);
    for (double dx = -0.2; dx <= 0.2; dx += 0.015) {
      for (double dy = -0.2; dy <= 0.2; dy += 0.015) {
        double cost = 0;
        for (const auto& p : sample) {
          const Eigen::Vector2d offset = p - start - Eigen::Vector2d(dx, dy);
          const double fx = (c * offset.x() + sn * offset.y() + extent) / cell + 0.5;
          const double fy = (-sn * offset.x() + c * offset.y() + extent) / cell + 0.5;
          const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
          cost += (fx < 0 || fy < 0 || ix >= cells || iy >= cells)
                      ? outside
                      : distance[static_cast<std::size_t>(iy) * cells + ix];
        }
        if (cost < best_cost) {
          best_cost = cost;
          x = {start.x() + dx, start.y() + dy, theta};
        }
      }
    }
  }
  nlopt::opt opt(nlopt::LN_NELDERMEAD, 3);
  opt.set_min_objective([](const std::vector<double>& v, std::vector<double>&,
                           void* data) { return static_cast<TemplateFit*>(data)->Cost(v.data()); },
                        &fit);
  opt.set_initial_step(std::vector<double>{0.01, 0.01, 0.02});
  opt.set_xtol_abs(1e-7);
  opt.set_maxeval(3000);
  for (int pass = 0; pass < 3; ++pass) {
    double f = 0;
    try {
      opt.optimize(x, f);
    } catch (const std::exception&) {
    }
    fit.cap = pass == 0 ? 0.02 : 0.012;  // tighten the truncation once near the solution
  }
  double rms = 0;
  int inside = 0;
  {
    const double c = std::cos(x[2]), sn = std::sin(x[2]);
    for (const auto& p : fit.points) {
      const Eigen::Vector2d dd = p - Eigen::Vector2d(x[0], x[1]);
      const Eigen::Vector2d q(c * dd.x() + sn * dd.y(), -sn * dd.x() + c * dd.y());
      double best = 1e9;
      for (const auto& e : fit.edges) best = std::min(best, SegmentDistance(q, e[0], e[1]));
      if (best < fit.cap) {
        rms += best * best;
        ++inside;
      }
    }
  }
  out.edge_rms = inside ? std::sqrt(rms / inside) : 0;
  Eigen::Matrix3d R_lidar_plane;
  R_lidar_plane.col(0) = x_axis;
  R_lidar_plane.col(1) = y_axis;
  R_lidar_plane.col(2) = normal;
  const Eigen::Matrix3d R_plane_board =
      Eigen::AngleAxisd(x[2], Eigen::Vector3d::UnitZ()).toRotationMatrix();
  out.T_lidar_board.linear() = R_lidar_plane * R_plane_board;
  out.T_lidar_board.translation() = origin + x[0] * x_axis + x[1] * y_axis;
  for (const auto& c : board.HoleCorners()) out.corners_lidar.push_back(out.T_lidar_board * c);
  out.ok = true;
  return out;
}

}  // namespace autoshovel::identification
