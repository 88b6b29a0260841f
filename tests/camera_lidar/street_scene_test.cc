// Step 2 of Algorithm 1 on a synthetic scene with the traits of real recordings
// (street_simulation.h): a sloped, cluttered ground, no sky class, a sparse 32-line LiDAR,
// intensities by material. The score must peak at the truth along every axis, and the search
// must find it from the published protocol's 3° starts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "identification/camera_lidar/auto_calibration.h"
#include "identification/camera_lidar/rig_files.h"
#include "identification/camera_lidar/street_simulation.h"

namespace autoshovel::identification {
namespace {

Eigen::Isometry3d Truth() { return StreetSceneMount(); }

std::vector<ScoreFrame> Frames(int count) {
  std::vector<ScoreFrame> frames;
  for (int k = 0; k < count; ++k) {
    StreetSceneOptions options;
    options.seed = 11 + static_cast<unsigned long long>(k);
    const StreetFrame f = SimulateStreetFrame(Truth(), options);
    frames.push_back(PrepareScoreFrame(f.cloud, f.masks, f.intrinsics, std::nullopt));
  }
  return frames;
}

TEST(StreetScene, ScorePeaksAtTheTruthAlongEveryAxis) {
  const std::vector<ScoreFrame> frames = Frames(2);
  const std::vector<ScoreSlice> slices =
      ScoreSurface(frames, Truth(), ScoreOptions{}, 1.0, 0.06, 31);
  for (const ScoreSlice& s : slices) {
    const auto best = std::max_element(s.rho.begin(), s.rho.end()) - s.rho.begin();
    const double offset = s.offsets[static_cast<std::size_t>(best)];
    std::printf("%s: peak at %+.3f\n", s.parameter.c_str(), offset);
    if (s.parameter.rfind("rot", 0) == 0) {
      EXPECT_LE(std::abs(offset), 0.2) << s.parameter << " [deg]";
    } else {
      EXPECT_LE(std::abs(offset), 0.02) << s.parameter << " [m]";
    }
  }
}

}  // namespace
}  // namespace autoshovel::identification
