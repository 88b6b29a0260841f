#include "runtime/perception/scan/scan_map.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <queue>
#include <unordered_map>

namespace autoshovel::perception {

namespace {

constexpr double kNoReturn = 1e-3;  // [m] closer to the scanner than this: no return

// The form of the surface over `cells` (the header's quadric reading), from the measured cells
// only: a filled cell copies a neighbour and would only echo it.
SurfaceForm ReadForm(const GridMap& map, const std::vector<Index>& cells, double noise) {
  SurfaceForm form;
  const Eigen::MatrixXf& h = map["elevation"];
  const Eigen::MatrixXf& filled = map["filled"];
  std::vector<Eigen::Vector2d> xy;
  std::vector<double> z;
  for (const Index& c : cells) {
    const float height = h(c.x(), c.y());
    if (filled(c.x(), c.y()) > 0 || !std::isfinite(height)) continue;
    xy.push_back(map.PositionOf(c));
    z.push_back(height);
  }
  if (z.size() < 12) return form;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : xy) mean += p;
  mean /= static_cast<double>(xy.size());
  Eigen::MatrixXd A(static_cast<Eigen::Index>(z.size()), 6);
  Eigen::VectorXd b(static_cast<Eigen::Index>(z.size()));
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  for (std::size_t i = 0; i < z.size(); ++i) {
    const Eigen::Vector2d d = xy[i] - mean;
    A.row(static_cast<Eigen::Index>(i)) << 1, d.x(), d.y(), d.x() * d.x(), d.x() * d.y(),
        d.y() * d.y();
    b(static_cast<Eigen::Index>(i)) = z[i];
    covariance += d * d.transpose();
  }
  covariance /= static_cast<double>(z.size());
  const Eigen::VectorXd c = A.colPivHouseholderQr().solve(b);
  // z = … + xᵀ Q x with Q = [c3, c4/2; c4/2, c5]: its mean over the cells is tr(Q Σ).
  form.height = -(c(3) * covariance(0, 0) + c(4) * covariance(0, 1) + c(5) * covariance(1, 1));
  std::vector<double> sorted = z;
  std::sort(sorted.begin(), sorted.end());
  form.spread = sorted[sorted.size() * 95 / 100] - sorted[sorted.size() * 5 / 100];
  if (std::abs(form.height) < std::max(0.1 * form.spread, 3 * noise)) {
    form.name = "level";
  } else {
    form.name = form.height > 0 ? "heaped" : "drawn down";
  }
  return form;
}

// Connected (8-neighbour) components of cells standing higher than `min_height` above the
// floor; layer "heap" gets 1 + the heap's index (largest first), NaN elsewhere.
std::vector<Heap> FindHeaps(GridMap& map, double min_height, int min_cells, double floor_sigma,
                            double floor_rms) {
  const Eigen::MatrixXf& h = map["elevation"];
  const Eigen::MatrixXf& variance = map["variance"];
  const Eigen::MatrixXf& filled = map["filled"];
  const Eigen::MatrixXf& wall = map["wall"];
  const int nx = static_cast<int>(h.rows()), ny = static_cast<int>(h.cols());
  Eigen::MatrixXi label = Eigen::MatrixXi::Constant(nx, ny, -1);
  const double area = map.resolution() * map.resolution();
  std::vector<Heap> heaps;
  std::vector<std::vector<Index>> members;
  for (int x = 0; x < nx; ++x) {
    for (int y = 0; y < ny; ++y) {
      if (label(x, y) >= 0 || !(h(x, y) > min_height) || wall(x, y) > 0) continue;
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
            if (!map.IsValid(n) || label(n.x(), n.y()) >= 0 || !(h(n.x(), n.y()) > min_height) ||
                wall(n.x(), n.y()) > 0) {
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
    heap.floor_bias = heap.area * floor_rms;
    heap.form = ReadForm(map, cells, floor_rms);
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

// Heights above the empty place instead of above the floor plane: the difference where both
// scans know the cell, with the variances added; the floor plane's error cancels.
void SubtractReference(GridMap& grid, const GridMap& ref) {
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
}

// Isolated returns (a stray echo 3 m under the surface in a real bin scan) are dropped before
// anything is fitted or mapped: alone in their cell they would stand as a pit or spike, and Eq. (9)
// would spread them to the holes around. A return is isolated when the 3 × 3 × 3 voxels of edge
// `voxel` around it hold no more than `min_neighbours` other returns. Voxel counting in a hash
// map, O(n), where PCL's RadiusOutlierRemoval does a kd-tree radius search per point (0.3 s on a
// 200 k-point bin scan, as long as the rest of the mapping). Returns how many were dropped.
long DropIsolatedReturns(std::vector<ScanCloud>& clouds, std::vector<Eigen::Vector3d>& points,
                         double voxel, int min_neighbours) {
  // Voxel indices clamped to ±1.1e12 (a finite coordinate of 1e30 m would overflow the cast);
  // points that far out share the end voxels, which only makes them less likely to be dropped.
  // The hash mixes them in unsigned arithmetic, where overflow wraps.
  auto index = [&](double v, int d) {
    return static_cast<std::uint64_t>(
        static_cast<std::int64_t>(std::clamp(std::floor(v / voxel), -1.1e12, 1.1e12)) + d);
  };
  auto key = [&](const Eigen::Vector3d& p, int dx, int dy, int dz) {
    return (index(p.x(), dx) * 73856093u) ^ (index(p.y(), dy) * 19349663u) ^
           (index(p.z(), dz) * 83492791u);
  };
  std::unordered_map<std::uint64_t, int> count;
  count.reserve(points.size());
  for (const auto& p : points) ++count[key(p, 0, 0, 0)];
  std::vector<char> isolated(points.size(), 0);
  long dropped = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (count[key(points[i], 0, 0, 0)] > min_neighbours) continue;  // dense: not isolated
    int around = 0;
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = count.find(key(points[i], dx, dy, dz));
          if (it != count.end()) around += it->second;
        }
      }
    }
    if (around - 1 < min_neighbours) {
      isolated[i] = 1;
      ++dropped;
    }
  }
  if (dropped == 0) return 0;
  std::size_t k = 0;
  for (ScanCloud& c : clouds) {
    std::vector<sensors::LidarPoint> kept;
    for (const auto& point : c.cloud.points) {
      if (!isolated[k++]) kept.push_back(point);
    }
    c.cloud.points = std::move(kept);
  }
  std::size_t j = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!isolated[i]) points[j++] = points[i];
  }
  points.resize(j);
  return dropped;
}

// The returns on a wall's face (within the RANSAC threshold of its plane) are taken out before
// the map is built: a cell against the wall then holds the material in front of it, not the wall
// face's heights (MarkWalls leaves out what lies behind the face).
void DropWallReturns(std::vector<ScanCloud>& clouds, const ScanGround& ground) {
  if (ground.walls.empty()) return;
  for (ScanCloud& c : clouds) {
    std::erase_if(c.cloud.points, [&](const sensors::LidarPoint& point) {
      const Eigen::Vector3d p = c.T_first_scan * point.p_sensor.cast<double>();
      return std::any_of(ground.walls.begin(), ground.walls.end(), [&](const ScanPlane& wall) {
        return std::abs(wall.normal.dot(p) - wall.offset) < ground.threshold;
      });
    });
  }
}

// Layer "wall": 1 on the cells whose centre lies behind a wall's inner face (the face the scanner
// saw, its normal turned towards the scanner), 0 elsewhere. A bin's walls stand high above its
// floor but are no heap: their cells, and what stands behind them, are left out of the heaps. A
// cell the face crosses counts when its centre is in front, so the cells along a wall are
// counted by half on average, as their area is.
void MarkWalls(GridMap& grid, const ScanGround& ground) {
  grid.Add("wall", 0.f);
  const Eigen::Matrix3d& R = ground.T_ground_scan.linear();
  const Eigen::Vector3d& t = ground.T_ground_scan.translation();
  for (const ScanPlane& wall : ground.walls) {
    const Eigen::Vector3d n = R * wall.normal;  // n · p_ground = offset + n · t
    const double offset = wall.offset + n.dot(t);
    for (GridMap::Iterator it(grid); !it.done(); ++it) {
      const float h = grid.at("elevation", *it);
      const Eigen::Vector2d xy = grid.PositionOf(*it);
      const Eigen::Vector3d p(xy.x(), xy.y(), std::isfinite(h) ? h : 0.0);
      if (n.dot(p) < offset) grid.at("wall", *it) = 1.f;
    }
  }
}

// Registers the reference onto the scans and moves it there (points and clouds' poses); false,
// with the reason in `failure`, when too little of it lands on the scans.
bool RegisterReference(const std::vector<Eigen::Vector3d>& points, const ScanMapOptions& options,
                       std::vector<Eigen::Vector3d>& reference_points,
                       std::vector<ScanCloud>& reference, ScanMap& out) {
  out.registration =
      RegisterScans(reference_points, points, Eigen::Isometry3d::Identity(), options.registration);
  const ScanRegistration& r = *out.registration;
  if (r.overlap < options.min_reference_overlap) {
    char text[400];
    std::snprintf(text, sizeof text,
                  "the reference does not match the scan: after registration %.0f %% of its "
                  "points lie within %.0f mm of the scan (at least %.0f %% needed). Is it a scan "
                  "of the same place, and does the scan show more than the heap? Place it roughly "
                  "with its pose, or leave out --register if both were taken from the same "
                  "scanner pose",
                  100 * r.overlap, 1e3 * r.final_distance, 100 * options.min_reference_overlap);
    out.failure = text;
    return false;
  }
  for (auto& p : reference_points) p = r.T_target_source * p;
  for (ScanCloud& c : reference) c.T_first_scan = r.T_target_source * c.T_first_scan;
  return true;
}

}  // namespace

ScanMap BuildScanMap(const std::vector<ScanCloud>& clouds, const ScanMapOptions& options,
                     const std::vector<ScanCloud>* reference) {
  ScanMap out;
  std::vector<Eigen::Vector3d> points, reference_points;
  std::vector<ScanCloud> kept = KeepReturns(clouds, out.points_at_origin, points);
  std::vector<ScanCloud> kept_reference;
  if (reference != nullptr) {
    kept_reference = KeepReturns(*reference, out.points_at_origin, reference_points);
  }
  out.points = static_cast<long>(points.size());
  if (!points.empty()) {
    const double voxel = 2 * std::max(0.005, ScanExtent(points) / 250.0);
    out.points_isolated = DropIsolatedReturns(kept, points, voxel, options.min_neighbours);
    out.points_isolated +=
        DropIsolatedReturns(kept_reference, reference_points, voxel, options.min_neighbours);
  }
  if (kept.empty() || points.empty()) {
    out.failure = "no points";
    return out;
  }
  if (reference != nullptr && reference_points.empty()) {
    out.failure = "the reference scan has no points";
    return out;
  }
  using Clock = std::chrono::steady_clock;
  auto since = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  auto stage = Clock::now();
  if (reference != nullptr && options.register_reference &&
      !RegisterReference(points, options, reference_points, kept_reference, out)) {
    return out;
  }
  // The floor: of the empty place when there is one (the heap hides it in the scan).
  const std::vector<Eigen::Vector3d>& floor_points = reference ? reference_points : points;
  out.ground =
      FindScanGround(floor_points, clouds.front().T_first_scan.translation(), options.ground);
  // Without a floor, a scan alone still has its surface's relief and form to show. Above a
  // reference, the heights are the difference of two scans: the plane only lays out the grid,
  // and the mean surface of the empty scan serves as well as a floor.
  if (!out.ground.ok && !out.ground.surface) {
    out.failure = (reference ? "reference: " : "") + out.ground.failure;
    return out;
  }
  out.floor_found = out.ground.ok || reference != nullptr;
  if (!out.floor_found) out.failure = out.ground.failure;
  const ScanPlane& plane = out.ground.ok ? out.ground.floor : *out.ground.surface;
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
  config.roughness = std::max(cell, 3 * plane.noise);
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
  DropWallReturns(kept, out.ground);
  DropWallReturns(kept_reference, out.ground);
  out.cells_filled = build(kept, out.map, out.points_used);
  GridMap& grid = out.map.map();
  // The floor's height error (σ / √inliers, shifts the whole heap) and its RMS scatter (the
  // floor_bias bound); a reference's measured floor replaces both with its cells' variances.
  double floor_sigma = plane.noise / std::sqrt(std::max(1, plane.inliers));
  double floor_rms = plane.noise;
  if (reference != nullptr) {
    ElevationMap empty;
    long unused = 0;
    build(kept_reference, empty, unused);
    SubtractReference(grid, empty.map());
    floor_sigma = 0;
    floor_rms = 0;
  }
  for (GridMap::Iterator it(grid); !it.done(); ++it) {
    out.cells_observed += grid.at("observed", *it) > 0 ? 1 : 0;
  }
  out.seconds_map = since(stage);
  stage = Clock::now();
  out.min_heap_height =
      options.min_heap_height > 0 ? options.min_heap_height : std::max(0.01, 4 * plane.noise);
  if (out.floor_found) {
    MarkWalls(grid, out.ground);
    out.heaps =
        FindHeaps(grid, out.min_heap_height, options.min_heap_cells, floor_sigma, floor_rms);
  } else {
    std::vector<Index> cells;
    for (GridMap::Iterator it(grid); !it.done(); ++it) cells.push_back(*it);
    out.surface_form = ReadForm(grid, cells, plane.noise);
  }
  out.seconds_heaps = since(stage);
  out.ok = true;
  return out;
}

}  // namespace autoshovel::perception
