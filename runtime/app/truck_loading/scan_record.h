// Between the truck-loading job's scans and their recording (runtime/recording/
// scan_recording.h): the conversions, the bed-map fusion the job and its replay share, and the
// reference rows a replay is checked against.
#pragma once

#include <string>

#include "runtime/app/truck_scan/truck_scanner.h"
#include "runtime/planning/dump/bed_height_map.h"
#include "runtime/recording/scan_recording_format.h"

namespace autoshovel::app {

/// A scan as the recording keeps it (its number is the writer's to set).
recording::RecordedScan ToRecordedScan(const TruckScan& scan, recording::ScanKind kind, int pass);
/// A recorded scan as the recogniser and the bed mapper take it.
TruckScan FromRecordedScan(const recording::RecordedScan& scan);

/// §4.3 on the swing back: the cells `seen` knows overwrite those of `bed` (a cell keeps its last
/// seen height). Returns the number of cells seen.
int FuseBedScan(planning::BedHeightMap& bed, const planning::BedHeightMap& seen);

/// reference/truck.csv's row (recording::kTruckReferenceHeader): what recognition found, every
/// number in its shortest exact text.
std::string TruckReferenceRow(const perception::TruckRecognitionResult& truck, bool below_machine);
/// A reference/bed_maps.csv row (recording::kBedMapReferenceHeader): the bed map after scan
/// `scan`, with an FNV-1a digest of every cell's knowledge and height bits.
std::string BedMapReferenceRow(int scan, const planning::BedHeightMap& bed);

}  // namespace autoshovel::app
