// One scanner end to end (excavator seed §2–3): a panning sweep over the ground and a truck
// beside the machine gives points on their surfaces, through a dirty window.
#include "runtime/sensors/rangefinder/scanning_rangefinder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace autoshovel::sensors {
namespace {

TEST(ScanningRangefinder, PanningSweepMeasuresTheGroundAndTheTruck) {
  const WaveformConfig waveform;
  const ScanningRangefinder scanner(LeftScannerConfig(), waveform, MakeDetectorConfig(waveform),
                                    DirtyWindow());
  // The machine stands on level ground (z = 0 in the cab frame) turned 30° in the scene; a
  // truck body 9 m to its left, 3 m high.
  Eigen::Isometry3d T_scene_cab = Eigen::Isometry3d::Identity();
  T_scene_cab.linear() = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T_scene_cab.translation() = Eigen::Vector3d(4, -2, 0);
  SimpleScene scene;
  scene.AddPlane({0, 0, 0}, {0, 0, 1}, 0.2);
  Eigen::Isometry3d T_cab_truck = Eigen::Isometry3d::Identity();
  T_cab_truck.translation() = Eigen::Vector3d(0, 9, 1.5);
  scene.AddBox(T_scene_cab * T_cab_truck, {4.5, 1.25, 1.5}, 0.35);

  // Pan at the full 120°/s from the dig face in front across the truck (§2, Fig. 4).
  const PanSweep sweep{0.0, 0.0, 120.0 * kDegree, 120.0 * kDegree};
  Rng rng(3);
  int fired = 0, ground = 0, truck = 0, other = 0;
  for (std::int64_t k = 0; scanner.geometry().PulseTime(k) < 1.0; ++k) {
    const auto pulse = scanner.Fire(k, sweep, T_scene_cab, scene, rng);
    if (!pulse) {
      EXPECT_FALSE(scanner.geometry().InActiveArc(
          scanner.geometry().ElevationAt(scanner.geometry().PulseTime(k))));
      continue;
    }
    ++fired;
    EXPECT_TRUE(pulse->detection.window_return);
    EXPECT_NEAR(*pulse->detection.first_pulse_range, 0.0, 0.3);
    if (!pulse->p_cab_trailing) continue;
    const Eigen::Vector3d p = *pulse->p_cab_trailing;
    const Eigen::Vector3d q = T_cab_truck.inverse() * p;
    if (std::abs(p.z()) < 0.05) {
      ++ground;
    } else if (std::abs(std::abs(q.y()) - 1.25) < 0.05 || std::abs(q.z() - 1.5) < 0.05 ||
               std::abs(std::abs(q.x()) - 4.5) < 0.05) {
      ++truck;
      EXPECT_LT(q.cwiseAbs().maxCoeff(), 4.55);
    } else {
      ++other;
      ADD_FAILURE() << "point off every surface: " << p.transpose();
    }
    // The last pulse finds the same surface to within its threshold jitter.
    ASSERT_TRUE(pulse->p_cab_last);
    EXPECT_LT((*pulse->p_cab_last - p).norm(), 0.15);
  }
  // One second: 20 circles of 175 fired pulses.
  EXPECT_NEAR(fired, 3500, 2);
  EXPECT_GT(ground, 1000);
  EXPECT_GT(truck, 300);
  EXPECT_EQ(other, 0);
  EXPECT_THROW(
      scanner.Fire(0, {0.0, 0.0, 90.0 * kDegree, 150.0 * kDegree}, T_scene_cab, scene, rng),
      std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::sensors
