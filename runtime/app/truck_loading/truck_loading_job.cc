#include "runtime/app/truck_loading/truck_loading_job.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numbers>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "generated/registry.h"
#include "runtime/app/executive.h"
#include "runtime/app/safety_supervisor.h"
#include "runtime/app/stop_hold.h"
#include "runtime/app/truck_loading/excavator_on_plant.h"
#include "runtime/app/truck_loading/plant_dig_model.h"
#include "runtime/app/truck_loading/scan_record.h"
#include "runtime/app/truck_loading/world_height_grid.h"
#include "runtime/app/truck_scan/truck_scanner.h"
#include "runtime/app/truck_scan/world_rangefinder_scene.h"
#include "runtime/control/excavator/dig_motion.h"
#include "runtime/control/excavator/excavator_kinematics.h"
#include "runtime/control/excavator/excavator_simulator.h"
#include "runtime/control/excavator/joint_model.h"
#include "runtime/control/excavator/joint_servo.h"
#include "runtime/control/excavator/linkage_clearance.h"
#include "runtime/control/excavator/linkage_envelope.h"
#include "runtime/control/excavator/loading_script.h"
#include "runtime/control/excavator/obstacle_lookahead.h"
#include "runtime/control/excavator/script_parameters.h"
#include "runtime/machines/machine_code.h"
#include "runtime/model/description.h"
#include "runtime/planning/dig/coarse_dig_planner.h"
#include "runtime/planning/dig/refined_dig_planner.h"
#include "runtime/planning/dump/bed_height_map.h"
#include "runtime/planning/dump/dump_planner.h"
#include "runtime/plant/plant.h"
#include "runtime/plant/scenario.h"
#include "runtime/recording/scan_recording.h"
#include "runtime/sensors/raycast.h"
#include "runtime/sensors/rng.h"

namespace autoshovel::app {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kControlPeriod = 0.01;  ///< joint servos [s]
constexpr double kSafetyPeriod = 0.05;   ///< ground-truth clearance check [s]
constexpr double kMapHalfSize = 13.0;    ///< look-ahead map around the swing axis [m]
constexpr double kMapResolution = 0.2;   ///< [m]
constexpr double kPourOffset = 1.45;     ///< where a load lands, short of the bucket pin [m]
/// The look-ahead's horizon while stopped: longer than a swing back and lowering from rest take
/// (about 6 s on the 25 t machine), so that it covers the rest of the pass [s].
constexpr double kResumeHorizon = 10.0;
constexpr double kScanSwingRate = 42.0 * kDeg;   ///< the 90° pass's peak swing rate [rad/s]
constexpr double kBedScanHalfArc = 40.0 * kDeg;  ///< scan plane either side of the bed [rad]

/// The haul road: every cell beyond `edge_y` lowered to `-drop`, bare.
void CutHaulRoad(plant::Terrain& terrain, double edge_y, double drop) {
  for (int iy = 0; iy < terrain.ny(); ++iy) {
    for (int ix = 0; ix < terrain.nx(); ++ix) {
      if (terrain.CellCenter(ix, iy).y() <= edge_y) continue;
      if (terrain.depth(ix, iy) > 1e-9) {
        throw std::invalid_argument(
            "truck_loading: the scenario has material on the haul road at (" +
            std::to_string(terrain.CellCenter(ix, iy).x()) + ", " +
            std::to_string(terrain.CellCenter(ix, iy).y()) + ")");
      }
      terrain.SetFloor(ix, iy, -drop);
      terrain.SetHeight(ix, iy, -drop);
      terrain.SetMaterial(ix, iy, plant::Terrain::kNoMaterial);
    }
  }
}

/// The recognised truck as the scripts' obstacles. Recognition gives the bed's opening, its rim
/// and (when the road was seen) the rim's height above the road; the cab is not measured, so it
/// is the body's envelope ahead of the bed: 2.5 m long, 0.2 m wider than the opening, 0.6 m above
/// the rim (a tipper's cab guard; data-sheet typical). Walls 0.1 m thick.
std::vector<control::ObstacleBox> RecognisedTruckBoxes(
    const perception::TruckRecognitionResult& truck, double ground_z) {
  const Eigen::Isometry3d& T = truck.T_world_bed;
  const double yaw = truck.YawRad();
  const double rim = T.translation().z();
  const double length = truck.dimensions.length, width = truck.dimensions.width;
  const double bottom =
      std::isfinite(truck.dimensions.rim_height) ? rim - truck.dimensions.rim_height : ground_z;
  constexpr double kWall = 0.1, kCabLength = 2.5, kCabAboveRim = 0.6;
  std::vector<control::ObstacleBox> out;
  control::ObstacleBox body;
  body.center = T.translation().head<2>();
  body.yaw = yaw;
  body.half_extents = Eigen::Vector2d(0.5 * length + kWall, 0.5 * width + kWall);
  body.z_min = bottom;
  body.z_max = rim;
  out.push_back(body);
  control::ObstacleBox cab = body;
  cab.center = (T * Eigen::Vector3d(0.5 * length + kWall + 0.5 * kCabLength, 0, 0)).head<2>();
  cab.half_extents = Eigen::Vector2d(0.5 * kCabLength, 0.5 * width + kWall);
  cab.z_max = rim + kCabAboveRim;
  out.push_back(cab);
  return out;
}

/// §3's "slower, more conservative motion strategy": every joint's top rate scaled; latency,
/// braking and the final approach stay (they are the machine's, not the strategy's).
control::ExcavatorJointModels SlowedModels(control::ExcavatorJointModels models, double scale) {
  for (control::JointModelParams& m : models) {
    m.max_velocity_up *= scale;
    m.max_velocity_down *= scale;
  }
  return models;
}

std::vector<control::ObstacleBox> Boxes(const std::vector<plant::OrientedBox>& boxes) {
  std::vector<control::ObstacleBox> out;
  for (const plant::OrientedBox& b : boxes) out.push_back(ToObstacleBox(b));
  return out;
}

}  // namespace

Eigen::Vector2d PersonWalk::At(double t) const {
  const Eigen::Vector2d d = to - from;
  const double length = d.norm();
  if (length < 1e-9 || t <= 0) return t <= 0 ? from : to;
  const double walk = length / speed;
  double along;  // distance from `from`
  if (t < walk) {
    along = t * speed;
  } else if (t < walk + stay) {
    along = length;
  } else {
    along = std::max(0.0, length - (t - walk - stay) * speed);
  }
  return from + along / length * d;
}

bool TruckLoadingJob::IsTruckLoadingScenario(const std::string& scenario,
                                             const std::string& models_dir) {
  const plant::Scenario loaded = plant::LoadScenario(plant::ResolveScenario(scenario, models_dir));
  const model::MachineDescription machine =
      model::LoadMachineDescription(model::ResolveMachineDescription(loaded.machine, models_dir));
  return machine.kind == model::MachineKind::kExcavator;
}

struct TruckLoadingJob::State {
  TruckLoadingOptions options;
  plant::Scenario scenario;
  model::MachineDescription machine;
  const generated::MachineFunctions* functions = nullptr;
  std::unique_ptr<control::ExcavatorKinematics> kinematics;
  control::ExcavatorModelDerivation derivation;
  std::unique_ptr<control::LinkageEnvelope> envelope;
  std::unique_ptr<control::ObstacleLookAhead> lookahead;
  std::unique_ptr<control::ObstacleLookAhead> resume_lookahead;  ///< while stopped
  std::unique_ptr<control::ExcavatorJointServo> servo;
  std::unique_ptr<plant::Plant> plant;
  TruckPlacement truck;
  TruckRecognitionCheck recognition;
  // The scanner and what it knows (recognise_truck): the recognised truck and the bed map
  // measured on the first pass and on every swing back, fused (a cell keeps its last seen height).
  std::unique_ptr<TruckScanner> scanner;
  std::optional<perception::TruckRecognitionResult> recognised;
  std::optional<planning::BedHeightMap> scanned_bed;
  /// `--record`: the scans as they are made, and what the machine made of them.
  std::unique_ptr<recording::ScanRecordingWriter> recorder;
  int current_pass = 0;
  sensors::Rng rng;
  double speed_scale = 1.0;  ///< for the next pass, from the last scan's dust warning

  void AddDust(WorldRangefinderScene& scene) const {
    for (const DustCloud& cloud : options.dust) {
      sensors::DustProperties dust;
      dust.extinction = cloud.extinction;
      scene.AddDustSphere(cloud.p_world_center, cloud.radius, dust);
    }
  }
  std::vector<control::ObstacleBox> truck_boxes;       ///< what the scripts keep clear of
  std::vector<control::ObstacleBox> true_truck_boxes;  ///< the ground-truth check
  std::unique_ptr<planning::CoarseDigPlanner> coarse;
  std::unique_ptr<planning::RefinedDigPlanner> refined;
  planning::DumpPlanner dump_planner;
  control::DigMotionSettings dig_settings;
  control::ScriptSettings script_settings;
  planning::DigPlan next_dig;
  std::string material;
  double material_density = 1600;

  control::HeightGrid TerrainMap() const {
    // Terrain only (the dig planner's map): the world without its boxes.
    plant::World bare;
    bare.terrain = scenario.world.terrain;
    return HeightGridFromWorld(bare, Eigen::Vector2d::Zero(), kMapHalfSize, kMapResolution);
  }

  planning::BedHeightMap BedMap() const {
    std::vector<Eigen::Vector3d> p_world;
    const plant::Terrain& t = scenario.world.terrain;
    for (int index : truck.floor_cells) {
      const int ix = index % t.nx(), iy = index / t.nx();
      const Eigen::Vector2d c = t.CellCenter(ix, iy);
      p_world.emplace_back(c.x(), c.y(), t.height(ix, iy));
    }
    planning::BedHeightMapConfig config;
    // Heights above the floor: the bed-corner frame's origin is on the rim.
    const Eigen::Isometry3d T_world_floor =
        truck.T_world_bed_corner() * Eigen::Translation3d(0, 0, -truck.wall_height);
    return planning::BedHeightMap::FromWorldPoints(
        {.length_m = truck.inner_length, .width_m = truck.inner_width}, T_world_floor, p_world,
        config);
  }

  /// §2, §4.1: the left scanner's first-pass scan, the head panning during the first dig and on
  /// across the truck during the first swing (FirstPassScan, at the 90° pass's 42°/s peak).
  void RecogniseTruck(double dig_swing, double truck_swing) {
    TruckScannerConfig config;
    config.scanner = ScannerConfigFromDescription(machine, "left_scanner");
    scanner = std::make_unique<TruckScanner>(config);
    const std::vector<TruckScanMotion> phases =
        FirstPassScan(config.scanner, dig_swing, truck_swing, kScanSwingRate);
    const sensors::RaycastScene raycast(scenario.world);
    WorldRangefinderScene scene(raycast);
    AddDust(scene);
    rng.seed(options.seed);
    const TruckScanReport report =
        scanner->ScanAndRecognize(scene, Eigen::Isometry3d::Identity(), phases, rng);
    const perception::TruckRecognitionResult& r = report.recognition;
    if (!r.found) {
      throw std::runtime_error("truck_loading: the first-pass scan recognised no truck: " +
                               r.reason);
    }
    recognition.done = true;
    recognition.pulses = static_cast<long>(report.scan.pulses_fired);
    recognition.position_error =
        (r.T_world_bed.translation() - truck.T_world_bed.translation()).norm();
    recognition.yaw_error =
        std::abs(std::remainder(r.YawRad() - truck.pose.yaw, 2 * std::numbers::pi));
    recognition.length_error = r.dimensions.length - truck.inner_length;
    recognition.width_error = r.dimensions.width - truck.inner_width;
    truck_boxes = RecognisedTruckBoxes(r, -options.road_drop);
    recognised = r;
    if (report.bed_map) scanned_bed = *report.bed_map;
    speed_scale = report.scan.min_speed_scale;
    if (recorder) {
      const int scan = recorder->AddScan(
          ToRecordedScan(report.scan, recording::ScanKind::kRecognition, current_pass));
      recorder->SetTruckReference(TruckReferenceRow(r, report.truck_below_machine));
      if (scanned_bed) recorder->AddBedMapReference(BedMapReferenceRow(scan, *scanned_bed));
    }
  }

  /// §2, §4.3: the bed measured while the machine swings back from the truck (dump → dig at the
  /// scan's nominal 42°/s; the scan plane crosses the bed from 40° beyond its centre to 40°
  /// short of it), fused into the scanned map. Returns the cells seen, or -1 when the motion
  /// was out of the scanner's range (the map is then left as it was).
  int MeasureBed(double swing_from, double swing_to, std::ostream* progress, bool* dust_warning) {
    if (!scanner || !recognised || !scanned_bed) return -1;
    const Eigen::Vector3d c = recognised->T_world_bed.translation();
    const double bed_azimuth = std::atan2(c.y(), c.x());
    const double toward = swing_from >= swing_to ? 1.0 : -1.0;  // from the truck's side
    TruckScanMotion back;
    try {
      back = SwingWithCounterPan(
          scanner->config().scanner, swing_from, swing_to, speed_scale * kScanSwingRate,
          bed_azimuth + toward * kBedScanHalfArc, bed_azimuth - toward * kBedScanHalfArc);
    } catch (const std::invalid_argument& e) {
      if (progress) *progress << "  bed not scanned on the swing back: " << e.what() << "\n";
      return -1;
    }
    const sensors::RaycastScene raycast(scenario.world);
    WorldRangefinderScene scene(raycast);
    AddDust(scene);
    TruckScan scan;
    const planning::BedHeightMap seen =
        scanner->MeasureBed(scene, Eigen::Isometry3d::Identity(), back, *recognised, rng, &scan);
    // §3: what this scan saw of dust sets the next pass's speed.
    speed_scale = scan.min_speed_scale;
    if (dust_warning) *dust_warning = scan.dust_warning;
    const int known = FuseBedScan(*scanned_bed, seen);
    if (recorder) {
      const int number =
          recorder->AddScan(ToRecordedScan(scan, recording::ScanKind::kBed, current_pass));
      recorder->AddBedMapReference(BedMapReferenceRow(number, *scanned_bed));
    }
    return known;
  }

  struct LoadPlan {
    control::ExcavatorJointModels models;  ///< slowed by the last scan's dust warning
    control::ScriptParameters params;
    control::LoadingScript script;
  };
  struct LoadLoop;
  DigExecution Dig(PassOutcome& out, int index, std::ostream* progress);
  std::optional<LoadPlan> PlanLoad(const DigExecution& dig, PassOutcome& out,
                                   std::ostream* progress);

  planning::DigPlan PlanDig(std::ostream* progress) {
    const control::HeightGrid map = TerrainMap();
    PlantDigModel model(machine, *functions, *kinematics, derivation.models, scenario.world,
                        dig_settings);
    for (int attempt = 0; attempt < 64; ++attempt) {
      const std::optional<planning::DigRegion> region = coarse->NextRegion(map);
      if (!region) break;
      planning::DigPlan plan = refined->Plan(*region, map, model, truck_boxes);
      if (plan.status == planning::DigPlanStatus::kPlanned) {
        if (progress) {
          *progress << "  dig plan: region column " << region->column << " band " << region->band
                    << ", " << plan.evaluations << " dig simulations, predicted "
                    << plan.prediction.volume << " m3\n";
        }
        return plan;
      }
      coarse->MarkExhausted(*region);
    }
    planning::DigPlan none;
    none.why = "no feasible dig left in the sector";
    return none;
  }
};

TruckLoadingJob::TruckLoadingJob(const TruckLoadingOptions& options)
    : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.options = options;
  if (options.passes < 0 || options.max_passes < 1 || !(options.truck_payload > 0) ||
      !(options.road_drop > 0) || options.dig_evaluations < 1 || !(options.resume_after >= 0) ||
      !(options.max_pass_time > 0) || !std::isfinite(options.truck_radius) ||
      !std::isfinite(options.truck_azimuth_deg) || !std::isfinite(options.road_edge_y)) {
    throw std::invalid_argument(
        "truck_loading: passes >= 0, max_passes >= 1, a positive truck payload, road drop, "
        "resume time and pass time, dig evaluations >= 1 and finite truck pose are required");
  }
  for (const DustCloud& c : options.dust) {
    if (!c.p_world_center.allFinite() || !(c.radius > 0) || !(c.extinction > 0) ||
        !std::isfinite(c.radius) || !std::isfinite(c.extinction)) {
      throw std::invalid_argument(
          "truck_loading: a dust cloud needs a finite centre and a positive radius and extinction");
    }
  }
  if (options.person) {
    const PersonWalk& w = *options.person;
    if (!w.from.allFinite() || !w.to.allFinite() || !(w.speed > 0) || !(w.stay >= 0) ||
        !std::isfinite(w.start_delay) || w.pass < 0) {
      throw std::invalid_argument(
          "truck_loading: a person walk needs finite from/to and start delay, a positive speed, "
          "a stay >= 0 and a pass >= 0");
    }
  }
  s.scenario = plant::LoadScenario(plant::ResolveScenario(options.scenario, options.models_dir));
  const std::string description_path =
      model::ResolveMachineDescription(s.scenario.machine, options.models_dir);
  s.machine = model::LoadMachineDescription(description_path);
  if (s.machine.kind != model::MachineKind::kExcavator) {
    throw std::invalid_argument("truck_loading: scenario " + s.scenario.name + " names " +
                                s.machine.name + ", which is not an excavator");
  }
  s.functions = &machines::MachineFunctionsFor(s.machine);  // throws naming what to run
  s.kinematics = std::make_unique<control::ExcavatorKinematics>(s.machine, *s.functions);
  s.derivation = control::DeriveJointModels(
      s.machine, *s.functions, control::DefaultReferencePose(), s.machine.bucket.rated_load);
  s.envelope = std::make_unique<control::LinkageEnvelope>(
      *s.kinematics, control::DefaultEnvelopeConfig(s.machine));
  s.lookahead = std::make_unique<control::ObstacleLookAhead>(*s.envelope);
  control::LookAheadSettings resume;
  resume.horizon = kResumeHorizon;
  s.resume_lookahead = std::make_unique<control::ObstacleLookAhead>(*s.envelope, resume);
  s.servo =
      std::make_unique<control::ExcavatorJointServo>(s.machine, *s.functions, s.derivation.models);
  // The material of the face (the first pile's).
  if (s.scenario.piles.empty()) {
    throw std::invalid_argument("truck_loading: scenario " + s.scenario.name + " has no face");
  }
  s.material = s.scenario.piles.front().material;
  for (const model::Material& m : s.scenario.world.materials) {
    if (m.name == s.material) s.material_density = m.density;
  }

  CutHaulRoad(s.scenario.world.terrain, options.road_edge_y, options.road_drop);
  const double az = options.truck_azimuth_deg * kDeg;
  TruckPose pose;
  pose.p_world_bed = options.truck_radius * Eigen::Vector2d(std::cos(az), std::sin(az));
  pose.yaw = az + std::numbers::pi / 2;  // tangential, the cab away from the face
  pose.ground_z = -options.road_drop;
  s.truck = PlaceTruck(TruckBodyOf(options.truck), pose, &s.scenario.world);
  s.true_truck_boxes = Boxes(s.truck.boxes);
  s.truck_boxes = s.true_truck_boxes;

  planning::CoarseDigConfig coarse;
  coarse.sector.swing_min = -0.6;
  coarse.sector.swing_max = 0.45;
  coarse.sector.radius_min = 4.5;
  coarse.sector.radius_max = 10.0;
  coarse.sector.floor_height = 0.0;
  // Two bands over the 2.5 m face: a 1 m band leaves a thin top wedge of the ridge whose digs
  // take a fifth of a bucket.
  coarse.region_height = 1.25;
  s.coarse = std::make_unique<planning::CoarseDigPlanner>(coarse);
  // The approach 1.0 m above the entry point: the bucket, 1.5 m from pin to tip, reaches about
  // 0.7 m along the face towards the machine from its tip, and a 36° face rises 0.5 m over that.
  s.dig_settings.approach_height = 1.0;
  planning::RefinedDigConfig refined = planning::DefaultRefinedDigConfig(s.machine);
  refined.max_evaluations = options.dig_evaluations;
  // A region whose best dig fills less than half the bucket is done: the coarse planner moves on
  // (with the planner's default, 0.1 m³, the job scraped a dug-out region for a fifth of a
  // bucket at a time).
  refined.min_volume = 0.5 * s.machine.bucket.rated_capacity;
  refined.coarse_evaluations = std::max(1, options.dig_evaluations * 2 / 3);
  s.refined = std::make_unique<planning::RefinedDigPlanner>(*s.kinematics, refined);

  // The machine starts at the first dig's approach pose, as if a pass had just ended.
  s.next_dig = s.PlanDig(nullptr);
  if (s.next_dig.status != planning::DigPlanStatus::kPlanned) {
    throw std::runtime_error("truck_loading: no feasible first dig: " + s.next_dig.why);
  }
  if (!options.record_dir.empty()) {
    if (!options.recognise_truck) {
      throw std::invalid_argument(
          "truck_loading: --record keeps the scans, and with the truck taken from the truth "
          "(no recognition) there are none");
    }
    recording::ScanManifest manifest;
    manifest.scanner = "left_scanner";
    s.recorder = std::make_unique<recording::ScanRecordingWriter>(options.record_dir,
                                                                  description_path, manifest);
  }
  if (options.recognise_truck) s.RecogniseTruck(s.next_dig.action.swing, az);
  control::DigMotion first(*s.kinematics, ToStroke(s.next_dig.action), s.dig_settings);
  const std::optional<control::JointVector> q0 = first.ApproachPose();
  if (!q0) throw std::runtime_error("truck_loading: first dig's approach pose out of reach");
  plant::MachineState start;
  start.hinge_xy = Eigen::Vector2d(s.scenario.start.x, s.scenario.start.y);
  start.heading = s.scenario.start.heading;
  start.q.assign(q0->data(), q0->data() + control::kNumExcavatorJoints);
  if (start.hinge_xy.norm() > 1e-9 || std::abs(start.heading) > 1e-9) {
    throw std::invalid_argument(
        "truck_loading: the excavator must start at the world origin "
        "heading east (the job's frames assume base = world)");
  }
  s.plant = std::make_unique<plant::Plant>(s.machine, *s.functions, s.scenario.world, start);
}

TruckLoadingJob::~TruckLoadingJob() = default;

void TruckLoadingJob::CloseRecording() {
  if (state_->recorder) state_->recorder->Close();
}

const TruckPlacement& TruckLoadingJob::truck() const { return state_->truck; }
const TruckRecognitionCheck& TruckLoadingJob::recognition() const { return state_->recognition; }
double TruckLoadingJob::BucketCapacity() const { return state_->machine.bucket.rated_capacity; }
const std::string& TruckLoadingJob::scenario_name() const { return state_->scenario.name; }
const std::string& TruckLoadingJob::machine_name() const { return state_->machine.name; }
const std::string& TruckLoadingJob::material_name() const { return state_->material; }

double TruckLoadingJob::BedMass() const {
  return state_->truck.MaterialInBed(state_->scenario.world.terrain) * state_->material_density;
}

bool TruckLoadingJob::TruckFull() const { return BedMass() >= state_->options.truck_payload; }

planning::BedHeightMap TruckLoadingJob::BedMap() const { return state_->BedMap(); }

planning::FillSummary TruckLoadingJob::Fill() const {
  return planning::SummarizeFill(state_->BedMap(), state_->truck.wall_height);
}

std::string TruckLoadingJob::ConfigYaml() const {
  const TruckLoadingOptions& o = state_->options;
  std::ostringstream y;
  y << "job: truck_loading\nscenario: " << state_->scenario.name
    << "\nscenario_sha256: " << state_->scenario.sha256 << "\nmachine: " << state_->machine.name
    << "\nseed: " << o.seed << "\npasses: " << o.passes << "\nmax_passes: " << o.max_passes
    << "\ntruck: \"" << ToString(o.truck) << "\"\ntruck_payload_kg: " << o.truck_payload
    << "\ntruck_azimuth_deg: " << o.truck_azimuth_deg << "\ntruck_radius_m: " << o.truck_radius
    << "\nroad_drop_m: " << o.road_drop << "\nroad_edge_y_m: " << o.road_edge_y
    << "\ndig_evaluations: " << o.dig_evaluations << "\nresume_after_s: " << o.resume_after
    << "\nmax_pass_time_s: " << o.max_pass_time
    << "\nrecognise_truck: " << (o.recognise_truck ? "true" : "false")
    << "\nmaterial: " << state_->material << "\n";
  if (!o.dust.empty()) {
    y << "dust:\n";
    for (const DustCloud& c : o.dust) {
      y << "  - {center: [" << c.p_world_center.x() << ", " << c.p_world_center.y() << ", "
        << c.p_world_center.z() << "], radius: " << c.radius << ", extinction: " << c.extinction
        << "}\n";
    }
  }
  return y.str();
}

// The load phase of one pass (§4.4, §4.5): the script at 10 Hz, the servos at 100 Hz, the
// look-ahead at 10 Hz and the truth check at 20 Hz, until the script's final rules settle or the
// pass runs out of time.
struct TruckLoadingJob::State::LoadLoop {
  State& s;
  plant::Plant& plant;
  PassOutcome& out;
  const int index;
  std::ostream* progress;
  const double t_start, bed0;
  control::LoadingScript& script;
  ExcavatorOnPlant excavator;
  control::ExcavatorSimulator mirror;
  const double t_load;
  SafetySupervisor supervisor;  ///< the stop's reason, stops and recoveries
  StopHold hold;
  bool in_collision = false, finished = false;
  control::ExcavatorCommand command;
  std::string phase = "swing";
  std::map<std::string, std::pair<double, double>> phase_start;  // time, energy
  std::map<std::string, std::pair<double, double>> phase_total;
  int person_box = -1;
  double final_rules_since = std::numeric_limits<double>::quiet_NaN();
  std::vector<control::EnvelopePoint> underside;

  LoadLoop(State& state, PassOutcome& outcome, int pass, std::ostream* log, double start,
           double bed_before, control::LoadingScript& load_script,
           control::ExcavatorJointServo& servo, const control::ExcavatorJointModels& models)
      : s(state),
        plant(*state.plant),
        out(outcome),
        index(pass),
        progress(log),
        t_start(start),
        bed0(bed_before),
        script(load_script),
        excavator(plant, servo),
        mirror(models, excavator.Sense()),
        t_load(plant.time()),
        hold(state.options.resume_after) {
    command.position = excavator.Sense().q;
    plant.SetPhase(phase);
    phase_start[phase] = {plant.time(), plant.energy().hydraulic};
  }

  // On the multi-rate executive the main job runs on (executive.h): sensing and the servos at
  // 100 Hz, the script and its look-ahead at 10 Hz, the truth check at 20 Hz, in that order
  // within a tick. Once the script's final rules have settled nothing more runs.
  void Run() {
    MultiRateExecutive executive(kControlPeriod, plant.time());
    control::ExcavatorState measured;
    executive.Add("sense", kControlPeriod, [&](double) {
      measured = excavator.Sense();
      WalkPerson(plant.time());
    });
    executive.Add("script_and_lookahead", control::LoadingScript::kPeriod, [&](double) {
      if (!finished) finished = ScriptStep(plant.time(), measured);
    });
    executive.Add("truth_check", kSafetyPeriod, [&](double) {
      if (!finished) SafetyCheck(plant.time(), measured);
    });
    executive.Add("servos", kControlPeriod, [&](double) {
      if (finished) return;
      excavator.Command(command);
      mirror.Advance(kControlPeriod);
      excavator.Advance(kControlPeriod);
    });
    while (!finished && plant.time() - t_start < s.options.max_pass_time) executive.Step();
    SwitchPhase("idle");
  }

  void SwitchPhase(const std::string& next) {
    if (next == phase) return;
    if (progress) {
      *progress << "  " << phase << " -> " << next << " at " << plant.time() - t_start
                << " s, bucket holds " << plant.bucket().payload_volume() << " m3, bed "
                << s.truck.MaterialInBed(s.scenario.world.terrain) - bed0 << " m3\n";
    }
    phase_total[phase].first += plant.time() - phase_start[phase].first;
    phase_total[phase].second += plant.energy().hydraulic - phase_start[phase].second;
    phase = next;
    phase_start[phase] = {plant.time(), plant.energy().hydraulic};
    plant.SetPhase(phase);
  }

  // A person walking into the yard.
  void WalkPerson(double t) {
    if (!s.options.person || s.options.person->pass != index ||
        t - t_load < s.options.person->start_delay) {
      return;
    }
    const PersonWalk& w = *s.options.person;
    const Eigen::Vector2d p = w.At(t - t_load - w.start_delay);
    int ix, iy;
    const double ground = s.scenario.world.terrain.CellOf(p.x(), p.y(), ix, iy)
                              ? s.scenario.world.terrain.height(ix, iy)
                              : 0.0;
    plant::OrientedBox box;
    box.name = "person";
    box.center = Eigen::Vector3d(p.x(), p.y(), ground + 0.9);
    box.half_extents = Eigen::Vector3d(0.25, 0.25, 0.9);
    box.semantic_class = core::SemanticClass::kPerson;
    if (person_box < 0) {
      s.scenario.world.obstacles.push_back(box);
      person_box = static_cast<int>(s.scenario.world.obstacles.size()) - 1;
    } else {
      s.scenario.world.obstacles[person_box] = box;
    }
  }

  // 10 Hz: the script's next step, the look-ahead's stop or resume, the phase booking. True
  // once the script's final rules have settled.
  bool ScriptStep(double t, const control::ExcavatorState& measured) {
    const control::HeightGrid map = HeightGridFromWorld(s.scenario.world, Eigen::Vector2d::Zero(),
                                                        kMapHalfSize, kMapResolution);
    if (!supervisor.stopped()) {
      const control::ScriptOutput step = script.Step(measured.q);
      command = step.command;
      mirror.Command(command);
    }
    // §4.5: predict the script's next 2.5 s (from the script's state after this evaluation).
    // Stopped, the machine resumes only when the rest of its moves is clear: from rest, what
    // stopped it lies further ahead than 2.5 s, and a 2.5 s check would let it creep up to a
    // person in stop-and-go steps.
    mirror.Resync(measured);
    const control::ObstacleLookAhead& lookahead =
        supervisor.stopped() ? *s.resume_lookahead : *s.lookahead;
    const control::LookAheadResult check =
        lookahead.Check(measured, mirror, &script, control::LoadingScript::kPeriod, map,
                        Eigen::Isometry3d::Identity());
    // The supervisor's hold rule, shared with the loader (stop_hold.h).
    const std::string reason =
        check.stop() ? (check.reason.empty() ? "look-ahead" : check.reason) : "";
    const StopHold::Change change = hold.Update(t, reason, supervisor);
    if (check.stop()) {
      if (change == StopHold::Change::kStopped) {
        ++out.safety_stops;
        if (progress) {
          *progress << "  look-ahead stop at " << t - t_start << " s: " << check.reason;
          if (check.collision) {
            *progress << " (point " << check.collision->p_world.transpose() << " under cell "
                      << check.collision->cell_height << " m)";
          }
          *progress << "\n";
        }
      }
      command = control::ExcavatorCommand{};
      command.stop = true;
      mirror.Command(command);
    } else if (change == StopHold::Change::kResumed) {
      if (progress) *progress << "  resumed at " << t - t_start << " s\n";
      command.position = script.Commands();
      command.stop = false;
      mirror.Command(command);
    }
    // Phase booking from the bucket's script: opening = dump, moving to dig = return.
    const int bucket_rule = script.active_rule(control::ExcavatorJoint::kBucket);
    SwitchPhase(bucket_rule == 0 ? "swing" : bucket_rule == 1 ? "dump" : "return");
    if (!script.AtFinalRules()) return false;
    if (std::isnan(final_rules_since)) final_rules_since = t;
    // The machine settles within the servos' hold band, or a few seconds after the last rules
    // began (a boom that rings around its target holds no pass back).
    return script.Finished(measured, 0.05, 0.1) || t - final_rules_since > 6.0;
  }

  // 20 Hz: the linkage's underside against the true truck and any person (simulation truth),
  // and the trace.
  void SafetyCheck(double t, const control::ExcavatorState& measured) {
    s.envelope->Underside(measured.q, Eigen::Isometry3d::Identity(), underside);
    const double truck_clearance = control::MinClearance(underside, s.true_truck_boxes);
    out.min_truck_clearance = std::min(out.min_truck_clearance, truck_clearance);
    double person_clearance = std::numeric_limits<double>::infinity();
    if (person_box >= 0) {
      person_clearance =
          control::MinClearance(underside, {ToObstacleBox(s.scenario.world.obstacles[person_box])});
      out.min_person_clearance = std::min(out.min_person_clearance, person_clearance);
    }
    const bool colliding = truck_clearance < 0 || person_clearance < 0;
    if (colliding && !in_collision) ++out.collisions;
    in_collision = colliding;
    TraceSample sample;
    sample.t = t - t_load;
    sample.phase = phase;
    sample.p_world_tip = s.kinematics->TipPosition(measured.q);
    int ix, iy;
    sample.ground_below_tip =
        s.scenario.world.terrain.CellOf(sample.p_world_tip.x(), sample.p_world_tip.y(), ix, iy)
            ? s.scenario.world.terrain.height(ix, iy)
            : 0.0;
    sample.stopped = supervisor.stopped();
    out.trace.push_back(std::move(sample));
  }

  // The pass's figures once the loop is over: the bed scanned on the swing back, phase times and
  // energies, what reached the bed, why it failed.
  void Book(double swing_dump) {
    // §2: the swing back scanned the bed as it is now.
    if (finished) {
      const int seen = s.MeasureBed(
          swing_dump, excavator.Sense().q[control::JointIndex(control::ExcavatorJoint::kSwing)],
          progress, &out.dust_warning);
      out.bed_cells_seen = seen;
      if (progress && out.dust_warning) {
        *progress << "  dust warning on the swing-back scan: the next pass at " << s.speed_scale
                  << " of full speed\n";
      }
      if (progress && seen >= 0) {
        *progress << "  bed scanned on the swing back: " << seen << " cells seen, "
                  << s.scanned_bed->known_count() << " of "
                  << s.scanned_bed->cells_x() * s.scanned_bed->cells_y() << " known\n";
      }
    }
    out.swing_time = phase_total["swing"].first;
    out.swing_energy = phase_total["swing"].second;
    out.dump_time = phase_total["dump"].first;
    out.dump_energy = phase_total["dump"].second;
    out.return_time = phase_total["return"].first;
    out.return_energy = phase_total["return"].second;
    out.total_time = plant.time() - t_start;
    out.dumped_volume = s.truck.MaterialInBed(s.scenario.world.terrain) - bed0;
    out.dumped_mass = out.dumped_volume * s.material_density;
    if (person_box >= 0) {
      s.scenario.world.obstacles.erase(s.scenario.world.obstacles.begin() + person_box);
    }
    out.completed = finished && out.collisions == 0;
    if (!finished) {
      std::ostringstream why;
      why << "pass took longer than " << s.options.max_pass_time << " s (rules";
      for (control::ExcavatorJoint j : control::kAllExcavatorJoints) {
        why << " " << control::JointName(j) << " " << script.active_rule(j) + 1 << "/"
            << script.script(j).rules.size();
      }
      why << "; q " << excavator.Sense().q.transpose() << " against "
          << script.Commands().transpose() << ")";
      out.failure = why.str();
    }
    if (out.collisions > 0) out.failure = "collision";
  }
};

// 1. Dig (§4.2), executed by the dig motion on the machine.
DigExecution TruckLoadingJob::State::Dig(PassOutcome& out, int index, std::ostream* progress) {
  const double t_start = plant->time();
  out.dig = next_dig.action;
  out.predicted_volume = next_dig.prediction.volume;
  plant->SetPhase("dig");
  const double e_dig0 = plant->energy().hydraulic;
  control::DigMotion motion(*kinematics, ToStroke(out.dig), dig_settings);
  const DigExecution dig = ExecuteDig(*plant, *servo, *kinematics, motion, kControlPeriod);
  out.dig_time = plant->time() - t_start;
  out.dig_energy = plant->energy().hydraulic - e_dig0;
  out.dug_volume = dig.volume;
  if (progress) {
    *progress << "pass " << index + 1 << ": dig at swing " << out.dig.swing / kDeg << " deg, r "
              << out.dig.radius << " m: " << dig.volume << " m3 in " << out.dig_time << " s"
              << (dig.done ? "" : " (" + dig.failure + ")") << "\n";
  }
  return dig;
}

// 2. Plan: the next dig on the face as this one left it, the dump point on the bed, and the
// loading script from where the dig ended. Empty when no script can be made (out.failure says
// why).
std::optional<TruckLoadingJob::State::LoadPlan> TruckLoadingJob::State::PlanLoad(
    const DigExecution& dig, PassOutcome& out, std::ostream* progress) {
  State& s = *this;
  s.next_dig = s.PlanDig(progress);
  out.dig_evaluations = s.next_dig.evaluations;
  // The bed as the scanner has seen it (heights in the recognised bed-corner frame, rim at 0),
  // or as it is when no scan was made.
  const planning::DumpPlan dump =
      s.scanned_bed
          ? s.dump_planner.Plan(*s.scanned_bed, s.recognised->T_world_bed_corner())
          : s.dump_planner.Plan(s.BedMap(), s.truck.T_world_bed_corner() *
                                                Eigen::Translation3d(0, 0, -s.truck.wall_height));

  out.p_world_dump = dump.p_world_dump;
  control::LoadingGoal goal;
  // The scripts put the bucket pin above their dump point, but the opened bucket pours over its
  // lower rim, which hangs towards the machine: on the plant a load poured with the pin above the
  // planned point lands 1.35 m to 1.6 m closer to the machine (measured with this job's progress
  // output). The pin is aimed that much beyond the planned point.
  goal.p_base_dump = dump.p_world_dump;  // base = world (checked in the constructor)
  goal.p_base_dump.head<2>() += kPourOffset * goal.p_base_dump.head<2>().normalized();
  goal.truck = s.truck_boxes;
  // The return is not checked against the face here (ground_height stays NaN): the script's
  // ground test is one height for the whole return, which a face rising above the next dig's
  // approach point cannot meet; the look-ahead watches the face instead.
  if (s.next_dig.status == planning::DigPlanStatus::kPlanned) {
    const planning::DigAction& a = s.next_dig.action;
    goal.p_base_dig = control::ExcavatorKinematics::BaseFromArmPlane(
        a.swing, Eigen::Vector2d(a.radius, a.entry_height));
  } else {
    // Nothing left to dig: return over the last dig and stop there.
    goal.p_base_dig = control::ExcavatorKinematics::BaseFromArmPlane(
        out.dig.swing, Eigen::Vector2d(out.dig.radius, out.dig.entry_height));
  }
  // The pass ends where the next dig's motion begins: its approach point, at the attitude the
  // dig motion found reachable there.
  control::ScriptSettings settings = s.script_settings;
  settings.dig_approach_height = s.dig_settings.approach_height;
  if (s.next_dig.status == planning::DigPlanStatus::kPlanned) {
    control::DigMotion next(*s.kinematics, ToStroke(s.next_dig.action), s.dig_settings);
    if (const std::optional<control::JointVector> q = next.ApproachPose()) {
      settings.dig_attitude = (*q)[0] + (*q)[1] + (*q)[2];
    }
  }
  // When the pin cannot be put over the aimed point (beyond the arm's reach with the truck
  // cleared), it is pulled back towards the machine in steps: a load landing short of the
  // planned cell still lands in the bed.
  // §3: after a dust warning the whole load phase runs slower; the scripts' parameters, the
  // look-ahead's mirror and the servos share the slowed models, so predictions stay those of the
  // machine that moves. (The dig runs at its own speeds: it is in the face, not near the truck.)
  out.speed_scale = s.speed_scale;
  const control::ExcavatorJointModels models =
      SlowedModels(s.derivation.models, std::clamp(s.speed_scale, 0.05, 1.0));
  control::ScriptParameters params;
  const Eigen::Vector2d aimed = goal.p_base_dump.head<2>();
  for (int attempt = 0;; ++attempt) {
    try {
      params = control::ComputeScriptParameters(*s.envelope, models, dig.end_state, goal, settings);
      break;
    } catch (const std::invalid_argument& e) {
      if (attempt == 3) {
        out.failure = std::string("script parameters: ") + e.what();
        return std::nullopt;
      }
      goal.p_base_dump.head<2>() = aimed - (attempt + 1) * kPourOffset / 3.0 * aimed.normalized();
      if (progress) {
        *progress << "  dump pin pulled back " << (attempt + 1) * kPourOffset / 3.0
                  << " m towards the machine: " << e.what() << "\n";
      }
    }
  }
  return LoadPlan{models, params, control::BuildLoadingScript(params, settings)};
}

PassOutcome TruckLoadingJob::RunPass(int index, std::ostream* progress) {
  State& s = *state_;
  s.current_pass = index;
  PassOutcome out;
  out.index = index;
  out.min_truck_clearance = std::numeric_limits<double>::infinity();
  out.min_person_clearance = std::numeric_limits<double>::infinity();
  if (s.next_dig.status != planning::DigPlanStatus::kPlanned) {
    out.failure = "no dig left: " + s.next_dig.why;
    return out;
  }
  const double t_start = s.plant->time();
  const double bed0 = s.truck.MaterialInBed(s.scenario.world.terrain);
  const DigExecution dig = s.Dig(out, index, progress);
  std::optional<State::LoadPlan> plan = s.PlanLoad(dig, out, progress);
  if (!plan) return out;
  // 3. Load.
  control::ExcavatorJointServo servo(s.machine, *s.functions, plan->models);
  State::LoadLoop load(s, out, index, progress, t_start, bed0, plan->script, servo, plan->models);
  load.Run();
  load.Book(plan->params.swing_dump);
  if (progress) {
    char line[300];
    std::snprintf(line, sizeof line,
                  "  load: swing %.1f s, dump %.1f s, return %.1f s; dumped %.2f m3 (%.0f kg); "
                  "truck clearance %.2f m; %d stop(s)\n",
                  out.swing_time, out.dump_time, out.return_time, out.dumped_volume,
                  out.dumped_mass, out.min_truck_clearance, out.safety_stops);
    *progress << line;
  }
  return out;
}

}  // namespace autoshovel::app
