// The simple scene the rangefinder tests look at: planes, boxes, dust spheres and boxes.
#include "runtime/sensors/rangefinder/rangefinder_scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace autoshovel::sensors {
namespace {

Eigen::Isometry3d At(const Eigen::Vector3d& p, double yaw = 0.0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = p;
  return T;
}

TEST(RangefinderScene, NearestSolidWithIncidence) {
  SimpleScene scene;
  scene.AddPlane({0, 0, 0}, {0, 0, 1}, 0.2);
  scene.AddBox(At({10, 0, 1}), {1, 1, 1}, 0.6);
  // Level ray into the box face at x = 9.
  RayProfile p = scene.Trace({0, 0, 1}, {1, 0, 0}, 80);
  ASSERT_TRUE(p.solid);
  EXPECT_NEAR(p.solid->range, 9.0, 1e-12);
  EXPECT_DOUBLE_EQ(p.solid->reflectivity, 0.6);
  EXPECT_NEAR(p.solid->cos_incidence, 1.0, 1e-12);
  // 30° down onto the ground from 2.6 m: range 5.2 m, incidence cos 60°.
  const Eigen::Vector3d d(std::cos(std::numbers::pi / 6), 0.3, -std::sin(std::numbers::pi / 6));
  p = scene.Trace({0, 0, 2.6}, d.normalized(), 80);
  ASSERT_TRUE(p.solid);
  EXPECT_NEAR(p.solid->range * d.normalized().z(), -2.6, 1e-12);
  EXPECT_NEAR(p.solid->cos_incidence, -d.normalized().z(), 1e-12);
  EXPECT_DOUBLE_EQ(p.solid->reflectivity, 0.2);
  // Beyond max_range: nothing. A ray starting inside the box does not see it.
  EXPECT_FALSE(scene.Trace({0, 0, 1}, {1, 0, 0}, 8.0).solid);
  EXPECT_FALSE(scene.Trace({10, 0, 1}, {1, 0, 0}, 80).solid);
  // A turned box: the 45° face.
  SimpleScene turned;
  turned.AddBox(At({10, 0, 0}, std::numbers::pi / 4), {1, 1, 1}, 0.5);
  p = turned.Trace({0, 0, 0}, {1, 0, 0}, 80);
  ASSERT_TRUE(p.solid);
  EXPECT_NEAR(p.solid->range, 10 - std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(p.solid->cos_incidence, std::sqrt(0.5), 1e-12);
}

TEST(RangefinderScene, DustSegmentsAreClippedAtTheSolid) {
  SimpleScene scene;
  DustProperties dust;
  dust.extinction = 0.4;
  dust.lidar_ratio = 40;
  scene.AddDustSphere({10, 0, 0}, 3.0, dust);
  scene.AddDustBox(At({20, 0, 0}), {1, 2, 2}, dust);
  RayProfile p = scene.Trace({0, 0, 0}, {1, 0, 0}, 80);
  EXPECT_FALSE(p.solid);
  ASSERT_EQ(p.dust.size(), 2u);
  EXPECT_NEAR(p.dust[0].range_begin, 7.0, 1e-12);
  EXPECT_NEAR(p.dust[0].range_end, 13.0, 1e-12);
  EXPECT_DOUBLE_EQ(p.dust[0].extinction, 0.4);
  EXPECT_DOUBLE_EQ(p.dust[0].backscatter, 0.01);
  EXPECT_NEAR(p.dust[1].range_begin, 19.0, 1e-12);
  EXPECT_NEAR(p.dust[1].range_end, 21.0, 1e-12);
  // A wall inside the sphere: the dust behind it is invisible.
  scene.AddPlane({11, 0, 0}, {-1, 0, 0}, 0.3);
  p = scene.Trace({0, 0, 0}, {1, 0, 0}, 80);
  ASSERT_TRUE(p.solid);
  ASSERT_EQ(p.dust.size(), 1u);
  EXPECT_NEAR(p.dust[0].range_end, 11.0, 1e-12);
  // From inside the sphere the dust starts at the scanner.
  p = scene.Trace({9, 0, 0}, {1, 0, 0}, 80);
  ASSERT_EQ(p.dust.size(), 1u);
  EXPECT_DOUBLE_EQ(p.dust[0].range_begin, 0.0);
}

TEST(RangefinderScene, FunctionSceneAdaptsAnyWorld) {
  const FunctionScene scene([](const Eigen::Vector3d& o, const Eigen::Vector3d& d, double) {
    RayProfile p;
    p.solid = SolidHit{-o.z() / d.z(), 0.3, 1.0};
    return p;
  });
  EXPECT_NEAR(scene.Trace({0, 0, 2}, {0, 0, -1}, 80).solid->range, 2.0, 1e-12);
  EXPECT_THROW(FunctionScene(nullptr), std::invalid_argument);
}

TEST(RangefinderScene, BadInputIsRefused) {
  SimpleScene scene;
  EXPECT_THROW(scene.AddPlane({0, 0, 0}, {0, 0, 0}, 0.2), std::invalid_argument);
  EXPECT_THROW(scene.AddPlane({0, 0, 0}, {0, 0, 1}, 1.5), std::invalid_argument);
  EXPECT_THROW(scene.AddBox(At({0, 0, 0}), {1, -1, 1}, 0.2), std::invalid_argument);
  EXPECT_THROW(scene.AddDustSphere({0, 0, std::nan("")}, 1, {}), std::invalid_argument);
  DustProperties bad;
  bad.extinction = -0.1;
  EXPECT_THROW(scene.AddDustSphere({0, 0, 0}, 1, bad), std::invalid_argument);
  RayProfile profile;
  profile.dust.push_back({5, 4, 0.1, 0.002, 0});
  EXPECT_THROW(ValidateRayProfile(profile), std::invalid_argument);
  profile.dust.clear();
  profile.solid = SolidHit{std::nan(""), 0.2, 1};
  EXPECT_THROW(ValidateRayProfile(profile), std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::sensors
