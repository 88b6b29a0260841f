// The closed loop's map-update stages on a real scenario yard: mixing_station (60 m × 60 m at
// 0.05 m, eight walled bins, parked loaders), the XCMG 968EV at the scenario's start pose with
// its own bodies in the scene, as `autoshovel run` sees it at its first map update. The
// synthetic yard of sensors_bench has few boxes and no machine in view; this one has what the
// closed loop's profile (`run --profile`, docs/performance.md) is made of.
//   build/sensor_stages_bench --benchmark_min_time=1
#include <benchmark/benchmark.h>

#include <string>

#include "runtime/perception/elevation_map.h"
#include "runtime/perception/lens_dirt_monitor.h"
#include "runtime/perception/semantic_map.h"
#include "runtime/perception/sensor_fusion.h"
#include "runtime/plant/plant.h"
#include "runtime/plant/poses.h"
#include "runtime/sensors/camera.h"
#include "runtime/sensors/lidar.h"
#include "runtime/sensors/raycast.h"
#include "runtime/sensors/sensor_pose.h"
#include "runtime/sim/perceive_from_plant.h"

namespace {

using namespace autoshovel;

struct Yard {
  plant::ScenarioWithMachine setup = plant::LoadScenarioWithMachine(
      "mixing_station", std::string(AUTOSHOVEL_SOURCE_DIR) + "/models");
  plant::Plant plant{setup.machine, *setup.functions, setup.scenario.world,
                     plant::StartState(setup.scenario, setup.machine)};
  sensors::RaycastScene scene{setup.scenario.world, plant.OwnBodies()};
};

Yard& Shared() {
  static Yard yard;
  return yard;
}

void BM_YardCameraFrame(benchmark::State& st) {
  Yard& y = Shared();
  const model::Camera& camera = y.setup.machine.sensors.camera;
  const Eigen::Isometry3d T_world_camera = sensors::SensorInWorld(y.plant.state(), camera.pose);
  sensors::CameraOptions options;
  options.lighting = static_cast<sensors::Lighting>(st.range(0));
  sensors::Rng rng(3);
  for (auto _ : st) {
    const auto frame =
        sensors::SimulateCameraFrame(camera, y.scene, T_world_camera, 0.0, options, rng);
    benchmark::DoNotOptimize(frame.bgr.data());
  }
  st.SetLabel(sensors::ToString(options.lighting));
  st.counters["pixels"] = camera.width_px * camera.height_px;
}
BENCHMARK(BM_YardCameraFrame)
    ->Arg(static_cast<int>(sensors::Lighting::kNormal))
    ->Arg(static_cast<int>(sensors::Lighting::kDim))
    ->Unit(benchmark::kMillisecond);

void BM_YardLidarFrame(benchmark::State& st) {
  Yard& y = Shared();
  const model::Lidar& lidar = y.setup.machine.sensors.lidars.at(st.range(0));
  const Eigen::Isometry3d T_world_lidar = sensors::SensorInWorld(y.plant.state(), lidar.pose);
  sensors::Rng rng(4);
  double stamp = 0;
  std::size_t returns = 0;
  for (auto _ : st) {
    const auto cloud = sensors::SimulateLidarFrame(lidar, y.scene, T_world_lidar, stamp, rng);
    returns += cloud.points.size();
    stamp += 0.1;
    benchmark::DoNotOptimize(cloud.points.data());
  }
  st.SetLabel(lidar.name);
  st.counters["returns"] = static_cast<double>(returns) / st.iterations();
}
BENCHMARK(BM_YardLidarFrame)->DenseRange(0, 1)->Unit(benchmark::kMillisecond);

// One later map update as the closed loop makes it (one frame per LiDAR and the camera), into a
// map that already holds the first update's five frames per LiDAR: simulation, then fusion.
void BM_YardMapUpdate(benchmark::State& st) {
  Yard& y = Shared();
  const bool simulate = st.range(0) == 0;
  sim::PerceptionFromPlantOptions options;
  options.truth_labels = true;
  sensors::Rng rng(5);
  perception::ElevationMap map({}, y.plant.state().hinge_xy);
  perception::SemanticMap semantic(map);
  sim::PerceiveFromPlant(y.plant, y.scene, rng, options, map, semantic);
  options.lidar_frames = 1;
  const perception::SensorFrames frames = sim::SimulateSensorFrames(y.plant, y.scene, rng, options);
  perception::LensDirtMonitor lens_dirt;  // on in every closed-loop update
  perception::FusionOptions fusion;
  fusion.truth_labels = true;
  fusion.lens_dirt = &lens_dirt;
  for (auto _ : st) {
    if (simulate) {
      const auto simulated = sim::SimulateSensorFrames(y.plant, y.scene, rng, options);
      benchmark::DoNotOptimize(simulated.lidar.data());
    } else {
      const auto stats =
          perception::FuseSensorFrames(y.setup.machine, frames, fusion, map, semantic);
      benchmark::DoNotOptimize(stats.returns_fused);
    }
  }
  st.SetLabel(simulate ? "sensor simulation" : "fusion (simulator labels)");
}
BENCHMARK(BM_YardMapUpdate)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
