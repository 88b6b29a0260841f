// Perception benchmarks: `build/perception_bench`. Map-update throughput is the counter
// `points_per_s` (issue goal ≥ 10 M points/s on one core for a 24k-point frame, 60 m × 60 m map).
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "generated/registry.h"
#include "runtime/model/description.h"
#include "runtime/perception/elevation_map.h"
#include "runtime/perception/pile_extraction.h"
#include "runtime/perception/scan/scan_map.h"
#include "runtime/perception/semantic_map.h"
#include "runtime/plant/plant.h"
#include "runtime/plant/poses.h"
#include "runtime/plant/scenario.h"
#include "runtime/sensors/camera.h"
#include "runtime/sensors/lidar.h"
#include "runtime/sensors/raycast.h"
#include "runtime/sensors/sensor_pose.h"

namespace {

using namespace autoshovel;

struct Frames {
  std::vector<sensors::PointCloud> clouds;
  std::vector<Eigen::Isometry3d> poses;
  Eigen::Vector2d center;
  perception::ClassProbabilities semantics;
  model::Camera camera;
  Eigen::Isometry3d T_world_camera;
  Frames() {
    const std::string models = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";
    plant::Scenario scenario =
        plant::LoadScenario(plant::ResolveScenario("mixing_station", models));
    const model::MachineDescription machine =
        model::LoadMachineDescription(model::ResolveMachineDescription(scenario.machine, models));
    plant::MachineState state;
    state.hinge_xy = Eigen::Vector2d(scenario.start.x, scenario.start.y);
    state.heading = scenario.start.heading;
    state.q = plant::BucketOnFloor(machine);
    plant::Plant plant(machine, *generated::FindMachine(machine.name), scenario.world, state);
    sensors::RaycastScene scene(scenario.world, plant.OwnBodies());
    sensors::Rng rng(1);
    const model::Lidar& lidar = machine.sensors.lidars.at(1);
    for (int k = 0; k < 10; ++k) {
      poses.push_back(sensors::SensorInWorld(plant.state(), lidar.pose));
      clouds.push_back(sensors::SimulateLidarFrame(lidar, scene, poses.back(), 0.1 * k, rng));
    }
    center = state.hinge_xy;
    camera = machine.sensors.camera;
    T_world_camera = sensors::SensorInWorld(plant.state(), camera.pose);
    const sensors::CameraFrame image = sensors::SimulateCameraFrame(
        camera, scene, T_world_camera, 0.0, sensors::CameraOptions{}, rng);
    semantics = perception::FromLabels(image.labels, image.width, image.height);
  }
};

const Frames& SharedFrames() {
  static const Frames frames;
  return frames;
}

void MapUpdate(benchmark::State& state, int clearing_stride) {
  const Frames& frames = SharedFrames();
  perception::ElevationMapConfig config;
  config.clearing_stride = clearing_stride;
  perception::ElevationMap map(config, frames.center);
  long points = 0;
  std::size_t k = 0;
  for (auto _ : state) {
    const sensors::PointCloud& cloud = frames.clouds[k % frames.clouds.size()];
    const auto stats = map.Update(cloud, frames.poses[k % frames.poses.size()], cloud.stamp);
    benchmark::DoNotOptimize(stats);
    points += static_cast<long>(cloud.points.size());
    ++k;
  }
  state.counters["points_per_s"] =
      benchmark::Counter(static_cast<double>(points), benchmark::Counter::kIsRate);
  state.counters["points"] = static_cast<double>(frames.clouds.front().points.size());
}

void FillHoles(benchmark::State& state) {
  const Frames& frames = SharedFrames();
  perception::ElevationMap map({}, frames.center);
  for (std::size_t k = 0; k < frames.clouds.size(); ++k) {
    map.Update(frames.clouds[k], frames.poses[k], frames.clouds[k].stamp);
  }
  for (auto _ : state) benchmark::DoNotOptimize(map.FillHoles());
}

// One 7 Hz semantic-map cycle without the network: fuse a LiDAR frame, project the class
// probabilities of one camera frame, fit the ground and fuse (Eq. 10–11), extract the piles.
void SemanticMapCycle(benchmark::State& state) {
  const Frames& frames = SharedFrames();
  perception::ElevationMap map({}, frames.center);
  perception::SemanticMap semantic(map);
  for (std::size_t k = 0; k < frames.clouds.size(); ++k) {
    map.Update(frames.clouds[k], frames.poses[k], frames.clouds[k].stamp);
  }
  std::size_t k = 0;
  std::size_t piles = 0;
  for (auto _ : state) {
    const sensors::PointCloud& cloud = frames.clouds[k % frames.clouds.size()];
    map.Update(cloud, frames.poses[k % frames.poses.size()], cloud.stamp);
    semantic.Project(frames.semantics, frames.camera, frames.T_world_camera);
    semantic.Fuse();
    piles = perception::ExtractPiles(map.map(), semantic.ground_plane()).size();
    ++k;
  }
  state.counters["piles"] = static_cast<double>(piles);
}

// A user's scan into the map (issue 43, scan_map.h): a 360 000-point scan of a floor with a
// heap of spheres on it, seen from 2.5 m, in the scanner's frame (z along the range axis).
sensors::PointCloud SyntheticScan(std::size_t points) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.002);
  sensors::PointCloud cloud;
  while (cloud.points.size() < points) {
    // A point of the floor z = 0 (world), raised by a bumpy heap within 1 m of the origin.
    const double x = 2.0 * u(rng), y = 2.0 * u(rng);
    const double r = std::hypot(x, y);
    const double z = r < 1.0 ? 0.5 * (1 - r) + 0.03 * std::sin(40 * x) * std::cos(40 * y) : 0.0;
    // Scanner 2.5 m above the origin looking down: its z axis is −z of the world.
    sensors::LidarPoint p;
    p.p_sensor = Eigen::Vector3f(static_cast<float>(x), static_cast<float>(-y),
                                 static_cast<float>(2.5 - z + noise(rng)));
    cloud.points.push_back(p);
  }
  return cloud;
}

void ScanToMap(benchmark::State& state) {
  perception::ScanCloud scan;
  scan.cloud = SyntheticScan(360000);
  double volume = 0, floor = 0, map = 0;
  for (auto _ : state) {
    const perception::ScanMap result = perception::BuildScanMap({scan});
    volume = result.heaps.empty() ? 0.0 : result.heaps.front().volume;
    floor = result.seconds_floor;
    map = result.seconds_map;
  }
  state.counters["points_per_s"] = benchmark::Counter(
      360000.0 * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["heap_m3"] = volume;
  state.counters["floor_s"] = floor;
  state.counters["map_s"] = map;
}

}  // namespace

BENCHMARK(ScanToMap)->Unit(benchmark::kMillisecond);
BENCHMARK(SemanticMapCycle)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(MapUpdate, clearing_every_4th_ray, 4)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(MapUpdate, clearing_every_ray, 1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(MapUpdate, no_clearing, 0)->Unit(benchmark::kMillisecond);
BENCHMARK(FillHoles)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
