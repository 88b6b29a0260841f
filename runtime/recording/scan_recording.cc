#include "runtime/recording/scan_recording.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <system_error>

#include "runtime/core/diagnostics.h"
#include "runtime/core/file_output.h"
#include "runtime/core/sha256.h"
#include "runtime/core/strings.h"
#include "runtime/recording/csv_rows.h"
#include "runtime/recording/folder_checks.h"
#include "runtime/recording/recording_format.h"
#include "runtime/recording/scan_tables.h"

namespace autoshovel::recording {
namespace {

// Shortest text that reads back to the same double: a replay sees the recorded numbers exactly.
std::string Num(double v) { return core::FormatNumber(v); }

std::string ManifestText(const ScanManifest& m) {
  const Eigen::Vector3d t = m.T_world_base.translation();
  const Eigen::Matrix3d R = m.T_world_base.linear();
  const double yaw_deg = std::atan2(R(1, 0), R(0, 0)) * 180.0 / 3.14159265358979323846;
  return "# autoshovel recording: the truck-loading job's scans (docs/recording_format.md)\n"
         "format: " +
         std::string(kFormatName) + "\nversion: " + std::to_string(kFormatVersion) +
         "\njob: " + kTruckLoadingJob + "\nmachine: " + m.machine_file + "\nscanner: " + m.scanner +
         "\nbase_xyz: [" + Num(t.x()) + ", " + Num(t.y()) + ", " + Num(t.z()) +
         "]\nbase_yaw_deg: " + Num(yaw_deg) + "\nscans: " + std::to_string(m.scans) + "\n";
}

}  // namespace

ScanRecordingWriter::ScanRecordingWriter(std::filesystem::path dir,
                                         const std::string& description_path, ScanManifest manifest)
    : dir_(std::move(dir)), manifest_(std::move(manifest)) {
  std::error_code ec;
  if (std::filesystem::exists(dir_, ec) && !std::filesystem::is_empty(dir_, ec)) {
    throw std::invalid_argument(dir_.string() +
                                ": the recording folder must be new or empty (it holds files)");
  }
  if (manifest_.scanner.empty() ||
      manifest_.scanner.find_first_of(":\n\"'#") != std::string::npos) {
    throw std::invalid_argument("ScanRecordingWriter: the scanner needs a plain name, got '" +
                                manifest_.scanner + "'");
  }
  core::CreateFolders(dir_);
  manifest_.machine_file = "machine.yaml";
  manifest_.scans = 0;
  core::WriteFileAtomically(dir_ / manifest_.machine_file, core::ReadFileBytes(description_path));
  scans_csv_ = std::string(kScansHeader) + "\n";
  scanlines_csv_ = std::string(kScanlinesHeader) + "\n";
  points_csv_ = std::string(kScanPointsHeader) + "\n";
  truck_csv_ = std::string(kTruckReferenceHeader) + "\n";
  bed_maps_csv_ = std::string(kBedMapReferenceHeader) + "\n";
}

int ScanRecordingWriter::AddScan(RecordedScan scan) {
  if (closed_) throw std::logic_error("ScanRecordingWriter: closed");
  if (scan.scanline_azimuths.size() != scan.scanlines.size()) {
    throw std::invalid_argument("ScanRecordingWriter::AddScan: one azimuth per scanline");
  }
  scan.scan = next_scan_++;
  const std::string id = std::to_string(scan.scan);
  scans_csv_ += id + "," + (scan.kind == ScanKind::kRecognition ? "recognition" : "bed") + "," +
                std::to_string(scan.pass) + "," + std::to_string(scan.pulses_fired) + "," +
                std::to_string(scan.points) + "," + std::to_string(scan.dust_evidence) + "," +
                Num(scan.max_azimuth_step) + "," + (scan.dust_warning ? "1" : "0") + "," +
                Num(scan.min_speed_scale) + "\n";
  for (std::size_t k = 0; k < scan.scanlines.size(); ++k) {
    const perception::Scanline& line = scan.scanlines[k];
    const std::string line_id = id + "," + std::to_string(k);
    scanlines_csv_ += line_id + "," + Num(line.p_world_sensor.x()) + "," +
                      Num(line.p_world_sensor.y()) + "," + Num(line.p_world_sensor.z()) + "," +
                      Num(scan.scanline_azimuths[k]) + "\n";
    for (const perception::ScanPoint& p : line.points) {
      if (p.p_world.allFinite()) {
        points_csv_ += line_id + "," + Num(p.p_world.x()) + "," + Num(p.p_world.y()) + "," +
                       Num(p.p_world.z()) + "," + (p.valid ? "1" : "0") + "\n";
      } else {
        // A miss keeps its place in the mirror order; a reading that is not finite is one.
        points_csv_ += line_id + ",nan,nan,nan,0\n";
      }
    }
  }
  ++manifest_.scans;
  return scan.scan;
}

void ScanRecordingWriter::SetTruckReference(const std::string& row) {
  truck_csv_ = std::string(kTruckReferenceHeader) + "\n" + row + "\n";
}

void ScanRecordingWriter::AddBedMapReference(const std::string& row) {
  bed_maps_csv_ += row + "\n";
}

void ScanRecordingWriter::Close() {
  if (closed_) return;
  if (manifest_.scans == 0) throw std::logic_error("ScanRecordingWriter: no scan was added");
  core::WriteFileAtomically(dir_ / "scans.csv", scans_csv_);
  core::WriteFileAtomically(dir_ / "scanlines.csv", scanlines_csv_);
  core::WriteFileAtomically(dir_ / "scan_points.csv", points_csv_);
  core::CreateFolders(dir_ / "reference");
  core::WriteFileAtomically(dir_ / "reference" / "truck.csv", truck_csv_);
  core::WriteFileAtomically(dir_ / "reference" / "bed_maps.csv", bed_maps_csv_);
  core::WriteFileAtomically(dir_ / "recording.yaml", ManifestText(manifest_));
  closed_ = true;
}

ScanRecording::ScanRecording(const std::filesystem::path& dir) : dir_(dir) {
  std::error_code ec;
  const std::filesystem::path manifest = ManifestOf(dir_);
  manifest_ = ReadScanManifest(manifest);
  const std::filesystem::path machine = machine_path();
  if (!std::filesystem::is_regular_file(machine, ec)) {
    Refuse(manifest.string(), 0, 0, "machine: " + machine.string() + " is missing");
  }
  const std::string scans_path = (dir_ / "scans.csv").string();
  scans_ = ParseScansCsv(ReadTableFile(scans_path), scans_path);
  if (static_cast<int>(scans_.size()) != manifest_.scans) {
    Refuse(scans_path, 0, 0,
           std::to_string(scans_.size()) + " scans, the manifest says " +
               std::to_string(manifest_.scans));
  }
  const std::string scanlines_path = (dir_ / "scanlines.csv").string();
  ParseScanlinesCsv(ReadTableFile(scanlines_path), scanlines_path, scans_);
  const std::string points_path = (dir_ / "scan_points.csv").string();
  ParseScanPointsCsv(ReadTableFile(points_path), points_path, scans_);
  for (const RecordedScan& s : scans_) {
    if (s.scanlines.empty()) {
      Refuse(scanlines_path, 0, 0, "scan " + std::to_string(s.scan) + " has no scanline");
    }
  }
  const std::filesystem::path truck = dir_ / "reference" / "truck.csv";
  if (std::filesystem::exists(truck, ec)) truck_reference_ = ReadTableFile(truck);
  const std::filesystem::path beds = dir_ / "reference" / "bed_maps.csv";
  if (std::filesystem::exists(beds, ec)) bed_maps_reference_ = ReadTableFile(beds);
}

}  // namespace autoshovel::recording
