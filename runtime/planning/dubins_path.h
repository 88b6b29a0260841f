// Curvature-bounded forward paths for the articulated loader: Dubins (1957) shortest paths of
// bounded curvature, closed form after Shkel & Lumelsky (2001).
//
// Why Dubins, for the approach to a shovel point (wheel-loader seed §5, Algorithm 2 PlanPath):
// - the loader attacks the pile driving forward, bucket first; the reversing leg of a loading
//   cycle ends before the approach begins, so reverse motions (Reeds–Shepp) are not wanted here;
// - the front axle of an articulated loader moves along the front frame's heading (no lateral
//   slip) with curvature κ = sin γ / (l_f cos γ + l_r) for a held articulation γ (the plant's
//   steering kinematics, runtime/plant/plant.cc), so the articulation limit γmax bounds the
//   curvature of the front axle's path by κmax = sin γmax / (l_f cos γmax + l_r): exactly the
//   Dubins car's constraint, with the front axle as the reference point;
// - Dubins paths are shortest among paths with |κ| ≤ κmax, which is what the efficiency score
//   (Eq. 16) compares, and they are closed-form (six words), cheap enough to plan one path per
//   candidate point and entry angle at the seed's 7 Hz.
// What Dubins ignores: the articulation rate limit (curvature jumps between segments). A
// clothoid path would honour it; the entry-angle score (Eq. 17) reads the curvature over the
// final metres before the pile (shovel_point_selection.h) rather than at one instant, which is
// where the rate limit matters. Planning *among obstacles* is left to the caller, which
// evaluates all six words and keeps the shortest collision-free one.
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string_view>
#include <vector>

namespace autoshovel::planning {

/// A planar pose: position [m, world] and heading from world x, counter-clockwise [rad].
struct Pose2 {
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  double heading = 0;
};

/// The six Dubins words: L left turn at κmax, R right turn at −κmax, S straight.
enum class DubinsWord { kLSL, kLSR, kRSL, kRSR, kRLR, kLRL };

std::string_view ToString(DubinsWord word);

/// One Dubins path: three segments of the word's types, each of `lengths[i]` metres.
struct DubinsPath {
  Pose2 start;
  DubinsWord word = DubinsWord::kLSL;
  double radius = 1;                       ///< turning radius 1/κmax [m]
  std::array<double, 3> lengths{0, 0, 0};  ///< segment lengths [m]

  double length() const { return lengths[0] + lengths[1] + lengths[2]; }
  /// Signed curvature at arc length s (left positive) [1/m]; s clamped to [0, length()].
  double CurvatureAt(double s) const;
  /// Pose at arc length s along the path (s clamped to [0, length()]).
  Pose2 At(double s) const;
};

/// Every word that connects `start` to `goal` with curvature bounded by `kappa_max` [1/m],
/// shortest first (ties broken by word order). Throws std::invalid_argument unless
/// kappa_max > 0 and the poses are finite.
std::vector<DubinsPath> AllDubinsPaths(const Pose2& start, const Pose2& goal, double kappa_max);

/// The shortest of AllDubinsPaths (there is always one).
DubinsPath ShortestDubinsPath(const Pose2& start, const Pose2& goal, double kappa_max);

/// A point of a sampled path.
struct PathSample {
  double s = 0;                                  ///< arc length from the start [m]
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  ///< world [m]
  double heading = 0;                            ///< [rad]
  double curvature = 0;                          ///< signed, left positive [1/m]
};

/// Samples at fixed arc-length `spacing` [m] from the start, plus the end point (so the last
/// interval may be shorter). Throws std::invalid_argument unless spacing > 0.
std::vector<PathSample> SamplePath(const DubinsPath& path, double spacing);

}  // namespace autoshovel::planning
