// `autoshovel run truck_loading`: passes until the truck is full, one results row per pass, and
// the report with the bed's fill and the per-pass times and payloads.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "runtime/app/truck_loading/bed_picture.h"
#include "runtime/app/truck_loading/truck_loading_job.h"
#include "runtime/plot/bar_chart.h"
#include "runtime/plot/image_file.h"
#include "runtime/results/report.h"
#include "runtime/results/results_db.h"
#include "runtime/results/run_folder.h"

namespace autoshovel::app {
namespace {

/// One row of `cycles` per pass. The table was made for the loader's cycle; a pass maps onto it
/// as docs/truck_loading.md lists: crowd = dig, scoop = swing to the truck, level = dump,
/// retreat = return, approach unused; fill rate = dug volume / rated bucket capacity, payload =
/// volume added to the bed.
results::CycleRecord ToRecord(const PassOutcome& pass, const TruckLoadingJob& job,
                              double bucket_capacity) {
  results::CycleRecord r;
  r.cycle = pass.index;
  r.scenario = job.scenario_name();
  r.machine = job.machine_name();
  r.bin = "truck";
  r.material = job.material_name();
  r.strategy = "script";
  r.atomic_actions = "dig,swing,dump,return";
  r.fill_rate = pass.dug_volume / bucket_capacity;
  r.payload_m3 = pass.dumped_volume;
  r.time_s.crowd = pass.dig_time;
  r.time_s.scoop = pass.swing_time;
  r.time_s.level = pass.dump_time;
  r.time_s.retreat = pass.return_time;
  r.time_s.total = pass.total_time;
  r.energy_kj.crowd = pass.dig_energy / 1e3;
  r.energy_kj.scoop = pass.swing_energy / 1e3;
  r.energy_kj.level = pass.dump_energy / 1e3;
  r.energy_kj.retreat = pass.return_energy / 1e3;
  r.energy_kj.total =
      (pass.dig_energy + pass.swing_energy + pass.dump_energy + pass.return_energy) / 1e3;
  r.safety_margin_m = std::min(pass.min_truck_clearance, pass.min_person_clearance);
  r.safety_violations = pass.collisions;
  r.completed = pass.completed;
  return r;
}

}  // namespace

void TruckLoadingJob::WriteBedPng(const std::filesystem::path& path) const {
  WriteBedHeightPng(BedMap(), truck().wall_height, path);
}

int RunTruckLoadingCommand(const TruckLoadingOptions& options, const std::filesystem::path& out_dir,
                           std::ostream& out, std::ostream& err) {
  std::unique_ptr<TruckLoadingJob> job;
  try {
    job = std::make_unique<TruckLoadingJob>(options);
  } catch (const std::exception& e) {
    err << "autoshovel run truck_loading: " << e.what() << "\n";
    return 2;
  }
  const std::unique_ptr<results::RunFolder> folder = results::RunFolder::OpenWithConfig(
      out_dir, job->ConfigYaml(), err, "autoshovel run truck_loading");
  if (!folder) return 2;
  results::RunLog& log = folder->log();
  results::ResultsDb db(folder->DatabasePath());
  results::RunInfo info;
  info.run_id = folder->name();
  info.scenario = job->scenario_name();
  info.machine = job->machine_name();
  info.seed = options.seed;
  const int planned = options.passes > 0 ? options.passes : options.max_passes;
  info.cycles_planned = planned;
  db.BeginRun(info);
  out << "autoshovel run truck_loading: " << job->machine_name() << " loads a "
      << ToString(options.truck) << " (" << options.truck_payload / 1000 << " t) -> "
      << folder->dir().string() << "\n";
  log.Info("run " + info.run_id + ": truck loading, seed " + std::to_string(options.seed));
  if (job->recognition().done) {
    const TruckRecognitionCheck& r = job->recognition();
    char line[300];
    std::snprintf(line, sizeof line,
                  "truck recognised from the first-pass scan (%ld pulses): position error %.3f m, "
                  "yaw error %.2f deg, length %+.3f m, width %+.3f m\n",
                  r.pulses, r.position_error, r.yaw_error * 180 / 3.14159265358979, r.length_error,
                  r.width_error);
    out << line;
    log.Info(line);
  }

  std::vector<PassOutcome> passes;
  int failures = 0;
  const auto w0 = std::chrono::steady_clock::now();
  for (int i = 0; i < planned; ++i) {
    if (options.passes == 0 && job->TruckFull()) break;
    std::ostringstream progress;
    PassOutcome pass;
    try {
      pass = job->RunPass(i, &progress);
    } catch (const std::exception& e) {
      err << "autoshovel run truck_loading: pass " << i + 1 << ": " << e.what() << "\n";
      log.Error("pass " + std::to_string(i + 1) + ": " + e.what());
      return 2;
    }
    std::istringstream lines(progress.str());
    for (std::string line; std::getline(lines, line);) log.Info(line);
    db.WriteCycle(info.run_id, ToRecord(pass, *job, job->BucketCapacity()));
    passes.push_back(pass);
    if (!pass.completed) ++failures;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
    char line[400];
    std::snprintf(line, sizeof line,
                  "[pass %d] %-6s dig %.2f m3, dumped %.2f m3 (%.0f kg), pass %.1f s "
                  "(dig %.1f, swing %.1f, dump %.1f, return %.1f), truck clearance %.2f m, "
                  "bed %.1f t  %s (%.0f s elapsed)\n",
                  i + 1, pass.completed ? "ok" : "FAILED", pass.dug_volume, pass.dumped_volume,
                  pass.dumped_mass, pass.total_time, pass.dig_time, pass.swing_time, pass.dump_time,
                  pass.return_time, pass.min_truck_clearance, job->BedMass() / 1000,
                  pass.failure.c_str(), elapsed);
    out << line;
    if (pass.speed_scale < 1.0) {
      out << "         dust: this pass's load phase at " << std::lround(100 * pass.speed_scale)
          << " % of full speed\n";
    }
    out << std::flush;
    if (!pass.completed) {
      // The machine stays where the failed pass left it (a bucket perhaps still loaded): the
      // run ends here rather than dig on top of it.
      out << "run stopped after pass " << i + 1 << ": " << pass.failure << "\n";
      log.Error("run stopped after pass " + std::to_string(i + 1) + ": " + pass.failure);
      break;
    }
  }

  if (!options.record_dir.empty()) {
    try {
      job->CloseRecording();
      out << "recording: " << options.record_dir << " (autoshovel replay " << options.record_dir
          << ")\n";
    } catch (const std::exception& e) {
      err << "autoshovel run truck_loading: --record: " << e.what() << "\n";
      log.Error(std::string("--record: ") + e.what());
      return 2;
    }
  }

  std::vector<results::ReportFigure> figures;
  if (options.figures && !passes.empty()) {
    const std::filesystem::path bed_png = folder->FigurePath("bed_fill.png");
    job->WriteBedPng(bed_png);
    figures.push_back({"Truck bed after loading (height above the floor, 15 cm cells)",
                       "figures/bed_fill.png", ""});
    plot::BarChart times{.title = "Time per pass", .unit = "s", .groups = {}, .series = {}};
    plot::BarChart payload{.title = "Payload per pass", .unit = "t", .groups = {}, .series = {}};
    plot::BarSeries dig{.name = "dig", .values = {}}, swing{.name = "swing", .values = {}},
        dump{.name = "dump", .values = {}}, back{.name = "return", .values = {}},
        mass{.name = "dumped", .values = {}};
    for (const PassOutcome& p : passes) {
      times.groups.push_back("pass " + std::to_string(p.index + 1));
      payload.groups.push_back("pass " + std::to_string(p.index + 1));
      dig.values.push_back(p.dig_time);
      swing.values.push_back(p.swing_time);
      dump.values.push_back(p.dump_time);
      back.values.push_back(p.return_time);
      mass.values.push_back(p.dumped_mass / 1000);
    }
    const unsigned char colours[4][3] = {
        {60, 90, 200}, {60, 160, 60}, {40, 160, 220}, {160, 90, 60}};
    plot::BarSeries* series[4] = {&dig, &swing, &dump, &back};
    for (int k = 0; k < 4; ++k) std::copy(colours[k], colours[k] + 3, series[k]->bgr);
    times.series = {dig, swing, dump, back};
    payload.series = {mass};
    const std::filesystem::path bars = folder->FigurePath("passes.png");
    plot::WriteBarChartsPng({times, payload}, bars.string());
    figures.push_back({"Time and payload per pass", "figures/passes.png", ""});
  }
  results::WriteReportHtml(db, info.run_id, figures, folder->ReportPath());

  const planning::FillSummary fill = job->Fill();
  double total_time = 0;
  int collisions = 0;
  for (const PassOutcome& p : passes) total_time += p.total_time, collisions += p.collisions;
  char line[400];
  std::snprintf(line, sizeof line,
                "%zu pass(es), %d failed, %.1f t in the bed (%.0f %% of %.0f t), mean pass %.1f s, "
                "fill: mean %.2f m std %.2f m over %d cells, %d collision(s)\nreport: %s\n",
                passes.size(), failures, job->BedMass() / 1000,
                100 * job->BedMass() / options.truck_payload, options.truck_payload / 1000,
                passes.empty() ? 0.0 : total_time / passes.size(), fill.mean_height_m,
                fill.std_height_m, fill.known_cells, collisions,
                folder->ReportPath().string().c_str());
  out << line;
  log.Info(line);
  return failures == 0 ? 0 : 1;
}

}  // namespace autoshovel::app
