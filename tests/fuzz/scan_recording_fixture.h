// What the truck-loading recording's later tables are read against (scan_tables.h): the scans of
// scans.csv for scanlines.csv, and their scanlines for scan_points.csv. Shared by the fuzz
// targets (scan_recording_fuzz.cc) and their regression test.
#pragma once

#include <vector>

#include "runtime/recording/scan_tables.h"

namespace autoshovel::fuzz {

/// Two scans (recognition, bed) without scanlines.
inline std::vector<recording::RecordedScan> ScansWithoutScanlines() {
  return recording::ParseScansCsv(std::string(recording::kScansHeader) +
                                      "\n0,recognition,0,100,60,0,0.01,0,1\n"
                                      "1,bed,0,40,20,3,0.02,1,0.5\n",
                                  "fixture/scans.csv");
}

/// The same with three scanlines each.
inline std::vector<recording::RecordedScan> ScansWithScanlines() {
  std::vector<recording::RecordedScan> scans = ScansWithoutScanlines();
  std::string lines = std::string(recording::kScanlinesHeader) + "\n";
  for (int scan = 0; scan < 2; ++scan) {
    for (int k = 0; k < 3; ++k) {
      lines += std::to_string(scan) + "," + std::to_string(k) + ",0.4,0.8,2.6," +
               std::to_string(0.01 * k) + "\n";
    }
  }
  recording::ParseScanlinesCsv(lines, "fixture/scanlines.csv", scans);
  return scans;
}

}  // namespace autoshovel::fuzz
