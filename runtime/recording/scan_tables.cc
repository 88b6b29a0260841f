#include "runtime/recording/scan_tables.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "runtime/core/diagnostics.h"
#include "runtime/core/yaml_reader.h"
#include "runtime/recording/csv_rows.h"
#include "runtime/recording/folder_checks.h"
#include "runtime/recording/recording_format.h"

namespace autoshovel::recording {
namespace {

// Scan-plane azimuths are unwrapped (truck_scanner.h), so a scan may turn several times; a
// hundred turns is beyond any machine.
constexpr double kAzimuthLimit = 200 * std::numbers::pi;
// A scan of a few minutes at 20 revolutions per second, each of a few thousand pulses.
constexpr long kMaxScans = 100000, kMaxScanlines = 10000000;
constexpr long long kMaxCount = 1000000000000LL;

double Coordinate(const std::string& source, int line, const Field& f, const char* name) {
  const double v = Finite(source, line, f, name);
  if (std::abs(v) > 1e6) {
    Refuse(source, line, f.column,
           std::string(name) + ": more than 1000 km from the world origin: " + f.text);
  }
  return v;
}

long long Count(const std::string& source, int line, const Field& f, const char* name) {
  return Integer(source, line, f, name, 0, static_cast<long>(kMaxCount));
}

}  // namespace

std::vector<RecordedScan> ParseScansCsv(const std::string& text, const std::string& source) {
  std::vector<RecordedScan> scans;
  for (const auto& [line, f] : CsvRows(text, source, kScansHeader)) {
    RecordedScan s;
    s.scan = static_cast<int>(Integer(source, line, f[0], "scan", 0, kMaxScans));
    if (s.scan != static_cast<int>(scans.size())) {
      Refuse(source, line, f[0].column,
             "scan: expected " + std::to_string(scans.size()) + " (scans are numbered in order)");
    }
    if (f[1].text == "recognition") {
      s.kind = ScanKind::kRecognition;
    } else if (f[1].text == "bed") {
      s.kind = ScanKind::kBed;
    } else {
      Refuse(source, line, f[1].column,
             "kind: expected recognition or bed, got '" + f[1].text.substr(0, 40) + "'");
    }
    if ((s.kind == ScanKind::kRecognition) != scans.empty()) {
      Refuse(source, line, f[1].column,
             "kind: the first scan, and only it, is the recognition scan");
    }
    s.pass = static_cast<int>(Integer(source, line, f[2], "pass", 0, 100000));
    if (!scans.empty() && s.pass < scans.back().pass) {
      Refuse(source, line, f[2].column,
             "pass: goes back from " + std::to_string(scans.back().pass));
    }
    s.pulses_fired = Count(source, line, f[3], "pulses_fired");
    s.points = Count(source, line, f[4], "points");
    s.dust_evidence = Count(source, line, f[5], "dust_evidence");
    s.max_azimuth_step = Finite(source, line, f[6], "max_azimuth_step");
    if (s.max_azimuth_step < 0 || s.max_azimuth_step > kAzimuthLimit) {
      Refuse(source, line, f[6].column, "max_azimuth_step: expected a non-negative angle [rad]");
    }
    s.dust_warning = Flag(source, line, f[7], "dust_warning");
    s.min_speed_scale = Finite(source, line, f[8], "min_speed_scale");
    if (!(s.min_speed_scale > 0 && s.min_speed_scale <= 1)) {
      Refuse(source, line, f[8].column, "min_speed_scale: expected a value in (0, 1]");
    }
    scans.push_back(std::move(s));
  }
  if (scans.empty()) Refuse(source, 1, 1, "no scan: the recognition scan must come first");
  return scans;
}

void ParseScanlinesCsv(const std::string& text, const std::string& source,
                       std::vector<RecordedScan>& scans) {
  int current = 0;
  long total = 0;
  for (const auto& [line, f] : CsvRows(text, source, kScanlinesHeader)) {
    const int scan = static_cast<int>(
        Integer(source, line, f[0], "scan", 0, static_cast<long>(scans.size()) - 1));
    if (scan < current) {
      Refuse(source, line, f[0].column,
             "scan: goes back from " + std::to_string(current) + " (rows are grouped by scan)");
    }
    current = scan;
    RecordedScan& s = scans[scan];
    const long index = Integer(source, line, f[1], "scanline", 0, kMaxScanlines);
    if (index != static_cast<long>(s.scanlines.size())) {
      Refuse(source, line, f[1].column,
             "scanline: expected " + std::to_string(s.scanlines.size()) + " in scan " +
                 std::to_string(scan));
    }
    if (++total > kMaxScanlines) Refuse(source, line, 1, "more than 10 million scanlines");
    perception::Scanline scanline;
    scanline.p_world_sensor = {Coordinate(source, line, f[2], "sensor_x"),
                               Coordinate(source, line, f[3], "sensor_y"),
                               Coordinate(source, line, f[4], "sensor_z")};
    const double azimuth = Finite(source, line, f[5], "azimuth");
    if (std::abs(azimuth) > kAzimuthLimit) {
      Refuse(source, line, f[5].column, "azimuth: more than a hundred turns [rad]");
    }
    s.scanlines.push_back(std::move(scanline));
    s.scanline_azimuths.push_back(azimuth);
  }
}

void ParseScanPointsCsv(const std::string& text, const std::string& source,
                        std::vector<RecordedScan>& scans) {
  int current_scan = 0;
  long current_line = 0;
  for (const auto& [line, f] : CsvRows(text, source, kScanPointsHeader)) {
    const int scan = static_cast<int>(
        Integer(source, line, f[0], "scan", 0, static_cast<long>(scans.size()) - 1));
    RecordedScan& s = scans[scan];
    if (s.scanlines.empty()) {
      Refuse(source, line, f[0].column,
             "scan " + std::to_string(scan) + " has no scanline in scanlines.csv");
    }
    const long scanline =
        Integer(source, line, f[1], "scanline", 0, static_cast<long>(s.scanlines.size()) - 1);
    if (scan < current_scan || (scan == current_scan && scanline < current_line)) {
      Refuse(source, line, f[0].column,
             "goes back from scan " + std::to_string(current_scan) + " scanline " +
                 std::to_string(current_line) + " (rows are grouped by scan and scanline)");
    }
    current_scan = scan, current_line = scanline;
    perception::ScanPoint p;
    p.valid = Flag(source, line, f[5], "valid");
    const bool all_nan = f[2].text == "nan" && f[3].text == "nan" && f[4].text == "nan";
    if (all_nan && !p.valid) {
      p.p_world = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
    } else {
      p.p_world = {Coordinate(source, line, f[2], "x"), Coordinate(source, line, f[3], "y"),
                   Coordinate(source, line, f[4], "z")};
    }
    s.scanlines[scanline].points.push_back(p);
  }
}

bool IsTruckLoadingManifest(const std::filesystem::path& path) {
  try {
    const YAML::Node root = YAML::LoadFile(path.string());
    return root.IsMap() && root["job"] && root["job"].IsScalar() &&
           root["job"].as<std::string>() == kTruckLoadingJob;
  } catch (const YAML::Exception&) {
    return false;  // not YAML: the loader's manifest reader says where
  }
}

ScanManifest ReadScanManifest(const std::filesystem::path& path) {
  core::DiagnosticSink sink;
  const core::YamlFile file(path, sink);
  ScanManifest m;
  if (file.ok()) {
    using core::NumberRule;
    core::MapReader root = core::MapReader::Root(file, nullptr);
    m.version = CheckFormatAndVersion(root, sink);
    root.Enum("job", {kTruckLoadingJob});
    m.machine_file = root.String("machine");
    m.scanner = root.String("scanner");
    const auto xyz = root.Numbers<3>("base_xyz", NumberRule::Closed(-1e6, 1e6, "m"));
    const double yaw = root.AngleDeg("base_yaw_deg", NumberRule::Closed(-360, 360, "deg"));
    m.T_world_base = Eigen::Translation3d(xyz[0], xyz[1], xyz[2]) *
                     Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
    m.scans = root.Integer("scans", 1, static_cast<int>(kMaxScans));
    root.Finish();
    if (sink.empty() &&
        (m.machine_file.empty() || m.machine_file.find("..") != std::string::npos ||
         m.machine_file.front() == '/' || m.machine_file.find('/') != std::string::npos)) {
      root.Error("machine", "must name a file in the recording folder");
    }
  }
  sink.ThrowIfAny();
  return m;
}

}  // namespace autoshovel::recording
