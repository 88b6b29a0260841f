// The truck-loading recording's tables read from their text (scan_recording_format.h): each row
// checked, the first problem refusing the file at `file:line:column` (core::InputError). Only
// core and Eigen: the fuzz targets (tests/fuzz/scan_recording_fuzz.cc) compile this file alone.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "runtime/recording/scan_recording_format.h"

namespace autoshovel::recording {

/// scans.csv: the header, then scans numbered 0, 1, 2 … with passes that never go back; the
/// first scan, and only it, a recognition scan. The scanlines are left empty.
std::vector<RecordedScan> ParseScansCsv(const std::string& text, const std::string& source);

/// scanlines.csv into `scans` (from ParseScansCsv): rows grouped by scan in order, scanlines
/// numbered 0, 1, 2 … within each; every scan named must exist.
void ParseScanlinesCsv(const std::string& text, const std::string& source,
                       std::vector<RecordedScan>& scans);

/// scan_points.csv into the scanlines of `scans` (after ParseScanlinesCsv): rows grouped by scan
/// and scanline, in mirror order. A valid reading has finite coordinates; a miss (valid 0) has
/// finite ones or the word nan for all three.
void ParseScanPointsCsv(const std::string& text, const std::string& source,
                        std::vector<RecordedScan>& scans);

/// Whether recording.yaml at `path` names the truck-loading job (`job: truck_loading`). Throws
/// core::InputError for a file that is not YAML.
bool IsTruckLoadingManifest(const std::filesystem::path& path);

/// recording.yaml of a truck-loading recording. Throws core::InputError listing every problem.
ScanManifest ReadScanManifest(const std::filesystem::path& path);

}  // namespace autoshovel::recording
