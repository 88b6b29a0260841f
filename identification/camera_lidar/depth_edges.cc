#include "identification/camera_lidar/depth_edges.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

namespace autoshovel::identification {

DepthEdges FindDepthEdges(const std::vector<Eigen::Vector3f>& points,
                          const DepthEdgeOptions& options) {
  const std::size_t n = points.size();
  DepthEdges edges;
  edges.weight.assign(n, 0.f);
  edges.silhouette = points;
  std::vector<float>& weight = edges.weight;
  if (n < 3 || !(options.row_height > 0) || !(options.column_width > 0)) return edges;
  constexpr double kPi = 3.14159265358979323846;
  const int columns = std::max(1, static_cast<int>(std::ceil(2 * kPi / options.column_width)));
  const int reach =
      std::max(1, static_cast<int>(std::lround(options.max_gap / options.column_width)));
  // Rows: the scan lines. Elevations sorted; a gap wider than `row_gap` starts a new row, and so
  // does a row growing past `row_height` (a scanner without lines: fixed bands then). A spinning
  // LiDAR's line jitters in elevation by far less than its line spacing, so one line is one row
  // even where it straddles a fixed bin's boundary.
  std::vector<int> row_of(n, std::numeric_limits<int>::min()), column_of(n, 0);
  std::vector<float> range(n);
  std::vector<std::pair<double, std::size_t>> by_elevation;
  by_elevation.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3f& p = points[i];
    range[i] = p.norm();
    if (!(range[i] > 0.05f) || !std::isfinite(range[i])) continue;
    by_elevation.emplace_back(std::atan2(p.z(), std::hypot(p.x(), p.y())), i);
    const double azimuth = std::atan2(p.y(), p.x()) + kPi;  // [0, 2π]
    column_of[i] = std::min(columns - 1, static_cast<int>(azimuth / options.column_width));
  }
  std::sort(by_elevation.begin(), by_elevation.end());
  int rows_total = 0;
  double row_start = 0, previous = 0;
  for (std::size_t k = 0; k < by_elevation.size(); ++k) {
    const double elevation = by_elevation[k].first;
    if (k == 0 || elevation - previous > options.row_gap ||
        elevation - row_start > options.row_height) {
      ++rows_total;
      row_start = elevation;
    }
    previous = elevation;
    row_of[by_elevation[k].second] = rows_total - 1;
  }
  // One point per cell (the nearest): a range image, row → column → point.
  std::vector<std::vector<int>> rows(static_cast<std::size_t>(rows_total));
  for (std::size_t i = 0; i < n; ++i) {
    if (row_of[i] == std::numeric_limits<int>::min()) continue;
    std::vector<int>& row = rows[static_cast<std::size_t>(row_of[i])];
    if (row.empty()) row.assign(static_cast<std::size_t>(columns), -1);
    int& cell = row[static_cast<std::size_t>(column_of[i])];
    if (cell < 0 || range[static_cast<std::size_t>(cell)] > range[i]) cell = static_cast<int>(i);
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (row_of[i] == std::numeric_limits<int>::min()) continue;
    const std::vector<int>& row = rows[static_cast<std::size_t>(row_of[i])];
    float jump = 0;
    int far_side = -1;
    for (const int direction : {-1, 1}) {
      int neighbour = -1;
      for (int step = 1; step <= reach && neighbour < 0; ++step) {
        const int c = ((column_of[i] + direction * step) % columns + columns) % columns;
        const int j = row[static_cast<std::size_t>(c)];
        if (j >= 0 && j != static_cast<int>(i)) neighbour = j;
      }
      if (neighbour < 0) continue;  // nothing beside on this side: sky, or the cloud's end
      const float this_jump = range[static_cast<std::size_t>(neighbour)] - range[i];
      if (this_jump > jump) {
        jump = this_jump;
        far_side = neighbour;
      }
    }
    if (jump < options.min_jump || jump < options.min_relative * range[i]) continue;
    weight[i] =
        static_cast<float>(std::pow(std::min<double>(jump, options.max_jump), options.exponent));
    // The silhouette lies between this point and its far neighbour: on average half way, at
    // this point's range (the object's) — turned about the LiDAR's z axis by half the azimuth
    // step.
    const Eigen::Vector3f& q = points[static_cast<std::size_t>(far_side)];
    double step = std::atan2(q.y(), q.x()) - std::atan2(points[i].y(), points[i].x());
    if (step > kPi) step -= 2 * kPi;
    if (step < -kPi) step += 2 * kPi;
    edges.silhouette[i] =
        Eigen::AngleAxisf(static_cast<float>(0.5 * step), Eigen::Vector3f::UnitZ()) * points[i];
  }
  return edges;
}

std::vector<float> DepthEdgeWeights(const std::vector<Eigen::Vector3f>& points,
                                    const DepthEdgeOptions& options) {
  return FindDepthEdges(points, options).weight;
}

}  // namespace autoshovel::identification
