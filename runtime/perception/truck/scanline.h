// The input of truck recognition (excavator seed §2, §4.1): one scanline is what one revolution of
// a scanner's rotating mirror returns. The mirror sweeps the beam round a circle in a vertical
// plane while the scanner pans about the vertical axis, so each scanline is (nearly) the cut of
// one vertical plane through the scene, and consecutive scanlines are neighbouring planes.
//
// Frame: every point is in the "world" frame of the caller, which must be right-handed with z
// pointing up, against gravity (the excavator's base frame qualifies when the machine stands
// level). The §2 scanline processors deliver exactly this: Cartesian points from the spherical
// sensor readings and the machine's position system.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <vector>

namespace autoshovel::perception {

/// One range reading. Invalid readings (no return, dropout, rejected last pulse) keep their place
/// in the sequence so that the order along the mirror circle is preserved.
struct ScanPoint {
  Eigen::Vector3d p_world = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  bool valid = false;
};

/// The readings of one mirror revolution, in the order the mirror swept them.
struct Scanline {
  /// The beam origin (mirror centre) during this revolution; used to orient surface normals
  /// toward the viewer and to reason about what the beam could see [m].
  Eigen::Vector3d p_world_sensor = Eigen::Vector3d::Zero();
  std::vector<ScanPoint> points;
};

/// A reading takes part in the fits only when flagged valid and finite: a NaN that slipped through
/// a driver must never reach a least-squares sum.
inline bool IsUsable(const ScanPoint& point) { return point.valid && point.p_world.allFinite(); }

}  // namespace autoshovel::perception
