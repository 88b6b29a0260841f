// report.html and the PNG plots: the summary numbers, the per-cycle table, links to the figures
// that exist (and no broken image for one that does not), non-empty PNGs.
#include "runtime/results/report.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "runtime/results/plots.h"
#include "runtime/results/run_folder.h"
#include "tests/results/test_records.h"

namespace autoshovel::results {
namespace {

namespace fs = std::filesystem;
using testing::ScratchDir;
using testing::TestRecord;
using testing::TestRun;

std::string ReadAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void ExpectPng(const fs::path& path) {
  ASSERT_TRUE(fs::exists(path)) << path;
  EXPECT_GT(fs::file_size(path), 2000u) << path;
  EXPECT_EQ(ReadAll(path).substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << path;
}

TEST(Plots, WriteNonEmptyPngs) {
  const fs::path dir = ScratchDir("");
  CycleRecord cycle = TestRecord(2, 120);
  for (std::size_t k = 0; k < cycle.samples.size(); ++k) {  // a plausible scoop, in metres
    CycleSample& s = cycle.samples[k];
    const double a = 0.02 * static_cast<double>(k);
    s.actual_tip_x = 3.0 + 1.2 * std::sin(a);
    s.actual_tip_z = 0.1 + 0.8 * (1.0 - std::cos(a));
    s.predicted_tip_x = s.actual_tip_x + 0.05 * a;
    s.predicted_tip_z = s.actual_tip_z - 0.03 * a;
  }
  WriteVolumePlotPng(cycle, 3.2, dir / "volume.png");
  WriteTipPathPlotPng(cycle, dir / "tip.png");
  std::vector<CycleRecord> cycles;
  for (int c = 0; c < 6; ++c) cycles.push_back(TestRecord(c, 0));
  cycles[4].fill_rate = kNotMeasured;
  WriteFillRatePlotPng(cycles, dir / "fill.png");
  for (const char* name : {"volume.png", "tip.png", "fill.png"}) ExpectPng(dir / name);

  // Degenerate input still gives a picture: no samples, no trigger, no target.
  CycleRecord empty = TestRecord(0, 0);
  empty.trigger_time_s = kNotMeasured;
  WriteVolumePlotPng(empty, kNotMeasured, dir / "empty.png");
  ExpectPng(dir / "empty.png");

  plot::LinePlot bad;
  bad.series.push_back({"x and y differ", {1.0, 2.0}, {1.0}, plot::kBlue, 2, false, false});
  EXPECT_THROW(plot::WriteLinePlotPng(bad, dir / "bad.png"), std::invalid_argument);
  // A grid of three 300 × 250 plots, two per row: two rows, two columns.
  plot::LinePlot small;
  small.width_px = 300;
  small.height_px = 250;
  small.series.push_back({"y = x", {0.0, 1.0}, {0.0, 1.0}, plot::kBlue, 2, false, false});
  plot::WriteLinePlotGridPng({small, small, small}, 2, dir / "grid.png");
  // The PNG header (IHDR) holds the width and height, big-endian, at bytes 16 and 20.
  std::ifstream png(dir / "grid.png", std::ios::binary);
  unsigned char header[24] = {};
  png.read(reinterpret_cast<char*>(header), sizeof header);
  auto be32 = [&](int at) {
    return (header[at] << 24) | (header[at + 1] << 16) | (header[at + 2] << 8) | header[at + 3];
  };
  EXPECT_EQ(be32(16), 600);
  EXPECT_EQ(be32(20), 500);
  EXPECT_FALSE(std::filesystem::exists(dir / "grid.png.tmp.png"));
  EXPECT_THROW(plot::WriteLinePlotGridPng({}, 2, dir / "none.png"), std::invalid_argument);
  EXPECT_THROW(WriteVolumePlotPng(cycle, 3.0, dir / "no_such_folder" / "v.png"),
               std::runtime_error);
}

TEST(Report, SummarizeSkipsNotMeasuredValues) {
  std::vector<CycleRecord> cycles = {TestRecord(0, 0), TestRecord(1, 0), TestRecord(2, 0)};
  cycles[0].fill_rate = 0.9;
  cycles[1].fill_rate = kNotMeasured;
  cycles[2].fill_rate = 1.0;
  cycles[1].completed = false;
  cycles[2].safety_violations = 1;
  for (CycleRecord& c : cycles) c.energy_kj.level = kNotMeasured;
  const RunSummary s = Summarize(cycles);
  EXPECT_EQ(s.cycles, 3);
  EXPECT_EQ(s.cycles_completed, 2);
  EXPECT_DOUBLE_EQ(s.mean_fill_rate, 0.95);
  EXPECT_TRUE(std::isnan(s.mean_energy_kj.level));
  EXPECT_DOUBLE_EQ(s.mean_time_s.crowd, 2.25);
  EXPECT_DOUBLE_EQ(s.min_safety_margin_m, 1.23);
  EXPECT_EQ(s.safety_violations, 1);
  EXPECT_TRUE(std::isnan(Summarize({}).mean_fill_rate));
}

TEST(Report, HtmlHoldsSummaryTableAndLinksToExistingFigures) {
  RunFolderOptions options;
  options.dir = ScratchDir("") / "run";
  RunFolder folder(options);
  ResultsDb db(folder.DatabasePath());
  db.BeginRun(TestRun());
  std::vector<ReportFigure> figures;
  for (int c = 0; c < 3; ++c) {
    CycleRecord record = TestRecord(c, 80);
    record.fill_rate = 0.90 + 0.05 * c;        // mean 95.0 %
    record.time_s.crowd = 2.0 + c;             // mean 3.00 s
    record.energy_kj.scoop = 100.0 * (c + 1);  // mean 200.0 kJ
    if (c == 1) record.material = "sand <wet>";
    db.WriteCycle("run-1", record);
    const fs::path png = folder.FigurePath("volume_cycle_" + std::to_string(c) + ".png");
    WriteVolumePlotPng(record, 3.2, png);
    figures.push_back({"V1 and V1+V2, cycle " + std::to_string(c), png, "trigger in red"});
  }
  WriteFillRatePlotPng(db.Cycles("run-1"), folder.FigurePath("fill_rate.png"));
  figures.push_back({"Fill rate", "figures/fill_rate.png", ""});  // relative to the report
  figures.push_back({"Semantic map layers", folder.FigurePath("map_layers.png"), ""});  // absent

  WriteReportHtml(db, "run-1", figures, folder.ReportPath());
  const std::string html = ReadAll(folder.ReportPath());
  ASSERT_FALSE(html.empty());
  for (const char* expected :
       {"<!DOCTYPE html>", "yard_small", "loader_20t", "<td>Seed</td><td class=\"text\">42</td>",
        "3 of 10 written, 3 completed", "95.0&nbsp;%", "<td>3.00</td>", "<td>200.0</td>",
        "Safety violations (must be 0)", "<span class=\"ok\">0</span>", "v0.1.0-12-gabcdef",
        "sand &lt;wet&gt;", "lift,tilt,lift", "<img src=\"figures/volume_cycle_0.png\"",
        "<img src=\"figures/volume_cycle_2.png\"", "<img src=\"figures/fill_rate.png\"",
        "Figure missing: Semantic map layers"}) {
    EXPECT_NE(html.find(expected), std::string::npos) << "missing: " << expected;
  }
  EXPECT_EQ(html.find("<img src=\"figures/map_layers.png\""), std::string::npos);
  EXPECT_EQ(html.find(folder.dir().string() + "/figures"), std::string::npos)
      << "absolute figure links make the folder non-relocatable";
  EXPECT_EQ(html.find("sand <wet>"), std::string::npos);  // escaped
  // Every linked image exists relative to the report.
  for (std::size_t at = html.find("<img src=\""); at != std::string::npos;
       at = html.find("<img src=\"", at + 1)) {
    const std::size_t begin = at + 10;
    const std::string link = html.substr(begin, html.find('"', begin) - begin);
    EXPECT_TRUE(fs::is_regular_file(folder.dir() / link)) << link;
  }
  EXPECT_THROW(WriteReportHtml(db, "no-such-run", {}, folder.ReportPath()), ResultsDbError);
}

TEST(Report, SafetyViolationsAreFlagged) {
  const fs::path dir = ScratchDir("");
  ResultsDb db(dir / "results.sqlite");
  db.BeginRun(TestRun());
  CycleRecord record = TestRecord(0, 0);
  record.safety_violations = 2;
  db.WriteCycle("run-1", record);
  WriteReportHtml(db, "run-1", {}, dir / "report.html");
  EXPECT_NE(ReadAll(dir / "report.html").find("<span class=\"bad\">2</span>"), std::string::npos);
}

// The penetration predictor in the closed loop (issue 41, item 5): the travel predicted at the
// trigger against the travel measured after it. Cycles without both count for nothing; the
// figure and the report's section exist only when some cycle has both.
CycleRecord WithTravel(int c, double actual, double predicted) {
  CycleRecord r = TestRecord(c, 0);
  r.crowding.present = true;
  r.crowding.strategy = "just_in_out";
  r.crowding.trigger = "predicted_volume";
  r.crowding.material = "big_gravel";
  r.crowding.penetration = actual;
  r.crowding.predicted_penetration = predicted;
  return r;
}

TEST(Report, TravelPredictionSummaryCountsOnlyCyclesWithBoth) {
  // Errors (predicted − actual): +0.05, −0.12, +0.18, −0.35; then two without both.
  const std::vector<CrowdingSample> samples = {
      WithTravel(0, 1.00, 1.05).crowding,         WithTravel(1, 1.00, 0.88).crowding,
      WithTravel(2, 1.00, 1.18).crowding,         WithTravel(3, 1.00, 0.65).crowding,
      WithTravel(4, 1.00, kNotMeasured).crowding, WithTravel(5, kNotMeasured, 0.9).crowding};
  const TravelPredictionSummary s = SummarizeTravelPrediction(samples);
  EXPECT_EQ(s.cycles, 4);
  EXPECT_EQ(s.within_010, 1);
  EXPECT_EQ(s.within_015, 2);
  EXPECT_EQ(s.within_020, 3);
  EXPECT_NEAR(s.rmse, std::sqrt((0.05 * 0.05 + 0.12 * 0.12 + 0.18 * 0.18 + 0.35 * 0.35) / 4),
              1e-12);
  EXPECT_NEAR(s.mean_error, -0.06, 1e-12);
  const TravelPredictionSummary none = SummarizeTravelPrediction({samples[4], samples[5]});
  EXPECT_EQ(none.cycles, 0);
  EXPECT_TRUE(std::isnan(none.rmse));
  EXPECT_TRUE(std::isnan(none.mean_error));
}

TEST(Report, TravelPredictionFigureAndSectionOnlyWhenLogged) {
  const fs::path dir = ScratchDir("");
  const std::string section = "Predicted against actual travel after the trigger";
  {  // Crowding samples without a logged prediction (an older run), and a cycle without one.
    ResultsDb db(dir / "without.sqlite");
    db.BeginRun(TestRun());
    db.WriteCycle("run-1", WithTravel(0, 0.9, kNotMeasured));
    db.WriteCycle("run-1", TestRecord(1, 0));
    EXPECT_FALSE(
        WriteTravelPredictionPlotPng(RunCrowdingSamples(db, "run-1"), dir / "travel_without.png"));
    EXPECT_FALSE(fs::exists(dir / "travel_without.png"));
    WriteReportHtml(db, "run-1", {}, dir / "without.html");
    EXPECT_EQ(ReadAll(dir / "without.html").find(section), std::string::npos);
  }
  ResultsDb db(dir / "with.sqlite");
  db.BeginRun(TestRun());
  db.BeginRun(TestRun("run-2"));
  db.WriteCycle("run-1", WithTravel(0, 1.00, 1.05));
  db.WriteCycle("run-1", WithTravel(1, 1.00, 0.88));
  db.WriteCycle("run-1", TestRecord(2, 0));
  db.WriteCycle("run-1", WithTravel(3, 1.00, 1.18));
  db.WriteCycle("run-1", WithTravel(4, 1.00, 0.65));
  db.WriteCycle("run-1", WithTravel(5, 1.00, kNotMeasured));
  db.WriteCycle("run-2", WithTravel(0, 1.00, 3.00));  // another run's: not in run-1's report
  const std::vector<CrowdingSample> samples = RunCrowdingSamples(db, "run-1");
  ASSERT_EQ(samples.size(), 5u);
  EXPECT_EQ(samples[1].predicted_penetration, 0.88);
  ASSERT_TRUE(WriteTravelPredictionPlotPng(samples, dir / "travel.png"));
  ExpectPng(dir / "travel.png");
  WriteReportHtml(db, "run-1", {{kTravelPredictionTitle, dir / "travel.png", ""}},
                  dir / "with.html");
  const std::string html = ReadAll(dir / "with.html");
  EXPECT_NE(html.find("<h2>" + section + "</h2>"), std::string::npos);
  for (const char* expected :
       {"<td>Cycles with both</td><td class=\"text\">4</td>", "1 of 4 (25.0&nbsp;%)",
        "2 of 4 (50.0&nbsp;%)", "3 of 4 (75.0&nbsp;%)",
        "<td>RMSE [m]</td><td class=\"text\">0.207</td>", "<td class=\"text\">-0.060</td>",
        "<img src=\"travel.png\""}) {
    EXPECT_NE(html.find(expected), std::string::npos) << "missing: " << expected;
  }
}

}  // namespace
}  // namespace autoshovel::results
