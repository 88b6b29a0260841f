#include "runtime/app/map_cloud_command.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <numbers>
#include <ostream>
#include <sstream>

#include "identification/camera_lidar/ply_io.h"
#include "identification/camera_lidar/point_cloud_io.h"
#include "runtime/core/diagnostics.h"
#include "runtime/core/file_output.h"
#include "runtime/perception/scan/geotiff_export.h"
#include "runtime/perception/scan/scan_map.h"
#include "runtime/perception/scan/scan_poses.h"
#include "runtime/perception/scan/scan_render.h"

namespace autoshovel::app {

namespace {

Eigen::Isometry3d PoseOf(const double* v) {
  return perception::PoseFromXyzRpyDegrees(v[0], v[1], v[2], v[3], v[4], v[5]);
}

void WriteHeapsCsv(const std::string& path, const perception::ScanMap& map) {
  std::ostringstream csv;
  csv << "heap,volume_m3,volume_sigma_m3,filled_volume_m3,area_m2,peak_m,cells,filled_cells,"
         "centroid_x_m,centroid_y_m\n";
  char line[256];
  for (std::size_t k = 0; k < map.heaps.size(); ++k) {
    const perception::Heap& h = map.heaps[k];
    std::snprintf(line, sizeof line, "%zu,%.6g,%.6g,%.6g,%.6g,%.6g,%d,%d,%.4f,%.4f\n", k + 1,
                  h.volume, h.volume_sigma, h.filled_volume, h.area, h.peak, h.cells,
                  h.filled_cells, h.centroid.x(), h.centroid.y());
    csv << line;
  }
  core::WriteFileAtomically(path, csv.str());
}

}  // namespace

int RunMapCloud(const MapCloudOptions& options, std::ostream& out, std::ostream& err) {
  const char* const kCommand = "autoshovel map --cloud";
  try {
    if (options.clouds.empty()) {
      err << kCommand << ": give one or more point clouds (.pcd, .bin)\n";
      return 2;
    }
    if (!options.poses.empty() && options.poses.size() != 6 * options.clouds.size()) {
      err << kCommand << ": --pose needs 6 values (x y z roll pitch yaw) for every --cloud, got "
          << options.poses.size() << " values for " << options.clouds.size() << " clouds\n";
      return 2;
    }
    if (!options.poses.empty() && !options.poses_file.empty()) {
      err << kCommand << ": give --pose or --poses, not both\n";
      return 2;
    }
    std::map<std::string, Eigen::Isometry3d> pose_by_name;
    if (!options.poses_file.empty()) {
      pose_by_name = perception::ReadScanPoses(options.poses_file);
      for (const std::string& cloud : options.clouds) {
        const std::string name = std::filesystem::path(cloud).filename().string();
        if (pose_by_name.count(name) == 0) {
          err << options.poses_file << ": no pose for the cloud '" << name << "'\n";
          return 2;
        }
      }
    }
    if (!options.up.empty() && options.up.size() != 3) {
      err << kCommand << ": --up needs 3 values (x y z)\n";
      return 2;
    }
    const auto start = std::chrono::steady_clock::now();
    // Read and check every cloud before anything is computed or written.
    std::vector<perception::ScanCloud> clouds;
    std::size_t non_finite = 0;
    for (std::size_t k = 0; k < options.clouds.size(); ++k) {
      perception::ScanCloud c;
      c.name = options.clouds[k];
      identification::PointCloudReadStats stats;
      c.cloud = identification::ReadPointCloud(c.name, options.max_points, &stats);
      non_finite += stats.non_finite;
      if (!options.poses.empty()) c.T_first_scan = PoseOf(&options.poses[6 * k]);
      if (!pose_by_name.empty()) {
        c.T_first_scan = pose_by_name.at(std::filesystem::path(c.name).filename().string());
      }
      clouds.push_back(std::move(c));
    }
    std::vector<perception::ScanCloud> references;
    for (const std::string& path : options.references) {
      perception::ScanCloud c;
      c.name = path;
      identification::PointCloudReadStats stats;
      c.cloud = identification::ReadPointCloud(path, options.max_points, &stats);
      non_finite += stats.non_finite;
      references.push_back(std::move(c));
    }
    const double read_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    perception::ScanMapOptions map_options;
    map_options.cell = options.cell;
    map_options.alpha_d = options.alpha_d;
    map_options.min_heap_height = options.min_heap_height;
    if (!options.up.empty()) {
      map_options.ground.up = Eigen::Vector3d(options.up[0], options.up[1], options.up[2]);
    }
    const perception::ScanMap map =
        perception::BuildScanMap(clouds, map_options, references.empty() ? nullptr : &references);
    if (!map.ok) {
      err << kCommand << ": " << options.clouds.front() << ": " << map.failure << "\n";
      return 2;
    }
    char line[320];
    out << "map of " << clouds.size() << " cloud" << (clouds.size() > 1 ? "s" : "") << ": "
        << map.points << " points";
    if (non_finite > 0) out << " (" << non_finite << " NaN or infinite dropped)";
    if (map.points_at_origin > 0) {
      out << " (" << map.points_at_origin << " at the scanner's origin: no return, dropped)";
    }
    std::snprintf(
        line, sizeof line, ", %ld fused; read %.2f s, floor %.2f s, map %.2f s, heaps %.2f s\n",
        map.points_used, read_seconds, map.seconds_floor, map.seconds_map, map.seconds_heaps);
    out << line;
    const perception::ScanPlane& floor = map.ground.floor;
    std::snprintf(line, sizeof line,
                  "  floor: normal (%.3f, %.3f, %.3f) in the first cloud's frame, %d points "
                  "within %.0f mm, noise sigma %.1f mm; %zu walls\n",
                  floor.normal.x(), floor.normal.y(), floor.normal.z(), floor.inliers,
                  1e3 * map.ground.threshold, 1e3 * floor.noise, map.ground.walls.size());
    out << line;
    std::snprintf(line, sizeof line,
                  "  points stand %.3f to %.3f m above the floor (1st to 99th percentile)%s\n",
                  map.height_low, map.height_high,
                  references.empty() ? "" : "; heights are measured above the reference scan");
    out << line;
    const perception::GridMap& grid = map.map.map();
    std::snprintf(line, sizeof line,
                  "  map: %d x %d cells of %.1f mm, %ld measured, %ld filled (Eq. 9); heaps "
                  "stand > %.1f mm above the floor\n",
                  grid.size().x(), grid.size().y(), 1e3 * grid.resolution(), map.cells_observed,
                  map.cells_filled, 1e3 * map.min_heap_height);
    out << line;
    out << "  | heap | volume m^3 | +/- m^3 (1 sigma) | on filled cells m^3 | area m^2 | peak m "
           "|\n  | --- | --- | --- | --- | --- | --- |\n";
    double total = 0, total_variance = 0;
    for (std::size_t k = 0; k < map.heaps.size(); ++k) {
      const perception::Heap& h = map.heaps[k];
      std::snprintf(line, sizeof line, "  | %zu | %.4g | %.2g | %.3g | %.3g | %.3f |\n", k + 1,
                    h.volume, h.volume_sigma, h.filled_volume, h.area, h.peak);
      out << line;
      total += h.volume;
      total_variance += h.volume_sigma * h.volume_sigma;
    }
    std::snprintf(line, sizeof line, "  total %.4g m^3 +/- %.2g\n", total,
                  std::sqrt(total_variance));
    out << line;
    core::CreateFolders(options.output);
    WriteHeapsCsv(options.output + "/heaps.csv", map);
    perception::WriteLayerPng(options.output + "/elevation.png", grid,
                              {"elevation", "height above the floor", "m"});
    perception::WriteLayerPng(options.output + "/uncertainty.png", grid,
                              {"variance", "height uncertainty (1 sigma)", "mm", 1e3, true});
    perception::LayerPicture heaps{"heap", "heaps", ""};
    heaps.categorical = true;
    perception::WriteLayerPng(options.output + "/heaps.png", grid, heaps);
    perception::WriteGeoTiff(options.output + "/map.tif", grid);
    sensors::PointCloud centres;  // the map's cells as points, for CloudCompare
    for (perception::GridMap::Iterator it(grid); !it.done(); ++it) {
      const float h = grid.at("elevation", *it);
      if (!std::isfinite(h)) continue;
      sensors::LidarPoint p;
      const Eigen::Vector2d xy = grid.PositionOf(*it);
      p.p_sensor = Eigen::Vector3f(static_cast<float>(xy.x()), static_cast<float>(xy.y()), h);
      p.intensity = grid.at("filled", *it) > 0 ? 0.f : 1.f;  // 1 measured, 0 filled
      centres.points.push_back(p);
    }
    identification::WritePly(options.output + "/map.ply", centres);
    out << "wrote " << options.output
        << "/heaps.csv, elevation.png, uncertainty.png, heaps.png, map.tif (GeoTIFF: height, "
           "sigma, filled), map.ply (cell centres; intensity 1 measured, 0 filled)\n";
    return 0;
  } catch (const core::InputError& e) {
    err << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << kCommand << ": " << e.what() << "\n";
    return 2;
  }
}

}  // namespace autoshovel::app
