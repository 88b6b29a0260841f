// Writes and reads the truck-loading job's recording (scan_recording_format.h,
// docs/recording_format.md "Truck loading"): the rangefinder's scans, and what the machine made
// of them for a replay to check against.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "runtime/recording/scan_recording_format.h"

namespace autoshovel::recording {

class ScanRecordingWriter {
 public:
  /// Creates `dir` (it must not exist, or be an empty folder) and copies the machine description
  /// at `description_path` byte for byte. Throws core::OutputError, or std::invalid_argument for
  /// a folder that holds files.
  ScanRecordingWriter(std::filesystem::path dir, const std::string& description_path,
                      ScanManifest manifest);

  /// Adds a scan (its `scan` number is set here: the next one). Returns that number.
  int AddScan(RecordedScan scan);
  /// reference/truck.csv's row (kTruckReferenceHeader), from the recognition scan.
  void SetTruckReference(const std::string& row);
  /// A reference/bed_maps.csv row (kBedMapReferenceHeader).
  void AddBedMapReference(const std::string& row);

  /// Writes the tables, the reference and, last, recording.yaml. Throws core::OutputError.
  void Close();

  const std::filesystem::path& dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
  ScanManifest manifest_;
  std::string scans_csv_, scanlines_csv_, points_csv_, truck_csv_, bed_maps_csv_;
  int next_scan_ = 0;
  bool closed_ = false;
};

/// A truck-loading recording, read and checked whole (manifest, every table row, a scanline per
/// scan at least). Throws core::InputError naming the file, line and column.
class ScanRecording {
 public:
  explicit ScanRecording(const std::filesystem::path& dir);

  const std::filesystem::path& dir() const { return dir_; }
  const ScanManifest& manifest() const { return manifest_; }
  std::filesystem::path machine_path() const { return dir_ / manifest_.machine_file; }
  const std::vector<RecordedScan>& scans() const { return scans_; }
  /// The machine's reference/ files as they are (empty when absent: a real machine's logger
  /// may not write them).
  const std::string& truck_reference() const { return truck_reference_; }
  const std::string& bed_maps_reference() const { return bed_maps_reference_; }

 private:
  std::filesystem::path dir_;
  ScanManifest manifest_;
  std::vector<RecordedScan> scans_;
  std::string truck_reference_, bed_maps_reference_;
};

}  // namespace autoshovel::recording
