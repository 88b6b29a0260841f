// Plant benchmarks: `build/plant_bench`. The real-time factor of a crowd + scoop cycle is
// reported as the counter `rtf` (simulated seconds per CPU second; issue goal ≥ 200 on one core).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <ctime>

#include "generated/registry.h"
#include "runtime/model/description.h"
#include "runtime/plant/plant.h"
#include "runtime/plant/poses.h"

namespace {

using namespace autoshovel;

struct Fixture {
  model::MachineDescription machine;
  plant::World world;
  int material = 0;

  explicit Fixture(const std::string& material_name) {
    const std::string models = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";
    machine = model::LoadMachineDescription(model::ResolveMachineDescription("xcmg_968ev", models));
    plant::GridGeometry geometry;
    geometry.resolution = 0.05;
    geometry.nx = geometry.ny = 480;  // 24 m × 24 m at the default physics resolution
    geometry.origin = Eigen::Vector2d(-12, -12);
    world.terrain = plant::Terrain(geometry, 0.0);
    world.materials = machine.materials;
    for (std::size_t i = 0; i < world.materials.size(); ++i) {
      if (world.materials[i].name == material_name) material = static_cast<int>(i);
    }
    // A 3.5 m cone at the material's angle of repose, centred 8 m ahead.
    const double slope = std::tan(world.materials[material].angle_of_repose);
    plant::Terrain& t = world.terrain;
    for (int iy = 0; iy < t.ny(); ++iy) {
      for (int ix = 0; ix < t.nx(); ++ix) {
        const double h = 3.5 - slope * (t.CellCenter(ix, iy) - Eigen::Vector2d(8, 0)).norm();
        if (h > 0)
          t.SetHeight(ix, iy, h), t.SetMaterial(ix, iy, static_cast<std::int16_t>(material));
      }
    }
  }
};

double CpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// Approach from standstill 1 m before the toe, crowd until the machine stalls (or 3 s), then
// scoop: boom up and bucket curled to its rack-back while pushing gently, for 3 s.
void CrowdScoopCycle(benchmark::State& state, const std::string& material) {
  const Fixture fixture(material);
  const generated::MachineFunctions& functions = *generated::FindMachine("xcmg_968ev");
  const double toe =
      8.0 - 3.5 / std::tan(fixture.world.materials[fixture.material].angle_of_repose);
  double simulated = 0, cpu = 0, energy = 0, payload = 0;
  long steps = 0;
  for (auto _ : state) {
    state.PauseTiming();
    plant::World world = fixture.world;
    plant::MachineState start;
    start.hinge_xy = Eigen::Vector2d(toe - 4.1, 0.0);  // the tip 1 m before the toe
    start.q = plant::BucketOnFloor(fixture.machine);
    state.ResumeTiming();
    const double cpu0 = CpuSeconds();
    plant::Plant plant(fixture.machine, functions, world, start);
    core::ActuatorCommand command;
    command.valve = {0.0, 0.0};
    command.drive = 0.6;
    plant.SetPhase("crowd");
    double stall_timer = 0, scoop_start = -1;
    while (scoop_start < 0 || plant.time() < scoop_start + 3.0) {
      if (scoop_start < 0) {
        stall_timer = plant.state().speed < 0.15 && plant.time() > 1.0 ? stall_timer + 0.01 : 0;
        if (stall_timer > 0.3 || plant.time() > 4.0) {
          scoop_start = plant.time();
          plant.SetPhase("scoop");
        }
      } else {
        command.drive = 0.2;
        command.valve = {0.9, plant.state().q[1] < 0.95 ? 0.9 : 0.0};
      }
      plant.SetCommand(command);
      plant.Advance(0.01);
    }
    cpu += CpuSeconds() - cpu0;
    simulated += plant.time();
    energy = plant.energy().total();
    payload = plant.bucket().payload_volume();
    steps = plant.counters().steps;
  }
  state.counters["rtf"] = simulated / cpu;
  state.counters["sim_s"] = simulated / static_cast<double>(state.iterations());
  state.counters["energy_kJ"] = energy / 1e3;
  state.counters["payload_m3"] = payload;
  state.counters["cvode_steps"] = static_cast<double>(steps);
}

}  // namespace

BENCHMARK_CAPTURE(CrowdScoopCycle, big_gravel, std::string("big_gravel"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(CrowdScoopCycle, river_sand, std::string("river_sand"))
    ->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
