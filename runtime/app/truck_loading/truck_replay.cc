#include "runtime/app/truck_loading/truck_replay.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <memory>
#include <numbers>
#include <optional>

#include "runtime/app/truck_loading/bed_picture.h"
#include "runtime/app/truck_loading/scan_record.h"
#include "runtime/app/truck_scan/truck_scanner.h"
#include "runtime/core/file_output.h"
#include "runtime/core/strings.h"
#include "runtime/model/description.h"
#include "runtime/recording/replay_check.h"
#include "runtime/recording/scan_recording.h"
#include "runtime/results/run_folder.h"

namespace autoshovel::app {
namespace {

// The bed map's heights are on the rim's plane (−wall height on an empty floor, §4.3); the
// picture wants them above the floor.
planning::BedHeightMap AboveFloor(const planning::BedHeightMap& map, double wall_height) {
  planning::BedHeightMap shown(map.bed(), map.cell_size_m());
  for (int ix = 0; ix < map.cells_x(); ++ix) {
    for (int iy = 0; iy < map.cells_y(); ++iy) {
      if (map.known(ix, iy)) shown.SetHeight(ix, iy, map.height(ix, iy) + wall_height);
    }
  }
  return shown;
}

}  // namespace

int RunTruckReplay(const std::string& recording_dir, const std::string& out_dir, bool check,
                   std::ostream& out, std::ostream& err) {
  std::unique_ptr<recording::ScanRecording> rec;
  std::unique_ptr<TruckScanner> scanner;
  model::MachineDescription machine;
  try {
    rec = std::make_unique<recording::ScanRecording>(recording_dir);
    machine = model::LoadMachineDescription(rec->machine_path().string());
    // The scanner and the recogniser as the job sets them up: the library's detection and
    // recognition settings, the mount from the recorded description.
    TruckScannerConfig config;
    config.scanner = ScannerConfigFromDescription(machine, rec->manifest().scanner);
    scanner = std::make_unique<TruckScanner>(config);
  } catch (const std::exception& e) {
    err << "autoshovel replay: " << e.what() << "\n";
    return 2;
  }
  const std::string config_yaml =
      "command: replay\njob: truck_loading\nrecording: " + recording_dir +
      "\nscans: " + std::to_string(rec->scans().size()) + "\n";
  const std::unique_ptr<results::RunFolder> folder =
      results::RunFolder::OpenWithConfig(out_dir, config_yaml, err, "autoshovel replay");
  if (!folder) return 2;
  results::RunLog& log = folder->log();
  out << "autoshovel replay: truck loading, " << rec->scans().size() << " scans of " << machine.name
      << "'s " << rec->manifest().scanner << " -> " << folder->dir().string() << "\n";
  const auto w0 = std::chrono::steady_clock::now();
  std::string truck_csv = std::string(recording::kTruckReferenceHeader) + "\n";
  std::string beds_csv = std::string(recording::kBedMapReferenceHeader) + "\n";
  std::optional<planning::BedHeightMap> bed;
  perception::TruckRecognitionResult truck;
  try {
    const std::vector<recording::RecordedScan>& scans = rec->scans();
    // §4.1 on the recognition scan, from where the base stood.
    TruckScanReport report =
        scanner->Recognize(FromRecordedScan(scans.front()), rec->manifest().T_world_base);
    truck = report.recognition;
    truck_csv += TruckReferenceRow(truck, report.truck_below_machine) + "\n";
    if (truck.found) {
      const Eigen::Vector3d c = truck.T_world_bed.translation();
      const std::string line = "truck recognised: bed centre (" + core::Fixed(c.x(), 2) + ", " +
                               core::Fixed(c.y(), 2) + ", " + core::Fixed(c.z(), 2) + ") m, yaw " +
                               core::Fixed(truck.YawRad() * 180 / std::numbers::pi, 1) +
                               " deg, inside " + core::Fixed(truck.dimensions.length, 2) + " x " +
                               core::Fixed(truck.dimensions.width, 2) + " m";
      out << line << "\n";
      log.Info(line);
    } else {
      out << "no truck recognised: " << truck.reason << "\n";
      log.Warning("no truck recognised: " + truck.reason);
    }
    if (report.bed_map) {
      bed = *report.bed_map;
      beds_csv += BedMapReferenceRow(0, *bed) + "\n";
    }
    // §4.3 on every swing back: the cells each scan sees overwrite the map.
    for (std::size_t k = 1; k < scans.size() && bed; ++k) {
      const planning::BedHeightMap seen = scanner->BedMap(FromRecordedScan(scans[k]), truck);
      const int cells = FuseBedScan(*bed, seen);
      beds_csv += BedMapReferenceRow(static_cast<int>(k), *bed) + "\n";
      log.Info("scan " + std::to_string(k) + " (pass " + std::to_string(scans[k].pass) +
               "): " + std::to_string(cells) + " cells seen, " +
               std::to_string(bed->known_count()) + " known");
    }
    core::WriteFileAtomically(folder->dir() / "truck.csv", truck_csv);
    core::WriteFileAtomically(folder->dir() / "bed_maps.csv", beds_csv);
    if (bed && bed->known_count() > 0) {
      // The floor at the recognised wall height below the rim; where recognition did not see
      // the floor (NaN), at the deepest cell the scans saw.
      double wall = truck.dimensions.wall_height;
      if (!std::isfinite(wall)) {
        wall = 0;
        for (int ix = 0; ix < bed->cells_x(); ++ix) {
          for (int iy = 0; iy < bed->cells_y(); ++iy) {
            if (bed->known(ix, iy)) wall = std::max(wall, -bed->height(ix, iy));
          }
        }
      }
      if (wall > 0) {
        WriteBedHeightPng(AboveFloor(*bed, wall), wall, folder->FigurePath("bed_map.png"));
      }
    }
  } catch (const std::exception& e) {
    err << "autoshovel replay: " << e.what() << "\n";
    log.Error(e.what());
    return 2;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  out << "replayed " << rec->scans().size() << " scans in " << core::Fixed(seconds, 2) << " s\n";
  if (rec->truck_reference().empty()) {
    out << "the recording has no reference/: nothing to compare with\n";
    return 0;
  }
  const recording::Comparison truck_cmp =
      recording::CompareTables(rec->truck_reference(), truck_csv, "truck.csv");
  const recording::Comparison beds_cmp =
      recording::CompareTables(rec->bed_maps_reference(), beds_csv, "bed_maps.csv");
  const std::string summary = "against the recording: truck " + std::to_string(truck_cmp.same) +
                              "/" + std::to_string(truck_cmp.rows) + " identical, bed maps " +
                              std::to_string(beds_cmp.same) + "/" + std::to_string(beds_cmp.rows) +
                              " identical";
  out << summary << "\n";
  log.Info(summary);
  bool same = true;
  for (const recording::Comparison* c : {&truck_cmp, &beds_cmp}) {
    if (c->first_difference.empty()) continue;
    same = false;
    out << "  first difference: " << c->first_difference << "\n";
    log.Warning("first difference: " + c->first_difference);
  }
  return check && !same ? 1 : 0;
}

}  // namespace autoshovel::app
