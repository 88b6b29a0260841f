#include "runtime/app/shovel_job/cycle_booking.h"

#include <cmath>

#include "runtime/perception/map_render.h"
#include "runtime/planning/candidate_render.h"
#include "runtime/results/plots.h"

namespace autoshovel::app {

namespace {

void BookSamples(const control::ScoopResult& r, double t0, const Eigen::Vector2d& frame_origin,
                 double frame_heading, results::CycleRecord& rec) {
  // Samples: V1, V1+V2, trigger; the tip in the frame of the machine at contact (x ahead, z up).
  const Eigen::Vector2d ahead(std::cos(frame_heading), std::sin(frame_heading));
  for (const control::ScoopSample& s : r.samples) {
    results::CycleSample cs;
    cs.t = s.time - t0;
    cs.v1 = s.v1;
    cs.v1v2 = s.v1_plus_v2;
    cs.triggered = s.triggered;
    cs.actual_tip_x = (s.tip.head<2>() - frame_origin).dot(ahead);
    cs.actual_tip_z = s.tip.z();
    rec.samples.push_back(cs);
  }
  for (std::size_t k = 0; k < r.predicted_tip_path.size(); ++k) {
    results::CycleSample cs;
    cs.t = r.trigger_time - t0 + 0.02 * static_cast<double>(k);
    cs.triggered = true;
    cs.predicted_tip_x = (r.predicted_tip_path[k].head<2>() - frame_origin).dot(ahead);
    cs.predicted_tip_z = r.predicted_tip_path[k].z();
    rec.samples.push_back(cs);
  }
}

void BookCrowdingSample(const control::ScoopResult& r, results::CycleRecord& rec) {
  results::CrowdingSample& c = rec.crowding;
  c.present = true;
  c.strategy = rec.strategy;
  c.trigger = r.trigger_reason;
  c.material = r.features_at_trigger.material;
  c.speed = r.features_at_trigger.speed;
  c.v1 = r.features_at_trigger.shoveled_volume;
  for (int k = 0; k < 6; ++k) c.heights[k] = r.features_at_trigger.heights[k];
  c.penetration = r.travel_after_trigger;
  c.predicted_penetration = r.predicted_travel_at_trigger;
}

}  // namespace

void BookCycle(const CycleEnd& end, const FaultSchedule& faults,
               const model::MachineDescription& machine, const NavigationGoal& nav,
               CycleOutcome& out) {
  results::CycleRecord& rec = out.record;
  const control::ScoopResult& r = out.scoop;
  if (out.failure.empty() && end.scooped && !r.ok) out.failure = r.failure;
  rec.completed = out.failure.empty() && r.ok;
  rec.failure = rec.completed ? "" : out.failure;
  rec.safe_stops = out.safe_stops;
  rec.recoveries = out.recoveries;
  rec.refused_frames = static_cast<int>(out.refused_frames);
  for (const plant::FaultSpec& f : faults.faults()) {
    const std::string kind = plant::ToString(f.kind);
    if (f.InCycle(faults.cycle()) && rec.faults.find(kind) == std::string::npos) {
      rec.faults += (rec.faults.empty() ? "" : ",") + kind;
    }
  }
  rec.strategy = end.scooped ? control::ToString(r.strategy) : "";
  std::string actions;
  for (const std::string& a : r.action_names) actions += (actions.empty() ? "" : ",") + a;
  rec.atomic_actions = actions;
  if (end.scooped && r.has_features_at_trigger && rec.completed &&
      std::isfinite(r.travel_after_trigger)) {
    BookCrowdingSample(r, rec);
  }
  rec.trigger_time_s = std::isnan(r.trigger_time) ? NAN : r.trigger_time - end.t0;
  rec.payload_m3 = end.payload;
  rec.fill_rate = rec.payload_m3 / machine.bucket.rated_capacity;
  auto phase = [&](const char* name, bool energy) {
    const control::PhaseRecord* p = r.Phase(name);
    if (p == nullptr) return 0.0;
    return energy ? p->energy / 1e3 : p->duration;
  };
  // Navigation: from the cycle start to the scoop cycle's start (booked to "approach").
  const double to_scoop_time = end.scooped ? r.start_time - end.t0 : end.navigation_time;
  for (const bool energy : {false, true}) {
    results::PhaseValues& v = energy ? rec.energy_kj : rec.time_s;
    v.approach = phase("approach", energy) + (energy ? 0.0 : to_scoop_time);
    v.crowd = phase("crowd", energy);
    v.scoop = phase("scoop", energy);
    v.level = phase("level", energy) + phase("shake", energy);
    v.retreat = phase("retreat", energy);
    v.total = energy ? end.energy / 1e3 : end.time - end.t0;
  }
  // Energy before the scoop cycle began (navigation): total less the cycle's phases.
  double booked = 0;
  for (const control::PhaseRecord& p : r.phases) booked += p.energy / 1e3;
  rec.energy_kj.approach += std::max(0.0, rec.energy_kj.total - booked);
  rec.safety_margin_m = end.min_clearance;
  rec.safety_violations = end.violations;
  const Eigen::Vector2d frame_origin =
      r.tip_path.empty() ? end.start_xy : Eigen::Vector2d(r.tip_path.front().head<2>());
  BookSamples(r, end.t0, frame_origin, nav.goal ? nav.goal->pose.entry_heading : end.start_heading,
              rec);
}

void WriteCycleFigures(const std::filesystem::path& figures_dir, const perception::GridMap& map,
                       const std::vector<perception::ExtractedPile>& piles,
                       const NavigationGoal& nav, bool chen2024,
                       const planning::LoaderGeometry& loader, bool scooped, CycleOutcome& out) {
  const std::string n = std::to_string(out.record.cycle);  // the database's cycle index
  const std::filesystem::path map_png = figures_dir / ("map_cycle_" + n + ".png");
  perception::WriteSemanticMapPng(map, piles, map_png.string(), 2);
  out.figures.push_back(map_png);
  out.figure_titles.push_back("Cycle " + n + ": semantic elevation map layers (Fig. 5)");
  if (nav.goal) {
    const std::filesystem::path cand_png = figures_dir / ("candidates_cycle_" + n + ".png");
    planning::WriteCandidatePng(map, nav.selection, chen2024 ? &nav.baseline : nullptr, nav.from,
                                loader, cand_png.string());
    out.figures.push_back(cand_png);
    out.figure_titles.push_back("Cycle " + n + ": scored shovel points (Fig. 19)");
  }
  if (scooped) {
    const std::filesystem::path vol_png = figures_dir / ("volume_cycle_" + n + ".png");
    results::WriteVolumePlotPng(out.record, out.target_volume, vol_png);
    out.figures.push_back(vol_png);
    out.figure_titles.push_back("Cycle " + n + ": V1 and V1+V2 against time, trigger");
    const std::filesystem::path tip_png = figures_dir / ("tip_path_cycle_" + n + ".png");
    results::WriteTipPathPlotPng(out.record, tip_png);
    out.figures.push_back(tip_png);
    out.figure_titles.push_back("Cycle " + n + ": predicted (at the trigger) and actual tip");
  }
}

void SayCycleSummary(const CycleOutcome& out, bool scooped, const std::string& site,
                     double min_clearance, const CycleStats& stats, const CycleLog& log) {
  const results::CycleRecord& rec = out.record;
  const control::ScoopResult& r = out.scoop;
  if (out.no_shovel_point) {
    log.Say("skipped " + site + ": " + out.failure);
    return;
  }
  if (scooped && !r.payload_at_actions.empty()) {
    std::string volumes;
    for (double v : r.payload_at_actions) volumes += (volumes.empty() ? "" : ", ") + Fixed(v, 2);
    log.Say("bucket volume before the first atomic action and after each: " + volumes + " m^3");
  }
  if (scooped && r.drive_eased_for_boom) {
    log.Say("the drive eased: the boom stalled lifting against the pile");
  }
  const bool travel_known = scooped && std::isfinite(r.predicted_travel_at_trigger) &&
                            std::isfinite(r.travel_after_trigger);
  const bool supervised =
      out.safe_stops + out.refused_frames > 0 || out.blind_sector || out.masked_fraction > 0;
  log.Say(std::string(rec.completed ? "done" : "NOT completed: " + out.failure) + " — " + site +
          ", " + rec.material + ", " + rec.strategy + " (" + rec.atomic_actions + "), fill " +
          Fixed(100 * rec.fill_rate, 1) + " %, trigger " + Fixed(r.trigger_after_contact, 2) +
          " s after contact, cycle " + Fixed(rec.time_s.total, 1) + " s, " +
          Fixed(rec.energy_kj.total, 0) + " kJ, clearance " + Fixed(min_clearance, 2) +
          " m, path error " + Fixed(stats.path_error, 2) + " m, drove in " +
          Fixed(stats.scoop_advance, 2) + " m past the planned contact" +
          (travel_known ? ", predicted travel " + Fixed(r.predicted_travel_at_trigger, 2) +
                              " m, actual " + Fixed(r.travel_after_trigger, 2) + " m"
                        : "") +
          "; map " + std::to_string(stats.map_updates) + "× (" + Fixed(stats.map_seconds, 1) +
          " s), selection " + std::to_string(stats.selections) + "× (" +
          Fixed(stats.selection_seconds, 1) + " s)" +
          (supervised
               ? "; supervisor: " + std::to_string(out.safe_stops) + " stop(s), " +
                     std::to_string(out.recoveries) + " recover(ies), " +
                     std::to_string(out.refused_frames) + " late frame(s) refused" +
                     (out.blind_sector ? ", a LiDAR blind sector" : "") +
                     (out.masked_fraction > 0 ? ", up to " + Fixed(100 * out.masked_fraction, 0) +
                                                    " % of the image masked"
                                              : "")
               : ""));
}

}  // namespace autoshovel::app
