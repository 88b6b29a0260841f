// Simulated sensor frames on the benchmark yard (60 m × 60 m at 0.05 m: 1200 × 1200 cells, three
// piles, a bin wall, a loader, a person), seen from the XCMG 968EV standing at the origin.
//   build/sensors_bench --benchmark_min_time=0.5
#include <benchmark/benchmark.h>

#include "runtime/sensors/camera.h"
#include "runtime/sensors/lidar.h"
#include "runtime/sensors/sensor_pose.h"
#include "tests/sensors/sensor_test_support.h"

namespace {

using namespace autoshovel;
using sensors::testing::FindLidar;
using sensors::testing::Xcmg;

struct Setup {
  plant::World world = sensors::testing::Yard();
  sensors::RaycastScene scene{world};
  plant::MachineState state;
};

Setup& Shared() {
  static Setup s;
  return s;
}

void BM_ForwardLidarFrame(benchmark::State& st) {
  Setup& s = Shared();
  const model::Lidar& lidar = FindLidar(Xcmg(), "front_solid_state");
  const Eigen::Isometry3d T = sensors::SensorInWorld(s.state, lidar.pose);
  sensors::Rng rng(1);
  double stamp = 0;
  std::size_t points = 0;
  for (auto _ : st) {
    const auto cloud = sensors::SimulateLidarFrame(lidar, s.scene, T, stamp, rng);
    points += cloud.points.size();
    stamp += 0.1;
    benchmark::DoNotOptimize(cloud.points.data());
  }
  st.counters["rays"] = static_cast<double>(lidar.points_per_second / lidar.rate);
  st.counters["returns"] = static_cast<double>(points) / st.iterations();
}
BENCHMARK(BM_ForwardLidarFrame)->Unit(benchmark::kMillisecond);

void BM_SpinningLidarFrame(benchmark::State& st) {
  Setup& s = Shared();
  const model::Lidar& lidar = FindLidar(Xcmg(), "top_16");
  const Eigen::Isometry3d T = sensors::SensorInWorld(s.state, lidar.pose);
  sensors::Rng rng(2);
  std::size_t points = 0;
  for (auto _ : st) {
    const auto cloud = sensors::SimulateLidarFrame(lidar, s.scene, T, 0.0, rng);
    points += cloud.points.size();
    benchmark::DoNotOptimize(cloud.points.data());
  }
  st.counters["rays"] = 1875 * 16;
  st.counters["returns"] = static_cast<double>(points) / st.iterations();
}
BENCHMARK(BM_SpinningLidarFrame)->Unit(benchmark::kMillisecond);

void BM_CameraFrame(benchmark::State& st) {
  Setup& s = Shared();
  const model::Camera& cam = Xcmg().sensors.camera;
  const Eigen::Isometry3d T = sensors::SensorInWorld(s.state, cam.pose);
  sensors::CameraOptions options;
  options.lighting = static_cast<sensors::Lighting>(st.range(0));
  sensors::Rng rng(3);
  for (auto _ : st) {
    const auto frame = sensors::SimulateCameraFrame(cam, s.scene, T, 0.0, options, rng);
    benchmark::DoNotOptimize(frame.bgr.data());
  }
  st.SetLabel(sensors::ToString(options.lighting));
}
BENCHMARK(BM_CameraFrame)
    ->Arg(static_cast<int>(sensors::Lighting::kNormal))
    ->Arg(static_cast<int>(sensors::Lighting::kDim))
    ->Unit(benchmark::kMillisecond);

// Rebuilding the whole max-height pyramid (after a change of unknown extent).
void BM_SceneFullUpdate(benchmark::State& st) {
  Setup& s = Shared();
  for (auto _ : st) s.scene.Update();
}
BENCHMARK(BM_SceneFullUpdate)->Unit(benchmark::kMillisecond);

// Refreshing a 2 m × 2 m dirty rectangle (one bucket pass).
void BM_SceneDirtyUpdate(benchmark::State& st) {
  Setup& s = Shared();
  for (auto _ : st) s.scene.UpdateTerrain(700, 580, 739, 619);
}
BENCHMARK(BM_SceneDirtyUpdate)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
