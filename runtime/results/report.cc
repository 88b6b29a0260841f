#include "runtime/results/report.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "runtime/core/file_output.h"

namespace autoshovel::results {
namespace fs = std::filesystem;

namespace {

struct Mean {
  double sum = 0.0;
  int count = 0;
  void Add(double v) {
    if (std::isnan(v)) return;
    sum += v;
    ++count;
  }
  double Value() const { return count == 0 ? kNotMeasured : sum / count; }
};

struct PhaseMeans {
  Mean approach, crowd, scoop, level, retreat, total;
  void Add(const PhaseValues& v) {
    approach.Add(v.approach), crowd.Add(v.crowd), scoop.Add(v.scoop);
    level.Add(v.level), retreat.Add(v.retreat), total.Add(v.total);
  }
  PhaseValues Value() const {
    return {approach.Value(), crowd.Value(),   scoop.Value(),
            level.Value(),    retreat.Value(), total.Value()};
  }
};

// "–" for NaN (NULL in the database).
std::string Number(double value, int decimals) {
  if (std::isnan(value)) return "&ndash;";
  char buffer[48];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, value);
  return buffer;
}

std::string Percent(double ratio) {
  return std::isnan(ratio) ? "&ndash;" : Number(100.0 * ratio, 1) + "&nbsp;%";
}

// The path as the report links it: relative to the report's folder when possible.
std::string LinkFor(const fs::path& png, const fs::path& report_dir) {
  if (png.is_relative()) return png.generic_string();
  std::error_code error;
  const fs::path relative = fs::relative(png, report_dir, error);
  return (error || relative.empty()) ? png.generic_string() : relative.generic_string();
}

constexpr const char* kStyle = R"css(
body { font-family: sans-serif; margin: 2em; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.2em; margin-top: 1.5em; }
table { border-collapse: collapse; font-size: 0.85em; }
th, td { border: 1px solid #ccc; padding: 3px 7px; text-align: right; }
th { background: #f0f0f0; } td.text { text-align: left; }
table.summary td:first-child { text-align: left; font-weight: bold; }
.bad { color: #b00; font-weight: bold; } .ok { color: #070; }
figure { display: inline-block; margin: 1em 1em 1em 0; vertical-align: top; }
figure img { max-width: 900px; border: 1px solid #ddd; }
figcaption { font-size: 0.9em; color: #444; max-width: 900px; }
.missing { color: #b00; }
)css";

}  // namespace

std::string HtmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

RunSummary Summarize(const std::vector<CycleRecord>& cycles) {
  RunSummary summary;
  Mean fill, payload, trigger;
  PhaseMeans time, energy;
  for (const CycleRecord& c : cycles) {
    ++summary.cycles;
    if (c.completed) ++summary.cycles_completed;
    fill.Add(c.fill_rate);
    payload.Add(c.payload_m3);
    trigger.Add(c.trigger_time_s);
    time.Add(c.time_s);
    energy.Add(c.energy_kj);
    if (!std::isnan(c.safety_margin_m) && (std::isnan(summary.min_safety_margin_m) ||
                                           c.safety_margin_m < summary.min_safety_margin_m)) {
      summary.min_safety_margin_m = c.safety_margin_m;
    }
    summary.safety_violations += c.safety_violations;
  }
  summary.mean_fill_rate = fill.Value();
  summary.mean_payload_m3 = payload.Value();
  summary.mean_trigger_time_s = trigger.Value();
  summary.mean_time_s = time.Value();
  summary.mean_energy_kj = energy.Value();
  return summary;
}

TravelPredictionSummary SummarizeTravelPrediction(const std::vector<CrowdingSample>& samples) {
  TravelPredictionSummary summary;
  double sum = 0.0, sum_sq = 0.0;
  for (const CrowdingSample& c : samples) {
    if (!std::isfinite(c.predicted_penetration) || !std::isfinite(c.penetration)) continue;
    const double error = c.predicted_penetration - c.penetration;
    ++summary.cycles;
    summary.within_010 += std::abs(error) <= 0.10;
    summary.within_015 += std::abs(error) <= 0.15;
    summary.within_020 += std::abs(error) <= 0.20;
    sum += error;
    sum_sq += error * error;
  }
  if (summary.cycles > 0) {
    summary.rmse = std::sqrt(sum_sq / summary.cycles);
    summary.mean_error = sum / summary.cycles;
  }
  return summary;
}

std::vector<CrowdingSample> RunCrowdingSamples(const ResultsDb& db, const std::string& run_id) {
  std::vector<CrowdingSample> samples;
  for (ResultsDb::StoredCrowdingSample& s : db.CrowdingSamples()) {  // ordered by run, cycle
    if (s.run_id == run_id) samples.push_back(std::move(s.sample));
  }
  return samples;
}

void WriteReportHtml(const ResultsDb& db, const std::string& run_id,
                     const std::vector<ReportFigure>& figures, const fs::path& html_path) {
  // No figure from a damaged file: integrity first, then every value through the typed reader.
  db.CheckIntegrity();
  const std::optional<RunInfo> run = db.FindRun(run_id);
  if (!run) {
    throw ResultsDbError(db.file().string() + ": no run '" + run_id + "' to report");
  }
  const std::vector<CycleRecord> cycles = db.Cycles(run_id, false);
  const RunSummary s = Summarize(cycles);
  const fs::path report_dir = html_path.has_parent_path() ? html_path.parent_path() : ".";

  std::ostringstream h;
  const std::string title = "autoshovel run " + run->run_id;
  h << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>"
    << HtmlEscape(title) << "</title>\n<style>" << kStyle << "</style>\n</head>\n<body>\n";
  h << "<h1>" << HtmlEscape(title) << "</h1>\n";

  // Summary.
  h << "<h2>Summary</h2>\n<table class=\"summary\">\n";
  auto row = [&h](const std::string& name, const std::string& value) {
    h << "<tr><td>" << name << "</td><td class=\"text\">" << value << "</td></tr>\n";
  };
  row("Scenario", HtmlEscape(run->scenario));
  row("Machine", HtmlEscape(run->machine));
  row("Seed", std::to_string(run->seed));
  row("Started (UTC)", HtmlEscape(run->start_time_utc));
  if (!run->git_describe.empty()) row("Build", HtmlEscape(run->git_describe));
  row("Cycles", std::to_string(s.cycles) +
                    (run->cycles_planned > 0 ? " of " + std::to_string(run->cycles_planned) : "") +
                    " written, " + std::to_string(s.cycles_completed) + " completed");
  row("Mean fill rate", Percent(s.mean_fill_rate));
  row("Mean payload [m&sup3;]", Number(s.mean_payload_m3, 2));
  row("Mean trigger time [s]", Number(s.mean_trigger_time_s, 2));
  row("Smallest safety margin [m]", Number(s.min_safety_margin_m, 2));
  row("Safety violations (must be 0)", std::string("<span class=\"") +
                                           (s.safety_violations == 0 ? "ok" : "bad") + "\">" +
                                           std::to_string(s.safety_violations) + "</span>");
  h << "</table>\n";

  h << "<h2>Mean time and energy per phase</h2>\n<table>\n<tr><th></th><th>approach</th>"
       "<th>crowd</th><th>scoop</th><th>level</th><th>retreat</th><th>total</th></tr>\n";
  auto phase_row = [&h](const char* name, const PhaseValues& v, int decimals) {
    h << "<tr><td class=\"text\">" << name << "</td><td>" << Number(v.approach, decimals)
      << "</td><td>" << Number(v.crowd, decimals) << "</td><td>" << Number(v.scoop, decimals)
      << "</td><td>" << Number(v.level, decimals) << "</td><td>" << Number(v.retreat, decimals)
      << "</td><td>" << Number(v.total, decimals) << "</td></tr>\n";
  };
  phase_row("time [s]", s.mean_time_s, 2);
  phase_row("energy [kJ]", s.mean_energy_kj, 1);
  h << "</table>\n";

  // Per-cycle table.
  h << "<h2>Cycles</h2>\n<table>\n<tr><th>cycle</th><th>bin</th><th>material</th>"
       "<th>strategy</th><th>atomic actions</th><th>trigger [s]</th><th>fill rate</th>"
       "<th>payload [m&sup3;]</th>";
  for (const char* phase : {"approach", "crowd", "scoop", "level", "retreat", "total"}) {
    h << "<th>t " << phase << " [s]</th>";
  }
  for (const char* phase : {"approach", "crowd", "scoop", "level", "retreat", "total"}) {
    h << "<th>E " << phase << " [kJ]</th>";
  }
  h << "<th>safety margin [m]</th><th>violations</th><th>completed</th></tr>\n";
  for (const CycleRecord& c : cycles) {
    h << "<tr><td>" << c.cycle << "</td><td class=\"text\">" << HtmlEscape(c.bin)
      << "</td><td class=\"text\">" << HtmlEscape(c.material) << "</td><td class=\"text\">"
      << HtmlEscape(c.strategy) << "</td><td class=\"text\">" << HtmlEscape(c.atomic_actions)
      << "</td><td>" << Number(c.trigger_time_s, 2) << "</td><td>" << Percent(c.fill_rate)
      << "</td><td>" << Number(c.payload_m3, 2) << "</td>";
    for (const double v : {c.time_s.approach, c.time_s.crowd, c.time_s.scoop, c.time_s.level,
                           c.time_s.retreat, c.time_s.total}) {
      h << "<td>" << Number(v, 2) << "</td>";
    }
    for (const double v : {c.energy_kj.approach, c.energy_kj.crowd, c.energy_kj.scoop,
                           c.energy_kj.level, c.energy_kj.retreat, c.energy_kj.total}) {
      h << "<td>" << Number(v, 1) << "</td>";
    }
    h << "<td>" << Number(c.safety_margin_m, 2) << "</td><td"
      << (c.safety_violations != 0 ? " class=\"bad\"" : "") << ">" << c.safety_violations
      << "</td><td>" << (c.completed ? "yes" : "<span class=\"bad\">no</span>") << "</td></tr>\n";
  }
  h << "</table>\n";

  // The penetration predictor in the closed loop: only when some cycle logged both travels.
  const TravelPredictionSummary travel = SummarizeTravelPrediction(RunCrowdingSamples(db, run_id));
  if (travel.cycles > 0) {
    auto share = [&travel](int count) {
      return std::to_string(count) + " of " + std::to_string(travel.cycles) + " (" +
             Percent(static_cast<double>(count) / travel.cycles) + ")";
    };
    h << "<h2>Predicted against actual travel after the trigger</h2>\n<table class=\"summary\">\n";
    row("Cycles with both", std::to_string(travel.cycles));
    row("|predicted &minus; actual| &le; 0.10 m", share(travel.within_010));
    row("&le; 0.15 m", share(travel.within_015));
    row("&le; 0.20 m", share(travel.within_020));
    row("RMSE [m]", Number(travel.rmse, 3));
    row("Mean error, predicted &minus; actual [m]", Number(travel.mean_error, 3));
    h << "</table>\n";
  }

  // Figures.
  if (!figures.empty()) h << "<h2>Figures</h2>\n";
  for (const ReportFigure& f : figures) {
    const fs::path on_disk = f.png.is_relative() ? report_dir / f.png : f.png;
    const std::string link = HtmlEscape(LinkFor(f.png, report_dir));
    if (!fs::is_regular_file(on_disk)) {
      h << "<p class=\"missing\">Figure missing: " << HtmlEscape(f.title) << " (" << link
        << " was not written)</p>\n";
      continue;
    }
    h << "<figure><a href=\"" << link << "\"><img src=\"" << link << "\" alt=\""
      << HtmlEscape(f.title) << "\"></a><figcaption><b>" << HtmlEscape(f.title) << "</b>";
    if (!f.caption.empty()) h << ". " << HtmlEscape(f.caption);
    h << "</figcaption></figure>\n";
  }
  h << "<p style=\"color:#888;font-size:0.8em\">Database: " << HtmlEscape(db.file().string())
    << ". Empty cells (&ndash;) are NULL: not measured.</p>\n</body>\n</html>\n";

  core::WriteFileAtomically(html_path, h.str());
}

}  // namespace autoshovel::results
