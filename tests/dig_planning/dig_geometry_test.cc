// Geometric constraints of the refined planner (dig_geometry.h) on the 25 t excavator, and the
// swept-volume screening estimate (swept_volume.h).
#include "runtime/planning/dig/dig_geometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "dig_test_support.h"
#include "runtime/planning/dig/swept_volume.h"

namespace autoshovel::planning {
namespace {

using testing::Excavator25t;
using testing::kDeg;
using testing::kNaN;

DigAction Action(double swing, double radius, double entry, double depth, double drag) {
  DigAction a;
  a.swing = swing;
  a.radius = radius;
  a.entry_height = entry;
  a.depth = depth;
  a.drag_length = drag;
  return a;
}

TEST(DigGeometry, NominalPathGoesDownBackAndUp) {
  const DigAction a = Action(30 * kDeg, 7.0, 1.2, 0.5, 2.0);
  const std::vector<Eigen::Vector3d> path = NominalTipPath(a, 0.5);
  ASSERT_EQ(path.size(), 4u);
  const Eigen::Vector3d u(std::cos(a.swing), std::sin(a.swing), 0.0);
  EXPECT_TRUE(path[0].isApprox(7.0 * u + Eigen::Vector3d(0, 0, 1.2)));
  EXPECT_TRUE(path[1].isApprox(7.0 * u + Eigen::Vector3d(0, 0, 0.7)));
  EXPECT_TRUE(path[2].isApprox(5.0 * u + Eigen::Vector3d(0, 0, 0.7)));
  EXPECT_TRUE(path[3].isApprox(5.0 * u + Eigen::Vector3d(0, 0, 1.7)));
}

TEST(DigGeometry, ReachabilityFollowsTheArmsWorkspace) {
  const DigGeometryConfig config;
  const DigReachability reach(*Excavator25t().kinematics, config);
  std::string why;
  EXPECT_TRUE(reach.Reachable(Action(0.2, 7.0, 0.5, 0.5, 2.0), why)) << why;
  EXPECT_TRUE(reach.Reachable(Action(-0.4, 8.5, 2.0, 0.6, 1.5), why)) << why;
  // Beyond the ~9.5 m reach at ground level.
  EXPECT_FALSE(reach.Reachable(Action(0.0, 10.5, 0.0, 0.3, 1.0), why));
  EXPECT_NE(why.find("unreachable entry"), std::string::npos) << why;
  // Entry fine, but the drag would pull the tip behind the swing axis.
  EXPECT_FALSE(reach.Reachable(Action(0.0, 5.0, 0.0, 0.3, 5.5), why));
  EXPECT_NE(why.find("drag end"), std::string::npos) << why;
  EXPECT_FALSE(reach.Reachable(Action(kNaN, 7.0, 0.0, 0.3, 1.0), why));

  // Solve puts the tip where asked, at an attitude within the range, joints within limits.
  const control::ExcavatorKinematics& k = *Excavator25t().kinematics;
  const Eigen::Vector3d p_base_tip = TipInBase(0.3, 6.5, -0.5);
  const auto q = reach.Solve(p_base_tip, config.entry_attitude_min, config.entry_attitude_max);
  ASSERT_TRUE(q.has_value());
  EXPECT_LT((k.TipPosition(*q) - p_base_tip).norm(), 1e-9);
  const double attitude = k.Pins(*q).link_angles[2];
  EXPECT_GE(attitude, config.entry_attitude_min - 1e-9);
  EXPECT_LE(attitude, config.entry_attitude_max + 1e-9);
  for (int j = 0; j < 4; ++j) {
    EXPECT_GE((*q)[j], k.joint_min()[j] - 1e-12);
    EXPECT_LE((*q)[j], k.joint_max()[j] + 1e-12);
  }
  // The middle of the range is tried first: it is reachable here, so it is the one returned.
  EXPECT_NEAR(attitude, 0.5 * (config.entry_attitude_min + config.entry_attitude_max), 1e-9);
}

TEST(DigGeometry, PathCollisionChecksBetweenSparsePoints) {
  DigGeometryConfig config;
  config.undercarriage_radius = 3.0;
  config.keep_out_margin = 0.2;
  control::ObstacleBox box;
  box.center = Eigen::Vector2d(6.0, 0.0);
  box.half_extents = Eigen::Vector2d(0.2, 0.2);
  box.z_min = 0.0;
  box.z_max = 2.0;
  std::string why;
  // Two points 4 m apart on either side of a 0.4 m box: only the segment meets it.
  EXPECT_TRUE(PathCollides({{8.0, 0.0, 1.0}, {4.0, 0.0, 1.0}}, {box}, config, why));
  EXPECT_NE(why.find("keep-out box 0"), std::string::npos) << why;
  // Beside it by more than the margin: clear.
  EXPECT_FALSE(PathCollides({{8.0, 0.5, 1.0}, {4.0, 0.5, 1.0}}, {box}, config, why));
  // Within the margin: not clear.
  EXPECT_TRUE(PathCollides({{8.0, 0.35, 1.0}, {4.0, 0.35, 1.0}}, {box}, config, why));
  // Into the undercarriage radius, even without boxes.
  EXPECT_TRUE(PathCollides({{5.0, 0.0, 0.0}, {2.5, 0.5, 0.0}}, {}, config, why));
  EXPECT_NE(why.find("undercarriage"), std::string::npos) << why;
  EXPECT_FALSE(PathCollides({}, {box}, config, why));
}

TEST(DigGeometry, UndercarriageRadiusFromTheTracks) {
  const model::MachineDescription& machine = Excavator25t().machine;
  EXPECT_NEAR(UndercarriageRadius(machine, 0.0), 0.5 * std::hypot(4.45, 2.59 + 0.60), 1e-12);
  EXPECT_NEAR(UndercarriageRadius(machine), 0.5 * std::hypot(4.45, 3.19) + 0.25, 1e-12);
  model::MachineDescription no_tracks;
  no_tracks.name = "no_tracks";
  EXPECT_THROW(UndercarriageRadius(no_tracks), std::invalid_argument);
  EXPECT_THROW(UndercarriageRadius(machine, -1.0), std::invalid_argument);
}

TEST(DigGeometry, InvalidConfigNamesTheField) {
  DigGeometryConfig config;
  config.drag_end_attitude_min = kNaN;
  try {
    Validate(config, "geometry");
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("geometry.drag_end_attitude_min"), std::string::npos);
  }
  config = {};
  config.lift_clearance = -0.1;
  EXPECT_THROW(Validate(config, "geometry"), std::invalid_argument);
  config = {};
  config.keep_out_margin = kNaN;
  EXPECT_THROW(DigReachability(*Excavator25t().kinematics, config), std::invalid_argument);
}

TEST(SweptVolume, FlatSlabAndUnknownCells) {
  control::HeightGrid map(Eigen::Vector2d(0.0, -5.0), 0.1, 120, 100, 1.0);
  // Bucket 1.3 m wide, cut 0.4 m deep, 2 m drag, all in a 1 m slab: 1.3 × 0.4 × 2.
  const DigAction a = Action(0.0, 8.0, 1.0, 0.4, 2.0);
  EXPECT_NEAR(SweptVolumeEstimate(map, a, 1.3, 0.1), 1.04, 1e-12);
  // Unknown cells along the second half of the drag count as empty.
  for (int iy = 0; iy < map.ny(); ++iy) {
    for (int ix = 60; ix < 70; ++ix) map.set_height(ix, iy, kNaN);
  }
  EXPECT_NEAR(SweptVolumeEstimate(map, a, 1.3, 0.1), 0.52, 1e-12);
  // A cut above the surface takes nothing.
  EXPECT_EQ(SweptVolumeEstimate(map, Action(0.0, 8.0, 1.5, 0.2, 2.0), 1.3, 0.1), 0.0);
}

}  // namespace
}  // namespace autoshovel::planning
