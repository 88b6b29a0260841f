// Fuzz targets: the truck-loading recording's tables and manifest (runtime/recording/
// scan_tables.h), one per file: SCAN_TABLE 0 scans.csv, 1 scanlines.csv (read against two
// scans), 2 scan_points.csv (against two scans of three scanlines), 3 recording.yaml. Each either
// reads the file, every number finite (a miss's NaN only on an invalid reading), or refuses it
// with a located core::InputError.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "runtime/core/diagnostics.h"
#include "runtime/recording/scan_tables.h"
#include "tests/fuzz/fuzz_input.h"
#include "tests/fuzz/refusal.h"
#include "tests/fuzz/scan_recording_fixture.h"

#ifndef SCAN_TABLE
#define SCAN_TABLE 0
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace autoshovel;
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::string path = fuzz::WriteInput(data, size, SCAN_TABLE == 3 ? ".yaml" : ".csv");
  try {
    if constexpr (SCAN_TABLE == 0) {
      const auto scans = recording::ParseScansCsv(text, path);
      if (scans.empty() || scans.front().kind != recording::ScanKind::kRecognition) std::abort();
      for (const recording::RecordedScan& s : scans) {
        if (!std::isfinite(s.max_azimuth_step) || !(s.min_speed_scale > 0)) std::abort();
      }
    } else if constexpr (SCAN_TABLE == 1) {
      auto scans = fuzz::ScansWithoutScanlines();
      recording::ParseScanlinesCsv(text, path, scans);
      for (const recording::RecordedScan& s : scans) {
        if (s.scanlines.size() != s.scanline_azimuths.size()) std::abort();
        for (std::size_t k = 0; k < s.scanlines.size(); ++k) {
          if (!s.scanlines[k].p_world_sensor.allFinite() ||
              !std::isfinite(s.scanline_azimuths[k])) {
            std::abort();
          }
        }
      }
    } else if constexpr (SCAN_TABLE == 2) {
      auto scans = fuzz::ScansWithScanlines();
      recording::ParseScanPointsCsv(text, path, scans);
      for (const recording::RecordedScan& s : scans) {
        for (const perception::Scanline& line : s.scanlines) {
          for (const perception::ScanPoint& p : line.points) {
            if (p.valid && !p.p_world.allFinite()) std::abort();
          }
        }
      }
    } else {
      const recording::ScanManifest m = recording::ReadScanManifest(path);
      if (m.scanner.empty() || m.machine_file.empty() || m.scans < 1 ||
          !m.T_world_base.matrix().allFinite()) {
        std::abort();
      }
    }
  } catch (const core::InputError& e) {
    fuzz::AbortUnlessLocated(e, path, text);
  }
  return 0;
}
