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
  csv << "heap,volume_m3,volume_sigma_m3,floor_bias_m3,filled_volume_m3,area_m2,peak_m,cells,"
         "filled_cells,centroid_x_m,centroid_y_m,form,form_height_m\n";
  char line[320];
  for (std::size_t k = 0; k < map.heaps.size(); ++k) {
    const perception::Heap& h = map.heaps[k];
    std::snprintf(line, sizeof line, "%zu,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%d,%d,%.4f,%.4f,%s,%.4f\n",
                  k + 1, h.volume, h.volume_sigma, h.floor_bias, h.filled_volume, h.area, h.peak,
                  h.cells, h.filled_cells, h.centroid.x(), h.centroid.y(), h.form.name.c_str(),
                  h.form.height);
    csv << line;
  }
  core::WriteFileAtomically(path, csv.str());
}

// The option combinations a parser cannot check; "" when they are fine.
std::string CheckOptions(const MapCloudOptions& options) {
  if (options.clouds.empty()) return "give one or more point clouds (.pcd, .ply, .bin)";
  if (!options.poses.empty() && options.poses.size() != 6 * options.clouds.size()) {
    return "--pose needs 6 values (x y z roll pitch yaw) for every --cloud, got " +
           std::to_string(options.poses.size()) + " values for " +
           std::to_string(options.clouds.size()) + " clouds";
  }
  if (!options.poses.empty() && !options.poses_file.empty())
    return "give --pose or --poses, not both";
  if (!options.up.empty() && options.up.size() != 3) return "--up needs 3 values (x y z)";
  if (!options.floor.empty() && options.floor.size() != 4) {
    return "--floor needs 4 values (a b c d of the plane a x + b y + c z = d)";
  }
  if (options.floor.size() == 4 &&
      Eigen::Vector3d(options.floor[0], options.floor[1], options.floor[2]).norm() == 0) {
    return "--floor: the plane's normal (a, b, c) must not be zero";
  }
  if (!options.floor.empty() && !options.references.empty()) {
    return "give --floor or --reference, not both: the reference's floor is measured";
  }
  if (options.register_reference && options.references.empty()) {
    return "--register registers a --reference scan; none was given";
  }
  return "";
}

// Every cloud (and reference) read and checked before anything is computed or written.
struct Inputs {
  std::vector<perception::ScanCloud> clouds, references;
  std::size_t non_finite = 0;
  double read_seconds = 0;
};

Inputs ReadInputs(const MapCloudOptions& options,
                  const std::map<std::string, Eigen::Isometry3d>& pose_by_name) {
  const auto start = std::chrono::steady_clock::now();
  Inputs in;
  auto read = [&](const std::string& path) {
    perception::ScanCloud c;
    c.name = path;
    identification::PointCloudReadStats stats;
    c.cloud = identification::ReadPointCloud(path, options.max_points, &stats);
    in.non_finite += stats.non_finite;
    return c;
  };
  for (std::size_t k = 0; k < options.clouds.size(); ++k) {
    perception::ScanCloud c = read(options.clouds[k]);
    if (!options.poses.empty()) c.T_first_scan = PoseOf(&options.poses[6 * k]);
    if (!pose_by_name.empty()) {
      c.T_first_scan = pose_by_name.at(std::filesystem::path(c.name).filename().string());
    }
    in.clouds.push_back(std::move(c));
  }
  for (const std::string& path : options.references) in.references.push_back(read(path));
  in.read_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return in;
}

void PrintFloorAndMap(const perception::ScanMap& map, bool reference, std::ostream& out) {
  char line[400];
  if (map.ground.ok) {
    const perception::ScanPlane& floor = map.ground.floor;
    std::snprintf(line, sizeof line,
                  "  floor%s: normal (%.3f, %.3f, %.3f) in the first cloud's frame, %d points "
                  "within %.0f mm, noise sigma %.1f mm; %zu wall%s\n",
                  map.ground.floor_given ? " (given)" : "", floor.normal.x(), floor.normal.y(),
                  floor.normal.z(), floor.inliers, 1e3 * map.ground.threshold, 1e3 * floor.noise,
                  map.ground.walls.size(), map.ground.walls.size() == 1 ? "" : "s");
    out << line;
    for (std::size_t k = 0; k < map.ground.walls.size(); ++k) {
      const perception::ScanPlane& wall = map.ground.walls[k];
      // Where the wall stands in the map's frame: its foot's distance from the map's origin.
      const Eigen::Vector3d n_ground = map.ground.T_ground_scan.linear() * wall.normal;
      const double tilt = std::acos(std::min(1.0, std::abs(n_ground.z()))) * 180 / std::numbers::pi;
      std::snprintf(line, sizeof line,
                    "    wall %zu: %d points, %.0f deg to the floor, facing (%.2f, %.2f) in the "
                    "map, noise sigma %.1f mm\n",
                    k + 1, wall.inliers, tilt, n_ground.x(), n_ground.y(), 1e3 * wall.noise);
      out << line;
    }
  } else {
    const perception::ScanPlane& surface = *map.ground.surface;
    std::snprintf(line, sizeof line,
                  "  surface: normal (%.3f, %.3f, %.3f) in the first cloud's frame, %d points "
                  "within %.0f mm; %s\n",
                  surface.normal.x(), surface.normal.y(), surface.normal.z(), surface.inliers,
                  1e3 * map.ground.threshold,
                  reference ? "the reference shows no floor: the grid lies on its mean surface"
                            : "heights below are its relief about this mean plane");
    out << line;
  }
  if (map.registration) {
    const perception::ScanRegistration& r = *map.registration;
    std::snprintf(line, sizeof line,
                  "  reference registered (GICP): moved %.2f deg and %.1f mm; %.0f %% of its "
                  "points within %.0f mm of the scan, RMS %.1f mm\n",
                  r.rotation * 180 / std::numbers::pi, 1e3 * r.translation, 100 * r.overlap,
                  1e3 * r.final_distance, 1e3 * r.rms);
    out << line;
  }
  std::snprintf(line, sizeof line,
                "  points stand %.3f to %.3f m above the %s (1st to 99th percentile)%s\n",
                map.height_low, map.height_high, map.ground.ok ? "floor" : "mean surface",
                reference ? "; heights are measured above the reference scan" : "");
  out << line;
  const perception::GridMap& grid = map.map.map();
  std::snprintf(line, sizeof line,
                "  map: %d x %d cells of %.1f mm, %ld measured, %ld filled (Eq. 9)",
                grid.size().x(), grid.size().y(), 1e3 * grid.resolution(), map.cells_observed,
                map.cells_filled);
  out << line;
  if (map.floor_found) {
    std::snprintf(line, sizeof line, "; heaps stand > %.1f mm above the floor",
                  1e3 * map.min_heap_height);
    out << line;
  }
  out << "\n";
}

void PrintHeaps(const perception::ScanMap& map, bool reference, std::ostream& out) {
  char line[400];
  out << "  | heap | volume m^3 | +/- m^3 (1 sigma) | floor +/- m^3 | on filled cells m^3 | "
         "area m^2 | peak m | form |\n  | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  double total = 0, total_variance = 0, total_bias = 0;
  for (std::size_t k = 0; k < map.heaps.size(); ++k) {
    const perception::Heap& h = map.heaps[k];
    std::snprintf(line, sizeof line,
                  "  | %zu | %.4g | %.2g | %.2g | %.3g | %.3g | %.3f | %s (%+.3f m) |\n", k + 1,
                  h.volume, h.volume_sigma, h.floor_bias, h.filled_volume, h.area, h.peak,
                  h.form.name.c_str(), h.form.height);
    out << line;
    total += h.volume;
    total_variance += h.volume_sigma * h.volume_sigma;
    total_bias += h.floor_bias;
  }
  std::snprintf(line, sizeof line, "  total %.4g m^3 +/- %.2g (1 sigma)", total,
                std::sqrt(total_variance));
  out << line;
  if (reference) {
    out << "; heights above the reference scan: its measured floor replaces the plane\n";
  } else if (map.ground.floor_given) {
    std::snprintf(line, sizeof line,
                  "; the floor is the one given: its own error is not in these figures (the "
                  "scan's points near it scatter %.2g m^3 over the heaps)\n",
                  total_bias);
    out << line;
  } else {
    std::snprintf(line, sizeof line,
                  "; the floor's RMS scatter under the heaps could move it by %.2g\n", total_bias);
    out << line;
  }
}

// The CSV (with a floor), the pictures, the GeoTIFF and the cell centres.
void WriteOutputs(const perception::ScanMap& map, const std::string& folder, std::ostream& out) {
  const perception::GridMap& grid = map.map.map();
  core::CreateFolders(folder);
  if (map.floor_found) {
    WriteHeapsCsv(folder + "/heaps.csv", map);
  } else {
    // No volumes: a heaps.csv or heaps.png left by an earlier run must not be read as this one's.
    std::filesystem::remove(folder + "/heaps.csv");
    std::filesystem::remove(folder + "/heaps.png");
  }
  perception::WriteLayerPng(
      folder + "/elevation.png", grid,
      {"elevation", map.floor_found ? "height above the floor" : "relief about the mean surface",
       "m"});
  perception::WriteLayerPng(folder + "/uncertainty.png", grid,
                            {"variance", "height uncertainty (1 sigma)", "mm", 1e3, true});
  if (map.floor_found) {
    perception::LayerPicture heaps{"heap", "heaps", ""};
    heaps.categorical = true;
    perception::WriteLayerPng(folder + "/heaps.png", grid, heaps);
  }
  perception::WriteGeoTiff(folder + "/map.tif", grid);
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
  identification::WritePly(folder + "/map.ply", centres);
  out << "wrote " << folder << "/" << (map.floor_found ? "heaps.csv, " : "")
      << "elevation.png, uncertainty.png, " << (map.floor_found ? "heaps.png, " : "")
      << "map.tif (GeoTIFF: height, sigma, filled), map.ply (cell centres; intensity 1 "
         "measured, 0 filled)\n";
}

}  // namespace

int RunMapCloud(const MapCloudOptions& options, std::ostream& out, std::ostream& err) {
  const char* const kCommand = "autoshovel map --cloud";
  try {
    if (const std::string problem = CheckOptions(options); !problem.empty()) {
      err << kCommand << ": " << problem << "\n";
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
    const Inputs in = ReadInputs(options, pose_by_name);
    perception::ScanMapOptions map_options;
    map_options.cell = options.cell;
    map_options.alpha_d = options.alpha_d;
    map_options.min_heap_height = options.min_heap_height;
    map_options.register_reference = options.register_reference;
    if (!options.up.empty()) {
      map_options.ground.up = Eigen::Vector3d(options.up[0], options.up[1], options.up[2]);
    }
    if (!options.floor.empty()) {
      map_options.ground.floor =
          Eigen::Vector4d(options.floor[0], options.floor[1], options.floor[2], options.floor[3]);
    }
    const bool reference = !in.references.empty();
    const perception::ScanMap map =
        perception::BuildScanMap(in.clouds, map_options, reference ? &in.references : nullptr);
    if (!map.ok) {
      err << kCommand << ": " << options.clouds.front() << ": " << map.failure << "\n";
      return 2;
    }
    char line[320];
    out << "map of " << in.clouds.size() << " cloud" << (in.clouds.size() > 1 ? "s" : "") << ": "
        << map.points << " points";
    if (in.non_finite > 0) out << " (" << in.non_finite << " NaN or infinite dropped)";
    if (map.points_at_origin > 0) {
      out << " (" << map.points_at_origin << " at the scanner's origin: no return, dropped)";
    }
    if (map.points_isolated > 0) {
      out << " (" << map.points_isolated << " isolated: stray returns, dropped)";
    }
    std::snprintf(
        line, sizeof line, ", %ld fused; read %.2f s, floor %.2f s, map %.2f s, heaps %.2f s\n",
        map.points_used, in.read_seconds, map.seconds_floor, map.seconds_map, map.seconds_heaps);
    out << line;
    PrintFloorAndMap(map, reference, out);
    if (map.floor_found) {
      PrintHeaps(map, reference, out);
    } else {
      std::snprintf(line, sizeof line,
                    "  form of the surface: %s (centre %+.3f m against its mean; heights spread "
                    "%.3f m)\n",
                    map.surface_form.name.c_str(), map.surface_form.height,
                    map.surface_form.spread);
      out << line;
    }
    WriteOutputs(map, options.output, out);
    if (!map.floor_found) {
      // The map and pictures are written, but the volume asked for is not there: say so and
      // fail, so that a script does not read a missing volume as a measured one.
      err << kCommand << ": " << options.clouds.front() << ": no volume: " << map.failure << "\n";
      return 1;
    }
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
