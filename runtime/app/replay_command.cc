#include "runtime/app/replay_command.h"

#include <chrono>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <ostream>
#include <sstream>
#include <vector>

#include "runtime/app/shovel_job/scoop_handover.h"
#include "runtime/app/shovel_job/shovel_point_task.h"
#include "runtime/core/diagnostics.h"
#include "runtime/core/file_output.h"
#include "runtime/core/strings.h"
#include "runtime/machines/machine_code.h"
#include "runtime/model/description.h"
#include "runtime/perception/elevation_map.h"
#include "runtime/perception/lens_dirt_monitor.h"
#include "runtime/perception/machine_footprint.h"
#include "runtime/perception/map_render.h"
#include "runtime/perception/semantic_map.h"
#include "runtime/perception/sensor_fusion.h"
#include "runtime/planning/candidate_render.h"
#include "runtime/prediction/penetration_predictor.h"
#include "runtime/prediction/scoop_volume_prediction.h"
#include "runtime/prediction/shipped_models.h"
#include "runtime/recording/recording_reader.h"
#include "runtime/recording/replay_check.h"
#include "runtime/results/report.h"
#include "runtime/results/run_folder.h"
#include "runtime/sensors/lidar.h"
#include "runtime/sensors/sensor_pose.h"

namespace autoshovel::app {

namespace {

// The frames of update `i` as the machine delivered them: clouds and image from their files,
// poses from frames.csv, the machine's outline from updates.csv, and for a frame marked for the
// health check the LiDAR's scan pattern at the frame's stamp (from the description).
perception::SensorFrames LoadUpdate(const recording::Recording& rec, std::size_t i,
                                    const model::MachineDescription& machine) {
  const recording::UpdateRow& u = rec.updates()[i];
  perception::SensorFrames frames;
  frames.footprint =
      perception::LoaderFootprint(machine, u.hinge_xy, u.heading, u.articulation, u.tip_reach);
  for (const recording::FrameRow& f : rec.FramesOf(i)) {
    if (f.kind == recording::FrameRow::Kind::kCamera) {
      frames.camera = rec.ReadCamera(f);
      frames.T_world_camera = f.T_world_sensor;
      continue;
    }
    const model::Lidar* lidar = machine.FindLidar(f.sensor);
    if (lidar == nullptr) {
      core::RefuseInput({(rec.dir() / "frames.csv").string(), 0, 0},
                        "update " + std::to_string(i) + ": machine '" + machine.name +
                            "' has no LiDAR '" + f.sensor + "'");
    }
    perception::LidarFrame frame;
    frame.lidar = f.sensor;
    frame.T_world_lidar = f.T_world_sensor;
    frame.stamp = f.stamp;
    frame.cloud = rec.ReadLidar(f);
    if (f.health_check) {
      for (const sensors::LidarRay& ray : sensors::LidarScanPattern(*lidar, f.stamp)) {
        frame.health_check_rays.push_back(ray.direction);
      }
      frame.R_cab_lidar = sensors::PoseToIsometry(lidar->pose).linear();
    }
    frames.lidar.push_back(std::move(frame));
  }
  return frames;
}

std::string ReadTextOrEmpty(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// How many rows of `ours` equal the reference's, and the first that does not ("" when all do).
// V1 (Eq. 19) and V2 at each recorded decision of cycle `cycle`'s scoop, on `map` (the map the
// scoop started from), as `predictions.csv` rows; the first decision at which κ(V1 + V2) reached
// V_t goes to `log`.
std::string ReplayScoopPredictions(const recording::Recording& rec,
                                   const recording::CycleInfo& cycle,
                                   const model::MachineDescription& machine,
                                   const generated::MachineFunctions& functions,
                                   const prediction::PenetrationPredictor& predictor,
                                   const perception::GridMap& map, results::RunLog& log,
                                   std::vector<std::string>& report_lines) {
  std::string rows;
  if (!cycle.scoop) return rows;
  const model::Material* material = machine.FindMaterial(cycle.scoop->material);
  if (material == nullptr) {
    throw std::invalid_argument("recording.yaml: cycle " + std::to_string(cycle.index) +
                                ": machine '" + machine.name + "' has no material '" +
                                cycle.scoop->material + "'");
  }
  const prediction::HeightGrid grid = HeightGridOf(map);
  const std::vector<Eigen::Vector3d> tip_path = rec.TipPathOf(cycle.index);
  const double kappa = predictor.IntakeFactor(material->name);
  double reached = NAN;
  for (const recording::DecisionRow& d : rec.decisions()) {
    if (d.cycle != cycle.index) continue;
    const std::vector<Eigen::Vector3d> so_far(tip_path.begin(), tip_path.begin() + d.path_points);
    const double v1 =
        so_far.size() >= 2 ? prediction::Eq19Volume(grid, so_far, machine.bucket.width).volume : 0;
    double v2 = NAN;
    if (d.predict) {
      v2 = prediction::PredictV2(machine, functions, grid, *material, predictor, so_far,
                                 {.hinge_xy = d.hinge_xy,
                                  .heading = d.heading,
                                  .speed = d.speed,
                                  .q_boom = d.q_boom,
                                  .q_bucket = d.q_bucket},
                                 v1, cycle.scoop->bucket_max, cycle.scoop->boom_lift)
               .v2;
      if (std::isnan(reached) && kappa * (v1 + v2) >= cycle.scoop->target_volume) reached = d.time;
    }
    rows += recording::PredictionRow(cycle.index, d.time, v1, v2) + "\n";
  }
  const std::string line =
      "cycle " + std::to_string(cycle.index) + ": " +
      (std::isnan(reached)
           ? std::string("kappa (V1 + V2) never reached V_t")
           : "kappa (V1 + V2) reached V_t = " + core::Fixed(cycle.scoop->target_volume, 2) +
                 " m3 at t = " + core::Fixed(reached, 2) + " s");
  log.Info(line);
  report_lines.push_back(line);
  return rows;
}

// report.html: what was replayed, the comparison with the recording machine, each cycle's
// selection and predicted trigger, and the figures.
std::string ReplayReportHtml(const recording::Recording& rec, const std::vector<std::string>& lines,
                             const std::vector<std::pair<std::string, std::string>>& figures) {
  using results::HtmlEscape;
  std::string h =
      "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>autoshovel replay"
      "</title><style>body{font-family:sans-serif;max-width:1100px;margin:auto}"
      "img{max-width:100%}li{margin:0.2em 0}</style></head><body>\n";
  h += "<h1>Replay of " + HtmlEscape(rec.dir().string()) + "</h1>\n";
  h += "<p>" + HtmlEscape(rec.manifest().source) + ": " + std::to_string(rec.updates().size()) +
       " map updates, " + std::to_string(rec.frame_count()) + " sensor frames, " +
       std::to_string(rec.decisions().size()) + " scoop decisions (docs/recording_format.md)." +
       "</p>\n<ul>\n";
  for (const std::string& line : lines) h += "<li>" + HtmlEscape(line) + "</li>\n";
  h += "</ul>\n";
  for (const auto& [title, png] : figures) {
    h += "<h2>" + HtmlEscape(title) + "</h2>\n<img src=\"" + HtmlEscape(png) + "\" alt=\"" +
         HtmlEscape(title) + "\">\n";
  }
  return h + "</body></html>\n";
}

std::string ConfigYaml(const ReplayOptions& o, const recording::Recording& rec) {
  return "command: replay\nrecording: " + o.recording + "\nsource: \"" + rec.manifest().source +
         "\"\nsemantics: " +
         (o.truth_labels.value_or(false) ? "recorded labels" : "network " + o.segmenter) +
         "\nupdates: " + std::to_string(rec.updates().size()) + "\n";
}

// One replay: the recording and the machine, the map the frames build, a cycle's selection task,
// and what the run folder gets (the three tables, the report's lines and figures).
class Replayer {
 public:
  Replayer(const ReplayOptions& o, const recording::Recording& rec,
           const model::MachineDescription& machine, const generated::MachineFunctions& functions,
           const prediction::PenetrationPredictor* predictor, results::RunFolder& folder)
      : o_(o),
        rec_(rec),
        m_(rec.manifest()),
        machine_(machine),
        functions_(functions),
        predictor_(predictor),
        folder_(folder),
        loader_(planning::LoaderGeometryFrom(machine, functions)),
        map_(MapConfig(m_), m_.map_center),
        semantic_(map_),
        fusion_{.truth_labels = o.truth_labels.value_or(false),
                .segmenter = o.segmenter,
                .segmentation_scale = o.segmentation_scale.value_or(1.0),
                .lens_dirt = &lens_dirt_} {
    for (const recording::CycleInfo& c : m_.cycles) cycles_[c.index] = &c;
  }

  // Update `i`: its frames fused, the selection where the machine ran one, the map's digest.
  void Update(std::size_t i) {
    const recording::UpdateRow& u = rec_.updates()[i];
    if (u.cycle != cycle_) BeginCycle(u.cycle);
    const perception::FusionStats fused = perception::FuseSensorFrames(
        machine_, LoadUpdate(rec_, i, machine_), fusion_, map_, semantic_);
    if (u.select) {
      last_pose_ = {u.select_xy, u.select_heading};
      const planning::ShovelCandidate* best =
          task_->Select(map_.map(), semantic_.ground_plane(), last_pose_);
      selections_ +=
          recording::SelectionRow(static_cast<long>(i), cycle_, task_->last_selection(), best) +
          "\n";
      if (best != nullptr && !goal_) {
        goal_ = Goal{task_->last_selection(), task_->last_baseline(), last_pose_};
        folder_.log().Info(task_->SelectedText(*best));
        report_lines_.push_back("cycle " + std::to_string(cycle_) + ": " +
                                task_->SelectedText(*best));
      }
    }
    digests_ += recording::MapDigestRow(static_cast<long>(i), map_.map()) + "\n";
    folder_.log().Debug("update " + std::to_string(i) + ": " + std::to_string(fused.returns_fused) +
                        " returns fused, " + fused.semantics);
  }

  // The running cycle's end: its scoop's predictions on the map it started from, its pictures.
  void FinishCycle() {
    if (task_ == nullptr) return;
    if (predictor_ != nullptr) {
      predictions_ += ReplayScoopPredictions(rec_, *cycles_.at(cycle_), machine_, functions_,
                                             *predictor_, map_.map(), folder_.log(), report_lines_);
    }
    if (!o_.figures) return;
    const std::string n = std::to_string(cycle_);
    perception::WriteSemanticMapPng(map_.map(), task_->last_piles(),
                                    folder_.FigurePath("map_cycle_" + n + ".png").string(), 2);
    report_figures_.emplace_back("Cycle " + n + ": semantic elevation map layers",
                                 "figures/map_cycle_" + n + ".png");
    if (goal_) {
      planning::WriteCandidatePng(map_.map(), goal_->selection,
                                  m_.chen2024 ? &goal_->baseline : nullptr, goal_->from, loader_,
                                  folder_.FigurePath("candidates_cycle_" + n + ".png").string());
      report_figures_.emplace_back("Cycle " + n + ": scored shovel points when its goal was chosen",
                                   "figures/candidates_cycle_" + n + ".png");
    }
  }

  void WriteTables() const {
    core::WriteFileAtomically(folder_.dir() / "map_digests.csv", digests_);
    core::WriteFileAtomically(folder_.dir() / "selections.csv", selections_);
    core::WriteFileAtomically(folder_.dir() / "predictions.csv", predictions_);
  }

  // Compares the tables with the recording's reference/, says so on `out`, the log and the
  // report, and writes report.html. Returns 0 (identical, or nothing to compare), 1 (a
  // difference, with --check), 2 (the report could not be written).
  int CompareAndReport(std::ostream& out, std::ostream& err) {
    const std::filesystem::path ref = rec_.dir() / "reference";
    const std::string ref_digests = ReadTextOrEmpty(ref / "map_digests.csv");
    bool identical = true;
    if (ref_digests.empty()) {
      out << "no reference/ in the recording: nothing to compare with\n";
      report_lines_.push_back("the recording has no reference/: nothing to compare with");
    } else {
      const recording::Comparison maps =
          recording::CompareTables(ref_digests, digests_, "map_digests.csv");
      const recording::Comparison picks = recording::CompareTables(
          ReadTextOrEmpty(ref / "selections.csv"), selections_, "selections.csv");
      const recording::Comparison volumes = recording::CompareTables(
          ReadTextOrEmpty(ref / "predictions.csv"), predictions_, "predictions.csv");
      std::ostringstream summary;
      summary << "against the recording machine: maps identical after " << maps.same << " of "
              << maps.rows << " updates, selections identical at " << picks.same << " of "
              << picks.rows << ", V1 and V2 identical at " << volumes.same << " of " << volumes.rows
              << " scoop decisions";
      out << summary.str() << "\n";
      folder_.log().Info(summary.str());
      report_lines_.push_back(summary.str());
      for (const recording::Comparison* c : {&maps, &picks, &volumes}) {
        if (c->first_difference.empty()) continue;
        out << "  first difference: " << c->first_difference << "\n";
        folder_.log().Warning(c->first_difference);
        report_lines_.push_back("first difference: " + c->first_difference);
      }
      identical =
          maps.same == maps.rows && picks.same == picks.rows && volumes.same == volumes.rows;
    }
    try {
      core::WriteFileAtomically(folder_.dir() / "report.html",
                                ReplayReportHtml(rec_, report_lines_, report_figures_));
    } catch (const std::exception& e) {
      err << "autoshovel replay: " << e.what() << "\n";
      return 2;
    }
    out << "report: " << (folder_.dir() / "report.html").string() << "\n";
    return o_.check && !identical ? 1 : 0;
  }

 private:
  // The selection that first gave the cycle a goal, for its picture.
  struct Goal {
    planning::ShovelPointResult selection;
    std::vector<planning::Chen2024Candidate> baseline;
    planning::Pose2 from;
  };

  static perception::ElevationMapConfig MapConfig(const recording::Manifest& m) {
    perception::ElevationMapConfig config;
    config.resolution = m.map_resolution;
    config.length = m.map_length;
    return config;
  }

  void BeginCycle(int cycle) {
    FinishCycle();
    goal_.reset();
    cycle_ = cycle;
    const recording::WorkArea area = cycles_.at(cycle)->area;
    task_ = std::make_unique<ShovelPointTask>(
        m_.selection, m_.min_planned_clearance, m_.chen2024, loader_,
        [area](const Eigen::Vector2d& p) { return area.Contains(p); });
    folder_.log().Info("cycle " + std::to_string(cycle) + " at " + cycles_.at(cycle)->site);
  }

  const ReplayOptions& o_;
  const recording::Recording& rec_;
  const recording::Manifest& m_;
  const model::MachineDescription& machine_;
  const generated::MachineFunctions& functions_;
  const prediction::PenetrationPredictor* predictor_;
  results::RunFolder& folder_;
  const planning::LoaderGeometry loader_;
  perception::ElevationMap map_;
  perception::SemanticMap semantic_;
  perception::LensDirtMonitor lens_dirt_;
  const perception::FusionOptions fusion_;
  std::map<int, const recording::CycleInfo*> cycles_;
  std::string digests_ = std::string(recording::kMapDigestsHeader) + "\n";
  std::string selections_ = std::string(recording::kSelectionsHeader) + "\n";
  std::string predictions_ = std::string(recording::kPredictionsHeader) + "\n";
  std::unique_ptr<ShovelPointTask> task_;
  int cycle_ = -1;
  planning::Pose2 last_pose_;
  std::optional<Goal> goal_;
  std::vector<std::string> report_lines_;
  std::vector<std::pair<std::string, std::string>> report_figures_;
};

}  // namespace

int RunReplay(const ReplayOptions& options, std::ostream& out, std::ostream& err) {
  ReplayOptions o = options;
  if (o.segmenter.empty()) o.segmenter = o.models_dir + "/segmentation/yard_segmenter.onnx";
  std::unique_ptr<recording::Recording> rec;
  model::MachineDescription machine;
  const generated::MachineFunctions* functions = nullptr;
  std::unique_ptr<prediction::PenetrationPredictor> predictor;
  try {
    rec = std::make_unique<recording::Recording>(o.recording);
    model::LoadOptions load;
    load.models_dir = o.models_dir;
    load.overlays = rec->overlay_paths();
    machine = model::LoadMachineDescription(rec->machine_path().string(), load);
    functions = &machines::MachineFunctionsFor(machine);
    if (!rec->decisions().empty()) {
      predictor =
          std::make_unique<prediction::PenetrationPredictor>(prediction::PenetrationPredictor::Load(
              o.predictor.empty() ? prediction::MainJobPredictor(o.models_dir) : o.predictor));
    }
  } catch (const std::exception& e) {
    err << "autoshovel replay: " << e.what() << "\n";
    return 2;
  }
  // The semantics the recording machine used, unless told otherwise.
  if (!o.truth_labels) o.truth_labels = rec->manifest().truth_labels.value_or(false);
  if (!o.segmentation_scale) o.segmentation_scale = rec->manifest().segmentation_scale;
  const std::unique_ptr<results::RunFolder> folder =
      results::RunFolder::OpenWithConfig(o.out, ConfigYaml(o, *rec), err, "autoshovel replay");
  if (!folder) return 2;
  out << "autoshovel replay: " << rec->updates().size() << " updates, " << rec->frame_count()
      << " frames of " << machine.name << " (" << rec->manifest().source << ") -> "
      << folder->dir().string() << "\n";
  const auto w0 = std::chrono::steady_clock::now();
  std::unique_ptr<Replayer> replay;
  try {
    replay = std::make_unique<Replayer>(o, *rec, machine, *functions, predictor.get(), *folder);
    for (std::size_t i = 0; i < rec->updates().size(); ++i) replay->Update(i);
    replay->FinishCycle();
    replay->WriteTables();
  } catch (const std::exception& e) {
    err << "autoshovel replay: " << e.what() << "\n";
    folder->log().Error(e.what());
    return 2;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  out << "replayed " << rec->updates().size() << " updates in " << core::Fixed(seconds, 1) << " s ("
      << core::Fixed(1e3 * seconds / static_cast<double>(rec->updates().size()), 1)
      << " ms per update)\n";
  return replay->CompareAndReport(out, err);
}

}  // namespace autoshovel::app
