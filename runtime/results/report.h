// report.html of a run folder: a self-contained HTML page (inline CSS, no scripts, no external
// resources) with the run summary, the per-cycle table read from the results database, and the
// figures the caller made (PNG files in the run folder, linked by relative paths).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "runtime/results/results_db.h"

namespace autoshovel::results {

/// A figure of the report. Other modules draw theirs (semantic map layers, scored candidates);
/// this module draws the volume, tip-path and fill-rate plots (plots.h).
struct ReportFigure {
  std::string title;
  std::filesystem::path png;  ///< absolute or relative to the report's folder
  std::string caption;        ///< optional
};

/// Aggregates over a run's cycles. Means skip NaN (NULL) values and are NaN when no cycle has one.
struct RunSummary {
  int cycles = 0;                         ///< rows written
  int cycles_completed = 0;               ///< rows with completed = 1
  double mean_fill_rate = kNotMeasured;   ///< [1]
  double mean_payload_m3 = kNotMeasured;  ///< [m³]
  double mean_trigger_time_s = kNotMeasured;
  PhaseValues mean_time_s;     ///< [s]
  PhaseValues mean_energy_kj;  ///< [kJ]
  double min_safety_margin_m = kNotMeasured;
  int safety_violations = 0;  ///< sum over cycles; must be 0
};

RunSummary Summarize(const std::vector<CycleRecord>& cycles);

/// The penetration predictor in the closed loop (issue 41, item 5): the travel it predicted at
/// the trigger against the travel measured after it, over the crowding samples that have both
/// (the §7.4.1 buckets of `autoshovel train predictor`).
struct TravelPredictionSummary {
  int cycles = 0;                    ///< samples with both values finite; 0: nothing to show
  int within_010 = 0;                ///< |predicted − actual| ≤ 0.10 m
  int within_015 = 0;                ///< ≤ 0.15 m
  int within_020 = 0;                ///< ≤ 0.20 m
  double rmse = kNotMeasured;        ///< [m]
  double mean_error = kNotMeasured;  ///< predicted − actual [m]
};

TravelPredictionSummary SummarizeTravelPrediction(const std::vector<CrowdingSample>& samples);

/// The crowding samples of run `run_id`, by cycle.
std::vector<CrowdingSample> RunCrowdingSamples(const ResultsDb& db, const std::string& run_id);

/// Writes `html_path` for run `run_id` of `db`. Figures whose PNG does not exist are listed as
/// missing (no broken image). When some of the run's cycles logged both the predicted and the
/// actual travel after the trigger, a section gives SummarizeTravelPrediction of them. Throws
/// std::runtime_error naming the file when it cannot be written, ResultsDbError when the run is not
/// in the database.
void WriteReportHtml(const ResultsDb& db, const std::string& run_id,
                     const std::vector<ReportFigure>& figures,
                     const std::filesystem::path& html_path);

/// Escapes &, <, >, " and ' for HTML text and attribute values.
std::string HtmlEscape(const std::string& text);

}  // namespace autoshovel::results
