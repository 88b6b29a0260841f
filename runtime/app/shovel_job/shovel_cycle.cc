#include "runtime/app/shovel_job/shovel_cycle.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <sstream>

#include "runtime/app/crowd_lookahead.h"
#include "runtime/app/executive.h"
#include "runtime/app/plant_machine.h"
#include "runtime/app/shovel_job/clearance_record.h"
#include "runtime/app/shovel_job/control_task.h"
#include "runtime/app/shovel_job/crowd_watch.h"
#include "runtime/app/shovel_job/cycle_booking.h"
#include "runtime/app/shovel_job/joint_watch.h"
#include "runtime/app/shovel_job/machine_faults.h"
#include "runtime/app/shovel_job/map_update_task.h"
#include "runtime/app/shovel_job/path_watch.h"
#include "runtime/app/shovel_job/person_fault.h"
#include "runtime/app/shovel_job/scoop_handover.h"
#include "runtime/core/strings.h"
#include "runtime/perception/semantic_map.h"
#include "runtime/plant/plant.h"
#include "runtime/plant/poses.h"
#include "runtime/recording/recording_writer.h"
#include "runtime/recording/replay_check.h"
#include "runtime/sensors/raycast.h"

namespace autoshovel::app {

namespace {

// Where this site's piles lie: inside its bin, or, in the open yard, within the stockpile area
// the yard's plan gives (2 m beyond each open pile's footprint). A map pile elsewhere (noise far
// away, where Eq. (11) falls back on height alone) is not a work area. A recording keeps it as
// it is (recording::WorkArea), so a replay selects on the same piles.
recording::WorkArea SiteWorkArea(const plant::Scenario& scenario, const Site& site) {
  recording::WorkArea area;
  if (site.bin >= 0) {
    const plant::Bin& bin = scenario.bins[site.bin];
    area.kind = recording::WorkArea::Kind::kRectangle;
    area.front_center = bin.front_center;
    area.yaw = bin.yaw;
    area.width = bin.width;
    area.depth = bin.depth;
    return area;
  }
  area.kind = recording::WorkArea::Kind::kDiscs;
  for (const plant::Pile& q : scenario.piles) {
    if (q.bin >= 0) continue;
    const double extent = std::max({q.base_radius, q.length / 2, q.width / 2});
    area.discs.emplace_back(q.center.x(), q.center.y(), extent + 2.0);
  }
  return area;
}

control::ScoopCycleOptions ScoopOptionsFor(const ShovelRunOptions& o,
                                           const model::MachineDescription& machine) {
  control::ScoopCycleOptions scoop;
  scoop.tick = 1.0 / o.control_rate;
  scoop.decision_every =
      std::max(1, static_cast<int>(std::lround(o.control_rate / o.decision_rate)));
  const std::vector<double> q_attack = plant::BucketOnFloor(machine);
  scoop.attack_pose = {.boom = q_attack[0], .bucket = q_attack[1]};
  scoop.policy = o.policy;
  scoop.strategy.fixed_steps = o.stairway_steps;
  scoop.scoop_deceleration = o.scoop_deceleration;
  scoop.attack_speed = o.attack_speed;
  scoop.target_fill = o.target_fill;
  scoop.attitude_feed_forward = o.attitude_feed_forward;
  return scoop;
}

planning::ShovelPointConfig SelectionConfigFor(const CycleResources& r,
                                               const control::ScoopCycleOptions& scoop) {
  const ShovelRunOptions& o = r.options;
  planning::ShovelPointConfig config = r.selection;
  // Eq. (14) scores clearance but, as the seed writes it, only penalises a path that comes
  // closer than d_res (s_s = d_min / d_res). The run holds every cycle to the safety distance,
  // so our selection takes the best candidate whose planned clearance is at least the safety
  // distance plus `selection_margin` (ShovelPointTask; the path follower cuts corners and lags
  // curvature steps by some centimetres; the planned clearance already leaves out half a map
  // cell and half its outline sampling, shovel_point_selection.h).
  config.safety_distance = o.d_res;
  // Paths are planned at most at `curvature_reserve` of κmax: the follower keeps articulation
  // in hand to pull back onto a path whose curvature steps it can only follow at a finite rate.
  config.max_curvature = o.curvature_reserve * r.loader.MaxCurvature();
  // Eq. (14)'s area A runs on past the contact as far as the machine drives in, with the front
  // edge as far as the bucket reaches while it scoops (the boom lifted: beyond the tip on the
  // floor that the selection's body outline assumes).
  config.scoop_advance =
      o.scoop_drive_in + std::max(0.0, ScoopReach(r.machine, scoop.attack_pose.boom,
                                                  scoop.attack_pose.bucket, scoop.strategy) -
                                           r.loader.tip_reach);
  // The look-ahead ends the crowd once the sweep's front edge comes within the safety distance,
  // the planning margin, a map cell and the stopping distance of an obstacle ahead; the
  // selection's scoop drives on only as far (0.5 m stands in for the stopping distance,
  // v / f + v² / 2a at crowding speeds, and the middle of the front edge for the corridor).
  config.crowd_stop_distance =
      o.safety_distance + o.planning_margin + r.map.map().resolution() + 0.5;
  return config;
}

MapUpdateConfig MapUpdateConfigFor(const CycleResources& r) {
  MapUpdateConfig config;
  config.perceive.lighting = r.scenario.lighting;
  config.perceive.truth_labels = r.options.truth_labels;
  config.perceive.segmenter = r.segmenter;
  config.perceive.segmentation_scale = r.options.segmentation_scale;
  config.blind_sector_cone = r.options.supervisor.blind_sector_cone;
  config.max_masked_fraction = r.options.supervisor.max_masked_fraction;
  config.path_obstacle_margin = r.options.path_obstacle_margin;
  config.path_obstacle_confidence = r.options.path_obstacle_confidence;
  config.path_obstacle_height = r.options.path_obstacle_height;
  return config;
}

// The machine and the pile as the bucket touches it: what an optimal scoop from the same start
// needs (runtime/optimal). The pile is the plant's own terrain (simulation truth) sampled along
// the front frame's heading from the hinge, heights above the ground under the hinge.
ContactSnapshot SnapshotAtContact(const plant::Plant& plant, const results::CycleRecord& rec) {
  ContactSnapshot c;
  const plant::MachineState& state = plant.state();
  c.valid = state.q.size() >= 2;
  if (!c.valid) return c;
  c.speed = state.speed;
  c.q = {state.q[0], state.q[1]};
  c.payload_volume = state.payload_volume;
  c.material = rec.material;
  const plant::Terrain& terrain = plant.world().terrain;
  const Eigen::Vector2d forward(std::cos(state.heading), std::sin(state.heading));
  const double ground = terrain.HeightAt(state.hinge_xy.x(), state.hinge_xy.y());
  c.profile_start = 0;
  c.profile_spacing = 0.05;
  for (double x = 0; x <= 14.0 + 1e-9; x += c.profile_spacing) {
    const Eigen::Vector2d p = state.hinge_xy + x * forward;
    c.profile_heights.push_back(terrain.HeightAt(p.x(), p.y()) - ground);
  }
  return c;
}

plant::MachineState StartOf(const CycleResources& r, const Site& site, double start_clock) {
  plant::MachineState start = plant::StartState(r.scenario, r.machine);
  start.hinge_xy = site.start_xy;
  start.heading = site.start_heading;
  start.time = start_clock;
  return start;
}

plant::PlantOptions PlantOptionsFor(const ShovelRunOptions& o) {
  plant::PlantOptions options;
  options.energy_audit = o.energy_audit;
  return options;
}

// One cycle: the components and the tasks that connect them.
class ShovelCycle {
 public:
  ShovelCycle(CycleResources& r, const Site& site, int index, double start_clock,
              std::ostream* progress)
      : r_(r),
        o_(r.options),
        machine_(r.machine),
        site_(site),
        work_area_(SiteWorkArea(r.scenario, site)),
        in_site_([this](const Eigen::Vector2d& p) { return work_area_.Contains(p); }),
        log_(progress, index),
        start_(StartOf(r, site, start_clock)),
        plant_(machine_, r.functions, r.scenario.world, start_, PlantOptionsFor(o_)),
        machine_io_(plant_),
        scoop_options_(ScoopOptionsFor(o_, machine_)),
        t0_(plant_.time()),
        faults_(r.faults, index, t0_),
        mapping_(MapUpdateConfigFor(r)),
        selection_(SelectionConfigFor(r, scoop_options_), o_.safety_distance + o_.selection_margin,
                   o_.selection == SelectionMethod::kChen2024, r.loader, in_site_),
        control_(machine_, scoop_options_),
        supervisor_(o_.supervisor),
        path_watch_({.safety_distance = o_.safety_distance,
                     .planning_margin = o_.planning_margin,
                     .resume_clearance = o_.resume_clearance,
                     .resume_after = o_.resume_after,
                     .decision_rate = o_.decision_rate,
                     .max_deceleration = scoop_options_.speed_gains.max_deceleration}),
        crowd_watch_({.safety_distance = o_.safety_distance,
                      .planning_margin = o_.planning_margin,
                      .decision_rate = o_.decision_rate,
                      .max_deceleration = scoop_options_.speed_gains.max_deceleration,
                      .strategy = scoop_options_.strategy}),
        clearance_(o_.safety_distance) {
    results::CycleRecord& rec = out_.record;
    rec.cycle = index;
    rec.scenario = r.scenario.name;
    rec.machine = machine_.name;
    rec.bin = site.name;
    rec.completed = false;
    r.scene.Update();  // the terrain as the last cycle left it
    out_.target_volume = scoop_options_.target_fill * machine_.bucket.rated_capacity;
    if (r.recorder != nullptr) {
      r.recorder->SetSelection(selection_.config(), o_.safety_distance + o_.selection_margin,
                               o_.selection == SelectionMethod::kChen2024);
      r.recorder->BeginCycle(
          {.index = index, .site = site.name, .area = work_area_, .scoop = std::nullopt});
    }
  }

  CycleOutcome Run(const std::filesystem::path& figures_dir, double* end_clock);

  // The executive's tasks: which of the run's rates each runs at and the components it calls,
  // in order. Run() registers exactly these; ShovelJobArchitectureDot draws them.
  struct TaskSpec {
    const char* name;
    double ShovelRunOptions::*rate;
    void (ShovelCycle::*run)();
    std::vector<const char*> components;
  };
  static const std::vector<TaskSpec>& Tasks();

 private:
  enum class Stage { kSelect, kNavigate, kScoop, kSafeStop, kDone };

  void MapAndSelection();
  void Decide();
  void Supervise();
  void HandOver();
  void Control();
  void SafeStop(const std::string& reason);
  long RecordUpdate(bool select, const planning::Pose2& select_pose);
  void RecordScoop();
  void Finish(const std::filesystem::path& figures_dir);
  void Profile(const MultiRateExecutive& executive, double plant_seconds, long plant_steps,
               double finish_seconds);

  CycleResources& r_;
  const ShovelRunOptions& o_;
  const model::MachineDescription& machine_;
  const Site& site_;
  const recording::WorkArea work_area_;
  const std::function<bool(const Eigen::Vector2d&)> in_site_;
  const CycleLog log_;
  CycleOutcome out_;
  plant::MachineState start_;
  plant::Plant plant_;
  PlantMachine machine_io_;
  const control::ScoopCycleOptions scoop_options_;
  const double t0_;
  const FaultSchedule faults_;
  // The components (seed Fig. 2).
  MapUpdateTask mapping_;
  ShovelPointTask selection_;
  NavigationGoal nav_;
  ControlTask control_;
  SafetySupervisor supervisor_;
  PathWatch path_watch_;
  CrowdWatch crowd_watch_;
  ClearanceRecord clearance_;
  PersonOnPathFault person_;
  ScoopHandover handover_;
  // What flows between them.
  Stage stage_ = Stage::kSelect;
  std::string degraded_;  ///< degraded sensors as the last map update found them
  StopRecord stops_;
  double scoop_advance_ = 0;  ///< farthest the front axle went past the planned contact [m]
};

const std::vector<ShovelCycle::TaskSpec>& ShovelCycle::Tasks() {
  static const std::vector<TaskSpec> tasks = {
      {"map_and_selection",
       &ShovelRunOptions::map_rate,
       &ShovelCycle::MapAndSelection,
       {"MapUpdateTask", "ShovelPointTask", "NavigationGoal"}},
      {"state_machine_and_safety",
       &ShovelRunOptions::decision_rate,
       &ShovelCycle::Decide,
       {"ClearanceRecord", "PersonOnPathFault", "PathWatch", "CheckJoints", "CrowdWatch",
        "StartScoopCycle"}},
      {"control",
       &ShovelRunOptions::control_rate,
       &ShovelCycle::Control,
       {"ApplyMachineFaults", "ControlTask", "ScoopCycle"}},
  };
  return tasks;
}

void ShovelCycle::SafeStop(const std::string& reason) {
  // Abandons the cycle: the interlock holds the machine stopped until it rests.
  supervisor_.Stop(reason);
  machine_io_.HoldStop(true);
  stops_.Begin(plant_.state().hinge_xy, plant_.state().speed);
  out_.failure = "safe stop: " + reason;
  stage_ = Stage::kSafeStop;
  log_.Say("SAFE STOP at t = " + Fixed(plant_.time() - t0_, 2) + " s: " + reason);
}

// 7 Hz: the map from the sensors now, then (before committing to a path) the selection.
void ShovelCycle::MapAndSelection() {
  if (stage_ != Stage::kSelect && stage_ != Stage::kNavigate) return;
  std::vector<plant::OrientedBox> extra = plant_.OwnBodies();
  extra.insert(extra.end(), person_.boxes().begin(), person_.boxes().end());
  const MapUpdateResult seen =
      mapping_.Update(plant_, r_.scene, r_.rng, std::move(extra),
                      control_.target_speed() < 0 ? std::numbers::pi : 0.0, faults_, supervisor_,
                      r_.lens_dirt, r_.map, r_.semantic, log_);
  out_.masked_fraction = std::max(out_.masked_fraction, seen.camera_dirty_fraction);
  out_.blind_sector = out_.blind_sector || seen.blind_sector;
  degraded_ = seen.degraded;
  // Selection re-runs until the remaining path is short (a goal that moved under the bucket
  // would be chased): commit 5 m before the handover; a new goal must beat the one being driven
  // to by 0.05 in F (hysteresis against dithering between near-equal candidates).
  if (stage_ != Stage::kSelect && control_.remaining() <= o_.handover_distance + 5.0) {
    RecordUpdate(false, {});
    return;
  }
  const control::Proprioception s = machine_io_.Sense();  // the localisation, jumps included
  const long recorded = RecordUpdate(true, {s.hinge_xy, s.heading});
  const planning::ShovelCandidate* best = selection_.Select(
      r_.map.map(), r_.semantic.ground_plane(), planning::Pose2{s.hinge_xy, s.heading});
  if (recorded >= 0) {
    r_.recorder->AddReference(
        recording::MapDigestRow(recorded, r_.map.map()),
        recording::SelectionRow(recorded, out_.record.cycle, selection_.last_selection(), best));
  }
  if (stage_ == Stage::kSelect) {
    if (best == nullptr) {
      out_.failure = selection_.NoPointReason(site_.name);
      out_.no_shovel_point = true;
      stage_ = Stage::kDone;
      return;
    }
    const control::Proprioception now = machine_io_.Sense();
    nav_.Start(*best, true, selection_, {now.hinge_xy, now.heading}, r_.map.map(), r_.loader);
    stage_ = Stage::kNavigate;
    log_.Say(selection_.SelectedText(*best));
  } else if (best != nullptr) {
    const GoalChange change = selection_.Reconsider(*nav_.goal, *best);
    planning::Pose2 now;
    if (change.new_goal) {
      const control::Proprioception p = machine_io_.Sense();
      now = {p.hinge_xy, p.heading};
    }
    nav_.Start(*change.candidate, change.new_goal, selection_, now, r_.map.map(), r_.loader);
    if (!change.log.empty()) log_.Say(change.log);
  }
}

// The update just fused, its machine outline and (when selection runs on it) the localisation
// the selection plans from, into the recording; without a selection, the map's digest too.
// Returns the update's number, or −1 when nothing is recorded.
long ShovelCycle::RecordUpdate(bool select, const planning::Pose2& select_pose) {
  if (r_.recorder == nullptr) return -1;
  const plant::MachineState& s = plant_.state();
  recording::UpdateRow row;
  row.stamp = plant_.time();
  row.hinge_xy = s.hinge_xy;
  row.heading = s.heading;
  row.articulation = s.articulation;
  // As sim::SimulateSensorFrames outlines the machine for the map.
  row.tip_reach = (plant_.TipInWorld().head<2>() - s.hinge_xy).norm();
  row.select = select;
  row.select_xy = select_pose.xy;
  row.select_heading = select_pose.heading;
  const long update = r_.recorder->AddUpdate(row, mapping_.last_frames(), "camera");
  if (!select) r_.recorder->AddReference(recording::MapDigestRow(update, r_.map.map()), "");
  return update;
}

// The scoop's trigger decisions, the machine's V1 and V2 at each and its tip path, into the
// recording, with what the prediction assumed (material, V_t, the scoop it plans).
void ShovelCycle::RecordScoop() {
  if (r_.recorder == nullptr || handover_.material == nullptr) return;
  r_.recorder->SetScoop(
      {.material = handover_.material->name,
       .target_volume = out_.target_volume,
       .bucket_max = machine_.links[1].joint_max - scoop_options_.rack_back_margin,
       .boom_lift = scoop_options_.strategy.exit_boom_lift});
  std::vector<recording::DecisionRow> decisions;
  std::vector<double> v1, v2;
  for (const control::ScoopSample& sample : out_.scoop.samples) {
    decisions.push_back({.cycle = out_.record.cycle,
                         .time = sample.time,
                         .hinge_xy = sample.state.hinge_xy,
                         .heading = sample.state.heading,
                         .speed = sample.state.speed,
                         .q_boom = sample.state.q_boom,
                         .q_bucket = sample.state.q_bucket,
                         .path_points = static_cast<long>(sample.path_points),
                         .predict = !std::isnan(sample.v2)});
    v1.push_back(sample.v1);
    v2.push_back(sample.v2);
  }
  r_.recorder->AddScoop(decisions, v1, v2, out_.scoop.tip_path);
}

// The supervisor's 20 Hz checks (safety_supervisor.h): faults that put a person in the way, the
// sensor watchdog and the look-ahead along the path while driving, the actuators.
void ShovelCycle::Supervise() {
  const plant::MachineState& truth = plant_.state();
  const control::Proprioception sensed = machine_io_.Sense();
  const bool navigating = stage_ == Stage::kNavigate;
  person_.Update(faults_, navigating && nav_.goal ? &*nav_.goal : nullptr, truth,
                 machine_.chassis.hinge_to_front_axle, plant_.time(), log_);
  if (navigating) {
    path_watch_.Check(plant_.time(), degraded_, sensed, truth, machine_, nav_,
                      mapping_.sure_cells(), r_.map.map(), plant_.world(), supervisor_, machine_io_,
                      control_.speed_pid(), stops_, t0_, log_);
  }
  if (stage_ == Stage::kNavigate || stage_ == Stage::kScoop) {
    const std::string abandon =
        CheckJoints(supervisor_, machine_, plant_.time(), sensed, machine_io_.last_command(),
                    handover_.scoop.get(), t0_, log_);
    if (!abandon.empty()) SafeStop(abandon);
  }
}

// 20 Hz: the safety record on the truth, the supervisor, the crowd look-ahead, the hand-over.
void ShovelCycle::Decide() {
  const plant::MachineState& s = plant_.state();
  const double reach = prediction::TipInBase(machine_, s.q[0], s.q[1]).x();
  const perception::MachineFootprint footprint =
      perception::LoaderFootprint(machine_, s.hinge_xy, s.heading, s.articulation, reach);
  std::vector<plant::OrientedBox> truth_obstacles = r_.scenario.world.obstacles;
  truth_obstacles.insert(truth_obstacles.end(), person_.boxes().begin(), person_.boxes().end());
  clearance_.Update(footprint, truth_obstacles, s, control_.max_cross_track(), t0_, log_);
  Supervise();
  if (stage_ == Stage::kScoop && nav_.goal) {
    const Eigen::Vector2d front_axle =
        s.hinge_xy + machine_.chassis.hinge_to_front_axle *
                         Eigen::Vector2d(std::cos(s.heading), std::sin(s.heading));
    const double entry = nav_.goal->front_axle_goal.heading;
    scoop_advance_ =
        std::max(scoop_advance_, (front_axle - nav_.goal->front_axle_goal.xy)
                                     .dot(Eigen::Vector2d(std::cos(entry), std::sin(entry))));
  }
  if (stage_ == Stage::kScoop) {
    crowd_watch_.Check(s, footprint, machine_, *handover_.scoop, r_.map.map(), plant_.world(),
                       log_);
  }
  if (stage_ == Stage::kNavigate && control_.remaining() <= o_.handover_distance &&
      !supervisor_.stopped()) {
    HandOver();
  }
}

// Hands over to the scoop cycle with the map as it stands before contact.
void ShovelCycle::HandOver() {
  const ScoopHandoverInputs inputs{.options = o_,
                                   .machine = machine_,
                                   .functions = r_.functions,
                                   .predictor = r_.predictor,
                                   .optimal_solver = r_.optimal_solver,
                                   .scoop_options = scoop_options_,
                                   .piles = r_.scenario.piles,
                                   .in_site = in_site_,
                                   .site_name = site_.name};
  const std::string failure = StartScoopCycle(inputs, nav_.goal->pose.xy, r_.map.map(), faults_,
                                              machine_io_, handover_, log_);
  if (!failure.empty()) {
    out_.failure = failure;
    stage_ = Stage::kDone;
    return;
  }
  out_.record.material = handover_.material->name;
  crowd_watch_.SetObstacles(
      SureObstacleCells(r_.map.map(), o_.clear_obstacle_margin, o_.sure_obstacle_growth_cells),
      r_.map.map().resolution());
  stage_ = Stage::kScoop;
}

// 100 Hz: the machine's own faults, then the command for the stage.
void ShovelCycle::Control() {
  ApplyMachineFaults(faults_, machine_, machine_io_, plant_);
  const control::Proprioception s = machine_io_.Sense();
  if (stage_ == Stage::kSafeStop) {
    stops_.Track(plant_.state().hinge_xy);
    if (control_.BrakeToRest(machine_io_, plant_.state().speed)) stage_ = Stage::kDone;
    return;
  }
  const std::string pose_jump = supervisor_.CheckPose(s.time, s.hinge_xy, s.heading, s.speed);
  if (!pose_jump.empty()) {
    SafeStop(pose_jump);
    return;
  }
  if (stage_ == Stage::kNavigate || stage_ == Stage::kScoop) control_.Steer(nav_, s);
  if (stage_ == Stage::kNavigate) {
    control_.Navigate(machine_io_, s);
  } else if (stage_ == Stage::kSelect) {
    control_.Hold(machine_io_);
  } else if (stage_ == Stage::kScoop) {
    if (!control_.Scoop(*handover_.scoop, machine_io_)) stage_ = Stage::kDone;
  }
}

CycleOutcome ShovelCycle::Run(const std::filesystem::path& figures_dir, double* end_clock) {
  MultiRateExecutive executive(1.0 / o_.control_rate, plant_.time());
  for (const TaskSpec& task : Tasks()) {
    executive.Add(task.name, 1.0 / (o_.*task.rate),
                  [this, run = task.run](double) { (this->*run)(); });
  }
  std::string last_phase;
  double plant_seconds = 0;
  long plant_steps = 0;
  while (stage_ != Stage::kDone) {
    executive.Step();
    if (stage_ == Stage::kDone) break;
    const WallTimer plant_timer;
    plant_.Advance(1.0 / o_.control_rate);
    plant_seconds += plant_timer.Seconds();
    ++plant_steps;
    control::ScoopCycle* scoop = handover_.scoop.get();
    if (scoop != nullptr && scoop->phase_name() != last_phase) {
      last_phase = scoop->phase_name();
      // Contact: the crowd begins (a planned scoop goes from contact straight to its scoop).
      if ((last_phase == "crowd" || last_phase == "scoop") && !out_.contact.valid) {
        out_.contact = SnapshotAtContact(plant_, out_.record);
      }
      if (last_phase != "approach" && last_phase != "done") {
        log_.Say(last_phase + " at t = " + Fixed(plant_.time() - t0_, 2) + " s");
      }
    }
    if (plant_.time() - t0_ > o_.max_cycle_time) {
      out_.failure = "cycle not complete within " + Fixed(o_.max_cycle_time, 0) + " s";
      break;
    }
  }
  const WallTimer finish_timer;
  Finish(figures_dir);
  Profile(executive, plant_seconds, plant_steps, finish_timer.Seconds());
  *end_clock = plant_.time();
  return std::move(out_);
}

// The cycle's wall time by executive task, the components inside them, the plant's integration
// and the booking (run --profile).
void ShovelCycle::Profile(const MultiRateExecutive& executive, double plant_seconds,
                          long plant_steps, double finish_seconds) {
  RunProfile& p = out_.profile;
  for (const TaskSpec& task : Tasks()) {
    p.Add(std::string("task ") + task.name, executive.Seconds(task.name),
          executive.Calls(task.name));
    if (task.run != &ShovelCycle::MapAndSelection) continue;
    p.Add("sensor simulation (ray casting)", mapping_.simulation_seconds(), mapping_.calls(), 1);
    p.Add("map fusion (elevation, segmentation, semantic)", mapping_.fusion_seconds(),
          mapping_.calls(), 1);
    p.Add("shovel point selection", selection_.seconds(), selection_.selections(), 1);
  }
  p.Add("plant integration", plant_seconds, plant_steps);
  p.Add("cycle booking (figures, row)", finish_seconds, 1);
}

void ShovelCycle::Finish(const std::filesystem::path& figures_dir) {
  const bool scooped = handover_.scoop != nullptr;
  const double navigation_time = scooped ? 0.0 : plant_.time() - t0_;
  out_.safe_stops = supervisor_.safe_stops();
  out_.recoveries = supervisor_.recoveries();
  out_.stop_travel_m = stops_.travel;
  out_.refused_frames = supervisor_.refused_frames();
  out_.speed_at_stop = stops_.speed;
  if (scooped) out_.scoop = handover_.scoop->Finish(machine_io_);
  if (scooped) RecordScoop();
  const CycleEnd end{.scooped = scooped,
                     .t0 = t0_,
                     .time = plant_.time(),
                     .navigation_time = navigation_time,
                     .energy = machine_io_.Energy(),
                     .payload = machine_io_.PayloadVolume(),
                     .min_clearance = clearance_.min_clearance(),
                     .violations = clearance_.violations(),
                     .start_xy = start_.hinge_xy,
                     .start_heading = start_.heading};
  BookCycle(end, faults_, machine_, nav_, out_);
  if (o_.energy_audit) {
    out_.energy_audit_by_phase = plant_.phase_energy_audit();
    out_.energy_audit_trace = plant_.energy_audit_trace();
  }
  if (!figures_dir.empty() && o_.figures) {
    WriteCycleFigures(figures_dir, r_.map.map(), selection_.last_piles(), nav_,
                      o_.selection == SelectionMethod::kChen2024, r_.loader, scooped, out_);
  }
  SayCycleSummary(out_, scooped, site_.name, clearance_.min_clearance(),
                  {.path_error = control_.max_cross_track(),
                   .scoop_advance = scoop_advance_,
                   .map_updates = mapping_.calls(),
                   .map_seconds = mapping_.seconds(),
                   .selections = selection_.selections(),
                   .selection_seconds = selection_.seconds()},
                  log_);
}

}  // namespace

std::string ShovelJobArchitectureDot(const ShovelRunOptions& options) {
  // What flows between the components (seed Fig. 2); each end is a component of a task above,
  // the machine or the recorder.
  struct Flow {
    const char* from;
    const char* to;
    const char* what;
  };
  static const Flow kFlows[] = {
      {"SimulatedMachine", "MapUpdateTask", "LiDAR frames, camera image, pose"},
      {"MapUpdateTask", "ShovelPointTask", "semantic elevation map"},
      {"MapUpdateTask", "PathWatch", "sure obstacle cells, degraded sensors"},
      {"ShovelPointTask", "NavigationGoal", "best shovel point, path"},
      {"NavigationGoal", "ControlTask", "path"},
      {"NavigationGoal", "PathWatch", "path"},
      {"NavigationGoal", "StartScoopCycle", "goal at the handover distance"},
      {"MapUpdateTask", "StartScoopCycle", "pre-contact map"},
      {"StartScoopCycle", "ScoopCycle", "trigger, material, map"},
      {"StartScoopCycle", "CrowdWatch", "sure obstacle cells"},
      {"CrowdWatch", "ScoopCycle", "stop crowding"},
      {"CheckJoints", "ScoopCycle", "joint stalled under load"},
      {"PathWatch", "ControlTask", "stop / drive on"},
      {"SimulatedMachine", "ControlTask", "proprioception"},
      {"SimulatedMachine", "ScoopCycle", "proprioception, pressures"},
      {"SimulatedMachine", "CheckJoints", "joints, pressures, last command"},
      {"ControlTask", "SimulatedMachine", "drive, steering, valves"},
      {"ScoopCycle", "SimulatedMachine", "drive, valves"},
      {"ApplyMachineFaults", "SimulatedMachine", "sensor and actuator faults"},
      {"PersonOnPathFault", "SimulatedMachine", "a person in the yard"},
      {"ClearanceRecord", "CycleRecorder", "clearance (truth)"},
      {"ScoopCycle", "CycleRecorder", "phases, energy, V1 / V1+V2, tip path"},
  };
  std::ostringstream dot;
  dot << "// autoshovel architecture: the main job's components on the multi-rate executive\n"
         "digraph autoshovel_main_job {\n"
         "  rankdir=LR;\n  node [shape=box, fontname=\"Helvetica\", fontsize=10];\n"
         "  edge [fontname=\"Helvetica\", fontsize=8];\n";
  int k = 0;
  for (const ShovelCycle::TaskSpec& task : ShovelCycle::Tasks()) {
    dot << "  subgraph cluster_" << k++ << " {\n    label=\"" << task.name << " ("
        << core::FormatNumber(options.*task.rate) << " Hz)\";\n    style=rounded;\n";
    for (const char* component : task.components) dot << "    " << component << ";\n";
    dot << "  }\n";
  }
  dot << "  SimulatedMachine [shape=box3d, label=\"simulated machine\\n(plant: PlantMachine;\\n"
         "sensors: RaycastScene)\"];\n"
         "  CycleRecorder [shape=cylinder, label=\"recorder\\n(results.sqlite, figures, log)\"];\n";
  for (const Flow& f : kFlows) {
    dot << "  " << f.from << " -> " << f.to << " [label=\"" << f.what << "\"];\n";
  }
  dot << "}\n";
  return dot.str();
}

CycleOutcome RunShovelCycle(CycleResources& resources, const Site& site, int index,
                            double start_clock, double* end_clock,
                            const std::filesystem::path& figures_dir, std::ostream* progress) {
  ShovelCycle cycle(resources, site, index, start_clock, progress);
  return cycle.Run(figures_dir, end_clock);
}

}  // namespace autoshovel::app
