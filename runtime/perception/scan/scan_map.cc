#include "runtime/perception/scan/scan_map.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <queue>

namespace autoshovel::perception {

namespace {

constexpr double kNoReturn = 1e-3;  // [m] closer to the scanner than this: no return

// Connected (8-neighbour) components of cells standing higher than `min_height` above the
// floor; layer "heap" gets 1 + the heap's index (largest first), NaN elsewhere.
std::vector<Heap> FindHeaps(GridMap& map, double min_height, int min_cells, double floor_sigma) {
  const Eigen::MatrixXf& h = map["elevation"];
  const Eigen::MatrixXf& variance = map["variance"];
  const Eigen::MatrixXf& filled = map["filled"];
  const int nx = static_cast<int>(h.rows()), ny = static_cast<int>(h.cols());
  Eigen::MatrixXi label = Eigen::MatrixXi::Constant(nx, ny, -1);
  const double area = map.resolution() * map.resolution();
  std::vector<Heap> heaps;
  std::vector<std::vector<Index>> members;
  for (int x = 0; x < nx; ++x) {
    for (int y = 0; y < ny; ++y) {
      if (label(x, y) >= 0 || !(h(x, y) > min_height)) continue;
      std::vector<Index> cells;
      std::queue<Index> open;
      open.push(Index(x, y));
      label(x, y) = static_cast<int>(members.size());
      while (!open.empty()) {
        const Index c = open.front();
        open.pop();
        cells.push_back(c);
        for (int dx = -1; dx <= 1; ++dx) {
          for (int dy = -1; dy <= 1; ++dy) {
            const Index n = c + Index(dx, dy);
            if (!map.IsValid(n) || label(n.x(), n.y()) >= 0 || !(h(n.x(), n.y()) > min_height)) {
              continue;
            }
            label(n.x(), n.y()) = static_cast<int>(members.size());
            open.push(n);
          }
        }
      }
      members.push_back(std::move(cells));
    }
  }
  std::vector<int> order;
  for (std::size_t k = 0; k < members.size(); ++k) {
    if (static_cast<int>(members[k].size()) >= min_cells) order.push_back(static_cast<int>(k));
  }
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return members[static_cast<std::size_t>(a)].size() >
           members[static_cast<std::size_t>(b)].size();
  });
  map.Add("heap");
  for (std::size_t rank = 0; rank < order.size(); ++rank) {
    const std::vector<Index>& cells = members[static_cast<std::size_t>(order[rank])];
    Heap heap;
    // A filled cell copied its nearest measured neighbour's height (Eq. 9): how wrong that can
    // be is the heap's own relief, so its variance is the spread of the heap's measured heights.
    double n_measured = 0, sum_h = 0, sum_h2 = 0;
    for (const Index& c : cells) {
      if (filled(c.x(), c.y()) > 0) continue;
      const double height = h(c.x(), c.y());
      ++n_measured;
      sum_h += height;
      sum_h2 += height * height;
    }
    const double relief_variance =
        n_measured > 1 ? std::max(0.0, sum_h2 / n_measured - std::pow(sum_h / n_measured, 2))
                       : std::pow(min_height, 2);
    double sum_variance = 0;
    for (const Index& c : cells) {
      const double height = h(c.x(), c.y());
      const bool is_filled = filled(c.x(), c.y()) > 0;
      heap.volume += area * height;
      if (is_filled) {
        heap.filled_volume += area * height;
        ++heap.filled_cells;
        sum_variance += relief_variance;
      } else {
        const double v = variance(c.x(), c.y());
        sum_variance += std::isfinite(v) ? v : relief_variance;
      }
      heap.peak = std::max(heap.peak, height);
      heap.centroid += map.PositionOf(c) * height;
      map.at("heap", c) = static_cast<float>(rank + 1);
    }
    heap.cells = static_cast<int>(cells.size());
    heap.area = area * heap.cells;
    heap.centroid /= std::max(1e-12, heap.volume / area);
    heap.volume_sigma =
        std::sqrt(area * area * sum_variance + std::pow(heap.area * floor_sigma, 2));
    heaps.push_back(heap);
  }
  return heaps;
}

// Points at the scanner's own origin are "no return" (Livox drivers and CloudCompare exports
// write them as 0 0 0): dropped and counted, so that they neither form a "plane" through the
// origin nor a spike in the map. Appends the kept points, in the first cloud's frame.
std::vector<ScanCloud> KeepReturns(const std::vector<ScanCloud>& clouds, long& at_origin,
                                   std::vector<Eigen::Vector3d>& points) {
  std::vector<ScanCloud> kept = clouds;
  for (ScanCloud& c : kept) {
    std::vector<sensors::LidarPoint> returns;
    for (const auto& p : c.cloud.points) {
      if (p.p_sensor.squaredNorm() < kNoReturn * kNoReturn) {
        ++at_origin;
        continue;
      }
      returns.push_back(p);
      points.push_back(c.T_first_scan * p.p_sensor.cast<double>());
    }
    c.cloud.points = std::move(returns);
  }
  return kept;
}

}  // namespace

ScanMap BuildScanMap(const std::vector<ScanCloud>& clouds, const ScanMapOptions& options,
                     const std::vector<ScanCloud>* reference) {
  ScanMap out;
  std::vector<Eigen::Vector3d> points, reference_points;
  const std::vector<ScanCloud> kept = KeepReturns(clouds, out.points_at_origin, points);
  std::vector<ScanCloud> kept_reference;
  if (reference != nullptr) {
    kept_reference = KeepReturns(*reference, out.points_at_origin, reference_points);
  }
  out.points = static_cast<long>(points.size());
  if (kept.empty() || points.empty()) {
    out.failure = "no points";
    return out;
  }
  if (reference != nullptr && reference_points.empty()) {
    out.failure = "the reference scan has no points";
    return out;
  }
  // The floor: of the empty place when there is one (the heap hides it in the scan).
  using Clock = std::chrono::steady_clock;
  auto since = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  auto stage = Clock::now();
  const std::vector<Eigen::Vector3d>& floor_points = reference ? reference_points : points;
  out.ground =
      FindScanGround(floor_points, clouds.front().T_first_scan.translation(), options.ground);
  if (!out.ground.ok) {
    out.failure = (reference ? "reference: " : "") + out.ground.failure;
    return out;
  }
  out.seconds_floor = since(stage);
  stage = Clock::now();
  // The map's extent and cell from the data in the floor's frame.
  Eigen::Vector2d lo(std::numeric_limits<double>::infinity(),
                     std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  for (const std::vector<Eigen::Vector3d>* set : {&points, &reference_points}) {
    for (const auto& p : *set) {
      const Eigen::Vector3d g = out.ground.T_ground_scan * p;
      lo = lo.cwiseMin(g.head<2>());
      hi = hi.cwiseMax(g.head<2>());
    }
  }
  {
    std::vector<double> heights;
    heights.reserve(points.size());
    for (const auto& p : points) heights.push_back((out.ground.T_ground_scan * p).z());
    std::sort(heights.begin(), heights.end());
    out.height_low = heights[heights.size() / 100];
    out.height_high = heights[heights.size() - 1 - heights.size() / 100];
  }
  const Eigen::Vector2d extent = hi - lo;
  const double cell = options.cell > 0 ? options.cell : std::max(0.005, extent.maxCoeff() / 250.0);
  ElevationMapConfig config;
  config.resolution = cell;
  config.length = extent + Eigen::Vector2d::Constant(4 * cell);
  config.alpha_d = options.alpha_d;
  config.max_ray_length = 1e4;
  config.min_ray_length = 0.01;
  config.roughness = std::max(cell, 3 * out.ground.floor.noise);
  config.process_noise = 0;
  config.max_fill_distance = options.max_fill_cells * cell;
  config.max_pose_age = 1e9;
  // A scan is a snapshot: nothing moved between its returns, so no ray needs to clear the
  // cells it passes under (the loader's map clears for the bucket and for dynamic obstacles).
  config.clearing_stride = 0;
  auto build = [&](const std::vector<ScanCloud>& set, ElevationMap& map, long& used) {
    map = ElevationMap(config, 0.5 * (lo + hi));
    for (const ScanCloud& c : set) {
      sensors::PointCloud cloud = c.cloud;
      cloud.stamp = 0;
      used += map.Update(cloud, out.ground.T_ground_scan * c.T_first_scan, 0).fused;
    }
    return map.FillHoles();
  };
  out.cells_filled = build(kept, out.map, out.points_used);
  GridMap& grid = out.map.map();
  double floor_sigma = out.ground.floor.noise / std::sqrt(std::max(1, out.ground.floor.inliers));
  if (reference != nullptr) {
    // Heights above the empty place instead of above the floor plane: the difference where both
    // scans know the cell, with the variances added; the floor plane's error cancels.
    ElevationMap empty;
    long unused = 0;
    build(kept_reference, empty, unused);
    const GridMap& ref = empty.map();
    grid.Add("reference");
    for (GridMap::Iterator it(grid); !it.done(); ++it) {
      const float h_ref = ref.at("elevation", *it);
      grid.at("reference", *it) = h_ref;
      float& h = grid.at("elevation", *it);
      if (!std::isfinite(h) || !std::isfinite(h_ref)) {
        h = std::numeric_limits<float>::quiet_NaN();
        continue;
      }
      h -= h_ref;
      grid.at("variance", *it) += ref.at("variance", *it);
      if (ref.at("filled", *it) > 0) grid.at("filled", *it) = 1;
    }
    floor_sigma = 0;
  }
  for (GridMap::Iterator it(grid); !it.done(); ++it) {
    out.cells_observed += grid.at("observed", *it) > 0 ? 1 : 0;
  }
  out.seconds_map = since(stage);
  stage = Clock::now();
  out.min_heap_height = options.min_heap_height > 0 ? options.min_heap_height
                                                    : std::max(0.01, 4 * out.ground.floor.noise);
  out.heaps = FindHeaps(grid, out.min_heap_height, options.min_heap_cells, floor_sigma);
  out.seconds_heaps = since(stage);
  out.ok = true;
  return out;
}

}  // namespace autoshovel::perception
