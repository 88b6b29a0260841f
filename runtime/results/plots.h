// The run report's figures, drawn with the project's line plots (runtime/plot/line_plot.h).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "runtime/plot/line_plot.h"
#include "runtime/results/results_db.h"

namespace autoshovel::results {

/// V1 and V1+V2 [m³] against time [s] for one cycle, a vertical line at the trigger (omitted when
/// NaN) and a horizontal line at the target volume (omitted when NaN).
void WriteVolumePlotPng(const CycleRecord& cycle, double target_volume_m3,
                        const std::filesystem::path& path);

/// Predicted and actual bucket-tip paths in the x–z plane of the vehicle frame [m], equal aspect.
void WriteTipPathPlotPng(const CycleRecord& cycle, const std::filesystem::path& path);

/// Fill rate [%] per cycle index, one line per strategy, markers at each cycle.
void WriteFillRatePlotPng(const std::vector<CycleRecord>& cycles,
                          const std::filesystem::path& path);

inline constexpr const char* kTravelPredictionTitle =
    "Predicted against actual travel after the trigger";

/// The penetration predictor in the closed loop (issue 41, item 5): a dot per crowding sample
/// with both values at (predicted, actual) travel after the trigger [m], the line y = x and
/// dashed bands at ±0.10 and ±0.20 m, equal aspect. Returns false and writes nothing when no
/// sample has both.
bool WriteTravelPredictionPlotPng(const std::vector<CrowdingSample>& samples,
                                  const std::filesystem::path& path);

}  // namespace autoshovel::results
