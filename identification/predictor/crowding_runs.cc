#include "identification/predictor/crowding_runs.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <random>
#include <thread>

#include "runtime/plant/plant.h"
#include "runtime/plant/poses.h"
#include "runtime/plant/scenario_builder.h"

namespace autoshovel::predictor {

namespace {

// Roughness of irregular piles as a fraction of their height, and their flank slope as a
// fraction of the angle of repose's tangent (the scenario reader's defaults, scenario.cc).
constexpr double kIrregularRoughness = 0.12;
constexpr double kIrregularSlopeFraction = 0.8;

int MaterialIndexOf(const model::MachineDescription& machine, const std::string& name) {
  for (std::size_t i = 0; i < machine.materials.size(); ++i) {
    if (machine.materials[i].name == name) return static_cast<int>(i);
  }
  throw std::invalid_argument("crowding run: machine '" + machine.name + "' knows no material '" +
                              name + "'");
}

prediction::HeightGrid Crop(const plant::Terrain& terrain, const Eigen::Vector2d& lo,
                            const Eigen::Vector2d& hi) {
  int ix0 = 0, iy0 = 0, ix1 = 0, iy1 = 0;
  const double r = terrain.resolution();
  const Eigen::Vector2d o = terrain.geometry().origin;
  ix0 = std::clamp(static_cast<int>(std::floor((lo.x() - o.x()) / r)), 0, terrain.nx() - 1);
  iy0 = std::clamp(static_cast<int>(std::floor((lo.y() - o.y()) / r)), 0, terrain.ny() - 1);
  ix1 = std::clamp(static_cast<int>(std::floor((hi.x() - o.x()) / r)), 0, terrain.nx() - 1);
  iy1 = std::clamp(static_cast<int>(std::floor((hi.y() - o.y()) / r)), 0, terrain.ny() - 1);
  prediction::HeightGrid grid;
  grid.resolution = r;
  grid.origin = o + r * Eigen::Vector2d(ix0, iy0);
  grid.nx = ix1 - ix0 + 1;
  grid.ny = iy1 - iy0 + 1;
  grid.height.reserve(static_cast<std::size_t>(grid.nx) * grid.ny);
  for (int iy = iy0; iy <= iy1; ++iy) {
    for (int ix = ix0; ix <= ix1; ++ix) grid.height.push_back(terrain.height(ix, iy));
  }
  return grid;
}

// A revisit's pile: what a previous scoop along the same approach (the loader at the origin
// facing +x) took away. The bucket cut at floor level across its width, plus 0.1 m a side, up to
// x = `face_x`, and the face and walls it left stand at the material's angle of repose: every
// cell is lowered to at most floor + tan(repose) · (distance to the cut). Cut straight to repose
// rather than cut vertical and relaxed: the plant's relaxation is a diffusion that needs
// thousands of sweeps to lay a 2 m face down. The removed material left with that bucket.
void DigFace(const model::MachineDescription& machine, plant::World& world, double face_x) {
  plant::Terrain& terrain = world.terrain;
  const double half_cut = 0.5 * machine.bucket.width + 0.1;
  for (int iy = 0; iy < terrain.ny(); ++iy) {
    for (int ix = 0; ix < terrain.nx(); ++ix) {
      const int material = terrain.material(ix, iy);
      if (material < 0) continue;
      const Eigen::Vector2d c = terrain.CellCenter(ix, iy);
      const double dx = std::max(c.x() - face_x, 0.0);
      const double dy = std::max(std::abs(c.y()) - half_cut, 0.0);
      const double slope = std::tan(machine.materials[material].angle_of_repose);
      const double cap = terrain.floor(ix, iy) + slope * std::hypot(dx, dy);
      if (terrain.height(ix, iy) > cap) terrain.SetHeight(ix, iy, cap);
    }
  }
}

}  // namespace

double TravelAt(const CrowdingRun& run, double t) {
  const std::vector<double>& s = run.travel_after_trigger;
  if (s.empty() || !(run.travel_sample_period > 0)) return run.penetration;
  const double k = std::max(t, 0.0) / run.travel_sample_period;
  if (k >= static_cast<double>(s.size() - 1)) return s.back();
  const std::size_t i = static_cast<std::size_t>(k);
  return s[i] + (k - static_cast<double>(i)) * (s[i + 1] - s[i]);
}

CrowdingRunSpec DrawSpec(const model::MachineDescription& machine,
                         const CrowdingRunOptions& options, std::uint64_t seed, int index) {
  std::seed_seq sequence{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                         static_cast<std::uint32_t>(index), 0x5eedu};
  std::mt19937_64 rng(sequence);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  CrowdingRunSpec spec;
  spec.index = index;
  spec.seed = rng();
  static const char* kShapes[] = {"cone", "irregular", "low"};
  spec.shape = kShapes[static_cast<int>(unit(rng) * 3) % 3];
  spec.material = machine.materials
                      .at(static_cast<std::size_t>(unit(rng) * machine.materials.size()) %
                          machine.materials.size())
                      .name;
  spec.height = spec.shape == "low" ? 0.5 + 0.5 * unit(rng) : 1.5 + 2.0 * unit(rng);
  spec.approach_speed = options.min_speed + (options.max_speed - options.min_speed) * unit(rng);
  spec.trigger_volume = machine.bucket.rated_capacity *
                        (options.min_trigger_fraction +
                         (options.max_trigger_fraction - options.min_trigger_fraction) * unit(rng));
  if (options.dug_face_fraction > 0 && unit(rng) < options.dug_face_fraction) {
    spec.dug_depth =
        options.min_dug_depth + (options.max_dug_depth - options.min_dug_depth) * unit(rng);
  }
  return spec;
}

CrowdingRun RunCrowding(const model::MachineDescription& machine,
                        const generated::MachineFunctions& functions,
                        const CrowdingRunOptions& options, const CrowdingRunSpec& spec) {
  CrowdingRun run;
  run.spec = spec;
  std::mt19937_64 rng(spec.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);

  // The loader at the origin facing +x, bucket on the floor; the pile's toe ahead of the tip
  // far enough to reach v0 (about 0.7 m/s² of acceleration) plus a metre.
  const std::vector<double> q0 = plant::BucketOnFloor(machine);
  const double tip_x = prediction::TipInBase(machine, q0[0], q0[1]).x();
  const double toe = tip_x + 1.0 + spec.approach_speed * spec.approach_speed / (2 * 0.7);
  const int m = MaterialIndexOf(machine, spec.material);
  const double tan_repose = std::tan(machine.materials[m].angle_of_repose);

  plant::Pile pile;
  pile.name = "pile";
  pile.material = spec.material;
  pile.material_index = m;
  pile.height = spec.height;
  pile.yaw = (unit(rng) - 0.5) * 0.6;
  double reach = 0, half_span = 0;  // toe to far end along x, half extent along y
  if (spec.shape == "low") {
    pile.shape = plant::PileShape::kLow;
    pile.slope = tan_repose;
    const double flanks = 2 * spec.height / tan_repose;
    pile.length = std::max(flanks, 4.0) + 4.0 * unit(rng);
    pile.width = std::max(flanks, 4.0) + 4.0 * unit(rng);
    reach = pile.length, half_span = 0.5 * std::hypot(pile.length, pile.width);
  } else {
    pile.shape = spec.shape == "cone" ? plant::PileShape::kCone : plant::PileShape::kIrregular;
    pile.slope = spec.shape == "cone" ? tan_repose : kIrregularSlopeFraction * tan_repose;
    pile.base_radius = spec.height / pile.slope;
    if (pile.shape == plant::PileShape::kIrregular) {
      pile.roughness = kIrregularRoughness * spec.height;
      pile.seed = rng();
    }
    reach = 2 * pile.base_radius, half_span = pile.base_radius;
  }
  pile.center = Eigen::Vector2d(toe + 0.5 * reach, (unit(rng) - 0.5) * 1.0);

  plant::World world;
  plant::GridGeometry geometry;
  geometry.resolution = options.map_resolution;
  const double x_min = -1.0, x_max = toe + reach + 1.5;
  const double y_half = std::max(half_span + 1.5, 0.5 * machine.bucket.width + 2.0);
  geometry.origin = Eigen::Vector2d(x_min, -y_half);
  geometry.nx = static_cast<int>(std::ceil((x_max - x_min) / geometry.resolution));
  geometry.ny = static_cast<int>(std::ceil(2 * y_half / geometry.resolution));
  world.terrain = plant::Terrain(geometry, 0.0);
  world.materials = machine.materials;
  std::vector<plant::Pile> piles = {pile};
  plant::BuildTerrain(world, piles, {});
  if (spec.dug_depth > 0) DigFace(machine, world, toe + spec.dug_depth);
  const plant::Terrain before = world.terrain;

  plant::MachineState start;
  start.q.assign(machine.num_joints(), 0.0);
  start.q[0] = q0[0], start.q[1] = q0[1];
  plant::Plant loader(machine, functions, world, start);

  core::ActuatorCommand command;
  command.valve.assign(machine.hydraulics.actuators.size(), 0.0);
  const int boom_valve = machine.ActuatorOfJoint(0), tilt_valve = machine.ActuatorOfJoint(1);
  double integral = 0;
  const double kp = 1.0, ki = 0.5;
  bool contact = false, triggered = false, curled = false, arm_moving = false;
  double contact_time = 0, trigger_time = 0, slowing_since = NAN;
  Eigen::Vector2d contact_hinge = Eigen::Vector2d::Zero();
  const double heading = 0;
  const double rack_back = machine.links[1].joint_max - options.rack_back_margin;
  double boom_target = 0, max_travel = 0;
  long tick = 0, trigger_tick = 0;
  run.travel_sample_period = options.travel_sample_period;
  const long sample_every = std::max(1L, std::lround(options.travel_sample_period / options.tick));
  while (true) {
    const plant::MachineState& s = loader.state();
    const double t = loader.time();
    if (!contact && loader.resistance().in_contact) {
      contact = true;
      contact_time = t;
      contact_hinge = s.hinge_xy;
    }
    if (!contact && t > 30) {
      run.failure = "no contact with the pile within 30 s";
      return run;
    }
    if (contact && !triggered) {
      run.past_path.push_back(loader.TipInWorld());
      if (tick % options.decision_every == 0) {
        const prediction::HeightGrid map =
            Crop(before, run.past_path.front().head<2>() - Eigen::Vector2d(1, 3),
                 run.past_path.back().head<2>() + Eigen::Vector2d(1, 3));
        const double v1 = prediction::Eq19Volume(map, run.past_path, machine.bucket.width).volume;
        const bool stalled = s.speed < options.stall_speed && t - contact_time > 0.3;
        if (v1 >= spec.trigger_volume || stalled || t - contact_time > options.max_crowd_time) {
          triggered = true;
          trigger_time = t;
          trigger_tick = tick;
          run.trigger_cause = v1 >= spec.trigger_volume ? "volume" : stalled ? "stall" : "time_out";
          const Eigen::Vector3d tip = run.past_path.back();
          run.features.speed = s.speed;
          run.features.shoveled_volume = v1;
          run.features.material = spec.material;
          run.features.heights = prediction::SampleHeightsAhead(
              [&](double x, double y) { return world.terrain.HeightAt(x, y); }, tip.head<2>(),
              heading, machine.bucket.width);
          run.at_trigger.hinge_xy = s.hinge_xy;
          run.at_trigger.heading = s.heading;
          run.at_trigger.speed = s.speed;
          run.at_trigger.q = {s.q[0], s.q[1]};
          run.contact_to_trigger = (s.hinge_xy - contact_hinge).x();
          run.payload_at_trigger = loader.bucket().payload_volume();
          run.plan = prediction::ScoopPlanFromMachine(machine, functions, s.q, 1.0, 1.0,
                                                      std::max(rack_back - s.q[1], 0.0),
                                                      options.boom_lift);
          boom_target = s.q[0] + options.boom_lift;
        }
      }
    }
    if (triggered) {
      const double travel = (s.hinge_xy - run.at_trigger.hinge_xy).x();
      max_travel = std::max(max_travel, travel);
      if ((tick - trigger_tick) % sample_every == 0) run.travel_after_trigger.push_back(travel);
      if (!curled && s.q[1] >= rack_back) curled = true;
      if (!arm_moving && s.q[1] > run.at_trigger.q[1] + 0.02) arm_moving = true;
      command.valve[tilt_valve] = curled ? 0.0 : 1.0;
      command.valve[boom_valve] = curled && s.q[0] < boom_target ? 1.0 : 0.0;
      const bool lifted = curled && s.q[0] >= boom_target;
      if ((lifted && std::abs(s.speed) < 0.02) || t - trigger_time > options.max_scoop_time) break;
    }
    if (arm_moving && std::isnan(slowing_since)) slowing_since = t;
    const bool pushing = options.scoop_deceleration > 0 && !(curled && s.q[0] >= boom_target);
    const double reference =
        arm_moving ? spec.approach_speed - options.scoop_deceleration * (t - slowing_since)
                   : spec.approach_speed;
    if (!triggered || !arm_moving || (pushing && reference > 0)) {
      const double error = reference - s.speed;
      const double u = kp * error + integral;
      if (u < 1.0 && u > 0.0) integral += ki * error * options.tick;  // no wind-up
      command.drive = std::clamp(u, 0.0, 1.0);
      command.brake = 0;
    } else if (options.scoop_deceleration > 0) {
      command.drive = 0;  // the reference has reached zero, or the boom is lifted
      command.brake = 1.0;
    } else {
      // Scoop: the crowd goes on through the hydraulic delay (Fig. 21 (a)–(b)); once the bucket
      // moves the drive is released (the machine runs on into the pile on its momentum while the
      // bucket curls) and the brake is applied once the bucket is racked back.
      command.drive = 0;
      command.brake = curled ? 1.0 : 0.0;
    }
    std::string why;
    if (!loader.SetCommand(command, &why)) {
      run.failure = "command refused: " + why;
      return run;
    }
    loader.Advance(options.tick);
    ++tick;
  }
  run.penetration = max_travel;
  run.payload = loader.bucket().payload_volume();
  run.simulated_time = loader.time();
  run.map =
      Crop(before, run.past_path.front().head<2>() - Eigen::Vector2d(1, options.map_margin + 1.5),
           run.past_path.back().head<2>() +
               Eigen::Vector2d(max_travel + 4 + options.map_margin, options.map_margin + 1.5));
  run.ok = true;
  return run;
}

std::vector<CrowdingRun> RunCrowdingBatch(
    const model::MachineDescription& machine, const generated::MachineFunctions& functions,
    const CrowdingRunOptions& options, std::uint64_t seed, int first, int count, int threads,
    const std::function<void(const CrowdingRun&, int done)>& progress) {
  std::vector<CrowdingRun> runs(static_cast<std::size_t>(count));
  std::atomic<int> next{0};
  std::mutex mutex;
  int done = 0;
  auto worker = [&] {
    for (int i = next++; i < count; i = next++) {
      const CrowdingRunSpec spec = DrawSpec(machine, options, seed, first + i);
      try {
        runs[i] = RunCrowding(machine, functions, options, spec);
      } catch (const std::exception& e) {
        runs[i].spec = spec;
        runs[i].failure = e.what();
      }
      std::lock_guard<std::mutex> lock(mutex);
      ++done;
      if (progress) progress(runs[i], done);
    }
  };
  std::vector<std::thread> pool;
  for (int k = 0; k < std::max(threads, 1); ++k) pool.emplace_back(worker);
  for (std::thread& t : pool) t.join();
  return runs;
}

}  // namespace autoshovel::predictor
