// The recording's tables and manifest read from their text (recording_format.h): each row
// checked, the first problem refusing the file at `file:line:column` (core::InputError); the
// manifest strictly, every problem listed. Only core and Eigen: the fuzz targets
// (tests/fuzz/recording_fuzz.cc) compile this file alone.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "runtime/recording/recording_format.h"

namespace autoshovel::recording {

/// updates.csv: the header, then rows numbered 0, 1, 2 … with stamps that never go back.
std::vector<UpdateRow> ParseUpdatesCsv(const std::string& text, const std::string& source);

/// frames.csv: the header, then rows in update order, files relative to the folder, poses rigid.
std::vector<FrameRow> ParseFramesCsv(const std::string& text, const std::string& source);

/// scoop.csv: the header, then decisions in time order within each cycle.
std::vector<DecisionRow> ParseScoopCsv(const std::string& text, const std::string& source);

/// tip_path.csv: the header, then points grouped by cycle.
std::vector<TipPoint> ParseTipPathCsv(const std::string& text, const std::string& source);

/// recording.yaml. Throws core::InputError listing every problem.
Manifest ReadManifest(const std::filesystem::path& path);

}  // namespace autoshovel::recording
