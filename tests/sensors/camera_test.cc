// Camera: pinhole projection and the body/optical convention, ground-truth labels, shading
// (Lambert, shadows, lighting conditions), determinism.
#include "runtime/sensors/camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "runtime/sensors/sensor_pose.h"
#include "tests/sensors/sensor_test_support.h"

namespace autoshovel::sensors {
namespace {

using core::SemanticClass;
using testing::FlatWorld;
using testing::MakeBox;
using testing::Xcmg;

constexpr double kDeg = std::numbers::pi / 180;

Eigen::Isometry3d LevelCameraAt(const Eigen::Vector3d& xyz) {
  model::Pose3 pose;
  pose.xyz = xyz;
  return PoseToIsometry(pose);
}

// Pixel (column, row) that sees world point p.
Eigen::Vector2i PixelOf(const model::Camera& cam, const Eigen::Isometry3d& T_world_body,
                        const Eigen::Vector3d& p) {
  Eigen::Vector2d uv;
  EXPECT_TRUE(ProjectToPixel(cam, OpticalInWorld(T_world_body).inverse() * p, uv));
  return {static_cast<int>(std::lround(uv.x())), static_cast<int>(std::lround(uv.y()))};
}

SemanticClass LabelAt(const CameraFrame& f, const Eigen::Vector2i& px) {
  return static_cast<SemanticClass>(f.labels[px.y() * f.width + px.x()]);
}

// Mean of the three channels over a (2r+1)² window.
double Brightness(const CameraFrame& f, const Eigen::Vector2i& px, int r = 2) {
  double sum = 0;
  int n = 0;
  for (int v = px.y() - r; v <= px.y() + r; ++v) {
    for (int u = px.x() - r; u <= px.x() + r; ++u) {
      for (int c = 0; c < 3; ++c) sum += f.bgr[3 * (v * f.width + u) + c];
      n += 3;
    }
  }
  return sum / n;
}

double MeanBrightness(const CameraFrame& f) {
  double sum = 0;
  for (const auto b : f.bgr) sum += b;
  return sum / f.bgr.size();
}

TEST(Camera, OpticalAxesAndIntrinsics) {
  const Eigen::Matrix3d R = BodyFromOptical();
  EXPECT_TRUE(R.col(2).isApprox(Eigen::Vector3d::UnitX()));   // optical z: forward
  EXPECT_TRUE(R.col(0).isApprox(-Eigen::Vector3d::UnitY()));  // optical x: right
  EXPECT_TRUE(R.col(1).isApprox(-Eigen::Vector3d::UnitZ()));  // optical y: down
  EXPECT_NEAR(R.determinant(), 1.0, 1e-15);
  // A point 10.4 m ahead, 2.08 m left and 2.1 m below a level camera:
  // u = 240 + 260·(−2.08/10.4) = 188, v = 191.5 + 260·(2.1/10.4) = 244.
  const model::Camera& cam = Xcmg().sensors.camera;
  ASSERT_EQ(cam.width_px, 480);
  ASSERT_EQ(cam.height_px, 383);
  const Eigen::Isometry3d T = LevelCameraAt({0, 0, 3});
  Eigen::Vector2d uv;
  ASSERT_TRUE(
      ProjectToPixel(cam, OpticalInWorld(T).inverse() * Eigen::Vector3d(10.4, 2.08, 0.9), uv));
  EXPECT_NEAR(uv.x(), 188.0, 1e-9);
  EXPECT_NEAR(uv.y(), 244.0, 1e-9);
  // PixelRay inverts the projection.
  const Eigen::Vector3d ray = PixelRay(cam, uv.x(), uv.y());
  EXPECT_TRUE(ray.isApprox(Eigen::Vector3d(-2.08, 2.1, 10.4).normalized(), 1e-12));
  EXPECT_FALSE(ProjectToPixel(cam, Eigen::Vector3d(0, 0, -1), uv));
}

TEST(Camera, RenderedPixelSeesTheProjectedPoint) {
  // A 10 cm person-class box around the point of the previous test (a pixel spans 4 cm there)
  // is what pixel (188, 244) sees.
  plant::World world = FlatWorld(60, 60, 0.05);
  world.obstacles.push_back(
      MakeBox("marker", {10.4, 2.08, 0.9}, {0.05, 0.05, 0.05}, 0, SemanticClass::kPerson));
  const RaycastScene scene(world);
  const model::Camera& cam = Xcmg().sensors.camera;
  Rng rng(1);
  const auto f = SimulateCameraFrame(cam, scene, LevelCameraAt({0, 0, 3}), 0.0, {}, rng);
  ASSERT_EQ(f.labels.size(), 480u * 383u);
  ASSERT_EQ(f.bgr.size(), 3u * 480u * 383u);
  EXPECT_EQ(LabelAt(f, {188, 244}), SemanticClass::kPerson);
  EXPECT_EQ(LabelAt(f, {188, 250}), SemanticClass::kGround);
  EXPECT_EQ(LabelAt(f, {195, 244}), SemanticClass::kGround);
}

TEST(Camera, MountedCameraLooksDownFifteenDegrees) {
  // The XCMG camera (3.6 m up, rpy pitch +15°: down) on a machine at (5, −3) heading 30°: its
  // optical axis meets the floor 3.6/tan 15° = 13.4 m ahead, and that point projects onto the
  // principal point. Below the horizon the image sees ground; at the top, sky.
  const model::Camera& cam = Xcmg().sensors.camera;
  plant::MachineState state;
  state.hinge_xy = Eigen::Vector2d(5, -3);
  state.heading = 30 * kDeg;
  const Eigen::Isometry3d T = SensorInWorld(state, cam.pose);
  const double d = cam.pose.xyz.z() / std::tan(15 * kDeg);
  const Eigen::Vector3d ground = state.T_world_cab() * Eigen::Vector3d(cam.pose.xyz.x() + d, 0, 0);
  Eigen::Vector2d uv;
  ASSERT_TRUE(ProjectToPixel(cam, OpticalInWorld(T).inverse() * ground, uv));
  EXPECT_NEAR(uv.x(), cam.cx, 1e-9);
  EXPECT_NEAR(uv.y(), cam.cy, 1e-9);

  plant::World world = FlatWorld(60, 60, 0.05);
  const RaycastScene scene(world);
  Rng rng(2);
  const auto f = SimulateCameraFrame(cam, scene, T, 0.0, {}, rng);
  EXPECT_EQ(LabelAt(f, {240, 192}), SemanticClass::kGround);
  EXPECT_EQ(LabelAt(f, {10, 380}), SemanticClass::kGround);
  EXPECT_EQ(LabelAt(f, {240, 2}), SemanticClass::kOther);  // sky above the horizon (row 122)
  // Sky is brighter and bluer than the dusty floor.
  const Eigen::Vector2i sky(240, 5), floor(240, 300);
  EXPECT_GT(Brightness(f, sky), Brightness(f, floor));
  EXPECT_GT(f.bgr[3 * (5 * 480 + 240)], f.bgr[3 * (5 * 480 + 240) + 2]);  // blue > red
}

TEST(Camera, PersonPileAndOwnLoaderLabels) {
  plant::World world = FlatWorld(60, 60, 0.05);
  testing::AddCone(world.terrain, {14, 4}, 3, 4, 0);
  world.obstacles.push_back(
      MakeBox("worker", {6, -1.5, 0.9}, {0.25, 0.3, 0.9}, 0.4, SemanticClass::kPerson));
  // The own bucket, in front of and below the camera.
  const RaycastScene scene(
      world, {MakeBox("bucket", {3.2, 0, 0.6}, {0.6, 1.4, 0.5}, 0, SemanticClass::kOwnLoader)});
  const model::Camera& cam = Xcmg().sensors.camera;
  const Eigen::Isometry3d T = PoseToIsometry(cam.pose);
  Rng rng(3);
  const auto f = SimulateCameraFrame(cam, scene, T, 0.0, {}, rng);
  EXPECT_EQ(LabelAt(f, PixelOf(cam, T, {6, -1.5, 1.0})), SemanticClass::kPerson);
  EXPECT_EQ(LabelAt(f, PixelOf(cam, T, {14, 4, 2.9})), SemanticClass::kPile);
  EXPECT_EQ(LabelAt(f, PixelOf(cam, T, {3.2, 0.5, 1.1})), SemanticClass::kOwnLoader);
  EXPECT_EQ(LabelAt(f, PixelOf(cam, T, {10, -6, 0})), SemanticClass::kGround);
}

TEST(Camera, CastShadowIsDarkerThanLitGround) {
  // Sun due east at 45°; a 4 m wall at x = 12 throws its shadow 4 m towards the camera.
  plant::World world = FlatWorld(60, 60, 0.05);
  world.obstacles.push_back(MakeBox("wall", {12, 0, 2}, {0.5, 5, 2}, 0, SemanticClass::kWall));
  const RaycastScene scene(world);
  const model::Camera& cam = Xcmg().sensors.camera;
  const Eigen::Isometry3d T = PoseToIsometry(cam.pose);
  CameraOptions options;
  options.sun_direction = Eigen::Vector3d(1, 0, 1);
  Rng rng(4);
  const auto f = SimulateCameraFrame(cam, scene, T, 0.0, options, rng);
  const Eigen::Vector2i shadow = PixelOf(cam, T, {9.5, 0.5, 0}), lit = PixelOf(cam, T, {6, 0.5, 0});
  ASSERT_EQ(LabelAt(f, shadow), SemanticClass::kGround);
  ASSERT_EQ(LabelAt(f, lit), SemanticClass::kGround);
  // Linear radiance ratio ambient / (ambient + direct cos 45°) = 0.36 → 0.63 after gamma 1/2.2
  // (the ±6 % floor texture and the noise aside).
  const double ratio = Brightness(f, shadow) / Brightness(f, lit);
  EXPECT_NEAR(ratio, std::pow(0.30 / (0.30 + 0.75 * std::sqrt(0.5)), 1 / 2.2), 0.05);
  // Without shadow rays the two are lit alike.
  options.shadows = false;
  Rng rng2(4);
  const auto g = SimulateCameraFrame(cam, scene, T, 0.0, options, rng2);
  EXPECT_NEAR(Brightness(g, shadow) / Brightness(g, lit), 1.0, 0.08);
}

TEST(Camera, LightingConditionsOrderBrightness) {
  const plant::World world = testing::Yard();
  const RaycastScene scene(world);
  const model::Camera& cam = Xcmg().sensors.camera;
  plant::MachineState state;
  state.hinge_xy = Eigen::Vector2d(0, 0);
  const Eigen::Isometry3d T = SensorInWorld(state, cam.pose);
  double mean[3];
  for (Lighting l : {Lighting::kDim, Lighting::kNormal, Lighting::kBright}) {
    CameraOptions options;
    options.lighting = l;
    Rng rng(5);
    mean[static_cast<int>(l)] = MeanBrightness(SimulateCameraFrame(cam, scene, T, 0, options, rng));
  }
  const double dim = mean[static_cast<int>(Lighting::kDim)];
  const double normal = mean[static_cast<int>(Lighting::kNormal)];
  const double bright = mean[static_cast<int>(Lighting::kBright)];
  EXPECT_LT(dim, normal);
  EXPECT_LT(normal, bright);
  EXPECT_LT(dim, 0.6 * normal);
  EXPECT_GT(bright, 1.2 * normal);
}

TEST(Camera, LightingNames) {
  for (Lighting l : {Lighting::kNormal, Lighting::kBright, Lighting::kDim}) {
    EXPECT_EQ(ParseLighting(ToString(l)), l);
  }
  EXPECT_STREQ(ToString(Lighting::kDim), "dim");
  EXPECT_FALSE(ParseLighting("dark").has_value());
}

TEST(Camera, SameSeedIsByteIdenticalAndAnotherSeedDiffers) {
  const plant::World world = testing::Yard();
  const RaycastScene scene(world);
  const model::Camera& cam = Xcmg().sensors.camera;
  const Eigen::Isometry3d T = PoseToIsometry(cam.pose);
  CameraOptions options;
  options.lighting = Lighting::kDim;
  Rng a(8), b(8), c(9);
  const auto fa = SimulateCameraFrame(cam, scene, T, 0.5, options, a);
  const auto fb = SimulateCameraFrame(cam, scene, T, 0.5, options, b);
  const auto fc = SimulateCameraFrame(cam, scene, T, 0.5, options, c);
  EXPECT_TRUE(fa.bgr == fb.bgr);
  EXPECT_TRUE(fa.labels == fb.labels);
  EXPECT_FALSE(fa.bgr == fc.bgr);
  EXPECT_TRUE(fa.labels == fc.labels);  // labels are ground truth, noise-free
}

// The camera tests each box only over the pixels its projection covers. Every pixel must still see
// what RaycastScene::Cast of its ray finds: boxes in front, one the camera sits in (never seen
// from inside), one reaching behind the camera (clipped at its centre's plane), one wholly
// behind, and two twins at the same place (a later box wins a tie, as in Cast).
TEST(Camera, EveryPixelSeesWhatItsRayCastFinds) {
  plant::World world = testing::Yard();
  const model::Camera& cam = Xcmg().sensors.camera;
  const Eigen::Isometry3d T_world_body = LevelCameraAt({0, 0, 3.0});
  const Eigen::Vector3d c = T_world_body.translation();
  std::vector<plant::OrientedBox> own = {
      MakeBox("cab", c + Eigen::Vector3d(-0.3, 0, 0), {0.8, 0.7, 0.6}, 0.0,
              SemanticClass::kOwnLoader),
      MakeBox("hood_below", c + Eigen::Vector3d(-0.5, 0.2, -1.1), {2.5, 1.0, 0.35}, 0.1,
              SemanticClass::kOwnLoader),
      MakeBox("counterweight_behind", c + Eigen::Vector3d(-4.0, 0, -1.5), {0.8, 1.2, 0.8}, 0.0,
              SemanticClass::kOwnLoader),
      MakeBox("bucket", c + Eigen::Vector3d(4.0, 0, -2.4), {0.6, 1.4, 0.5}, 0.1,
              SemanticClass::kOwnLoader),
      MakeBox("bucket_twin", c + Eigen::Vector3d(4.0, 0, -2.4), {0.6, 1.4, 0.5}, 0.1,
              SemanticClass::kPerson)};
  const RaycastScene scene(world, own);
  CameraOptions options;
  options.lighting = Lighting::kDim;
  Rng rng(4);
  const CameraFrame frame = SimulateCameraFrame(cam, scene, T_world_body, 0, options, rng);
  const Eigen::Isometry3d T_world_optical = OpticalInWorld(T_world_body);
  int mismatches = 0, below = 0, twin = 0;
  for (int v = 0; v < frame.height; ++v) {
    for (int u = 0; u < frame.width; ++u) {
      const Eigen::Vector3d d = T_world_optical.linear() * PixelRay(cam, u, v);
      const RayHit hit = scene.Cast(T_world_optical.translation(), d, options.max_range);
      const auto expected = hit.hit ? hit.semantic_class : SemanticClass::kOther;
      mismatches += LabelAt(frame, {u, v}) != expected;
      below += hit.box == 1;
      twin += hit.box == 4;
    }
  }
  EXPECT_EQ(mismatches, 0);
  // The boxes that matter are in view: the one reaching behind the camera and the twins.
  EXPECT_GT(below, 100);
  EXPECT_GT(twin, 100);
}

// The gamma table against std::pow: within 0.02 DN everywhere, and exact at both ends.
TEST(Camera, GammaTableFollowsThePowerLaw) {
  double worst = 0;
  for (int k = 0; k <= 2000000; ++k) {
    const double x = k / 2000000.0;
    worst = std::max(worst, std::abs(GammaEncode(x) - 255.0 * std::pow(x, 1.0 / 2.2)));
  }
  EXPECT_LT(worst, 0.02);
  EXPECT_DOUBLE_EQ(GammaEncode(0.0), 0.0);
  EXPECT_DOUBLE_EQ(GammaEncode(1.0), 255.0);
  EXPECT_DOUBLE_EQ(GammaEncode(-0.5), 0.0);  // clamped
  EXPECT_DOUBLE_EQ(GammaEncode(3.0), 255.0);
}

}  // namespace
}  // namespace autoshovel::sensors
