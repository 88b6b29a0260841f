// Ray casting: exact box and terrain intersections, the pyramid traversal against an independent
// brute-force march over plant::Terrain::HeightAt, incremental updates, classes and reflectivity.
#include "runtime/sensors/raycast.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "tests/sensors/sensor_test_support.h"

namespace autoshovel::sensors {
namespace {

using core::SemanticClass;
using testing::FlatWorld;
using testing::MakeBox;

constexpr double kPi = std::numbers::pi;

Eigen::Vector3d Dir(double azimuth, double elevation) {
  return {std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
          std::sin(elevation)};
}

TEST(IntersectBox, AxisAlignedExactDistanceAndNormal) {
  const auto box = MakeBox("b", {0, 0, 1}, {1, 2, 3}, 0.0, SemanticClass::kWall);
  double t;
  Eigen::Vector3d n;
  ASSERT_TRUE(IntersectBox(box, {-10, 0.5, 1.5}, Eigen::Vector3d::UnitX(), 100, t, n));
  EXPECT_NEAR(t, 9.0, 1e-12);
  EXPECT_NEAR((n - Eigen::Vector3d(-1, 0, 0)).norm(), 0.0, 1e-12);
  // From above onto the top face z = 4.
  ASSERT_TRUE(IntersectBox(box, {0.3, -1.0, 10}, -Eigen::Vector3d::UnitZ(), 100, t, n));
  EXPECT_NEAR(t, 6.0, 1e-12);
  EXPECT_NEAR((n - Eigen::Vector3d(0, 0, 1)).norm(), 0.0, 1e-12);
  // Oblique: the face x = −1 is reached at t = 9 / cos a, where |y| = 9 tan a < 2.
  const double a = 10 * kPi / 180;
  ASSERT_TRUE(IntersectBox(box, {-10, 0, 0.5}, Dir(a, 0), 100, t, n));
  EXPECT_NEAR(t, 9.0 / std::cos(a), 1e-12);
}

TEST(IntersectBox, TurnedBoxExactDistance) {
  // A box turned by 30°; a ray along its local −x axis from 5 m out meets the face at
  // local x = +half_x: range 5 − 0.8.
  const double yaw = kPi / 6;
  const auto box = MakeBox("b", {3, -2, 1}, {0.8, 0.5, 1.0}, yaw, SemanticClass::kPerson);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d origin = box.center + R * Eigen::Vector3d(5, 0.3, 0.2);
  double t;
  Eigen::Vector3d n;
  ASSERT_TRUE(IntersectBox(box, origin, R * Eigen::Vector3d(-1, 0, 0), 100, t, n));
  EXPECT_NEAR(t, 4.2, 1e-12);
  EXPECT_NEAR((n - R * Eigen::Vector3d(1, 0, 0)).norm(), 0.0, 1e-12);
  // A box turned by 45° with half extents 1 meets a ray along world x through its centre at its
  // corner, √2 from the centre.
  const auto diamond = MakeBox("d", {0, 0, 0}, {1, 1, 1}, kPi / 4, SemanticClass::kOther);
  ASSERT_TRUE(IntersectBox(diamond, {-10, 0, 0.5}, Eigen::Vector3d::UnitX(), 100, t, n));
  EXPECT_NEAR(t, 10 - std::sqrt(2.0), 1e-12);
}

TEST(IntersectBox, MissesOverInsideAndBeyondRange) {
  const auto box = MakeBox("b", {0, 0, 1}, {1, 1, 1}, 0.3, SemanticClass::kWall);
  double t;
  Eigen::Vector3d n;
  // Passes 1 cm over the top.
  EXPECT_FALSE(IntersectBox(box, {-10, 0, 2.01}, Eigen::Vector3d::UnitX(), 100, t, n));
  // Points away.
  EXPECT_FALSE(IntersectBox(box, {-10, 0, 1}, -Eigen::Vector3d::UnitX(), 100, t, n));
  // Starts inside: a sensor does not see its own housing.
  EXPECT_FALSE(IntersectBox(box, {0, 0, 1}, Eigen::Vector3d::UnitX(), 100, t, n));
  // Beyond the range limit (hit at 9 m).
  EXPECT_FALSE(IntersectBox(box, {-10, 0, 1}, Eigen::Vector3d::UnitX(), 8.5, t, n));
}

TEST(RaycastScene, FlatFloorExactRange) {
  const plant::World world = FlatWorld(40, 40, 0.05);
  const RaycastScene scene(world);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> az(-kPi, kPi), el(-1.4, -0.08), xy(-3, 3), z(0.5, 5);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d o(xy(rng), xy(rng), z(rng));
    const double e = el(rng);
    const RayHit hit = scene.Cast(o, Dir(az(rng), e), 100);
    const double expected = o.z() / std::sin(-e);
    if (expected > 16.9) continue;  // may leave the 40 m yard
    ASSERT_TRUE(hit.hit);
    EXPECT_NEAR(hit.range, expected, 1e-9);
    EXPECT_NEAR(hit.point.z(), 0.0, 1e-9);
    EXPECT_NEAR(hit.normal.z(), 1.0, 1e-12);
    EXPECT_EQ(hit.semantic_class, SemanticClass::kGround);
    EXPECT_DOUBLE_EQ(hit.reflectivity, world.ground_reflectivity);
  }
  // Upwards: nothing.
  EXPECT_FALSE(scene.Cast({0, 0, 1}, Dir(0.3, 0.2), 100).hit);
}

TEST(RaycastScene, InclinedPlaneIsReproducedExactly) {
  // Bilinear interpolation reproduces a plane z = a x + b y + c exactly, so every hit inside the
  // cell-centre hull is the analytic one.
  plant::World world = FlatWorld(30, 30, 0.1);
  const double a = 0.3, b = -0.15, c = 2.0;
  auto& t = world.terrain;
  for (int iy = 0; iy < t.ny(); ++iy) {
    for (int ix = 0; ix < t.nx(); ++ix) {
      const Eigen::Vector2d p = t.CellCenter(ix, iy);
      t.SetHeight(ix, iy, a * p.x() + b * p.y() + c + 10);  // keep above the floor
    }
  }
  const RaycastScene scene(world);
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> az(-kPi, kPi), el(-1.5, -0.2), xy(-4, 4);
  int checked = 0;
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d o(xy(rng), xy(rng), 25.0);
    const Eigen::Vector3d d = Dir(az(rng), el(rng));
    // o_z + s d_z = a (o_x + s d_x) + b (o_y + s d_y) + c + 10
    const double s = (a * o.x() + b * o.y() + c + 10 - o.z()) / (d.z() - a * d.x() - b * d.y());
    const Eigen::Vector3d p = o + s * d;
    if (std::abs(p.x()) > 14.9 || std::abs(p.y()) > 14.9) continue;
    const RayHit hit = scene.Cast(o, d, 200);
    ASSERT_TRUE(hit.hit);
    EXPECT_NEAR(hit.range, s, 1e-9);
    EXPECT_NEAR((hit.normal - Eigen::Vector3d(-a, -b, 1).normalized()).norm(), 0, 1e-9);
    ++checked;
  }
  EXPECT_GT(checked, 1000);
}

// Independent reference: march along the ray in 2 mm steps against Terrain::HeightAt (the
// plant's own bilinear surface), then bisect the first sign change.
double BruteForceRange(const plant::Terrain& t, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                       double max_range) {
  const auto& g = t.geometry();
  const double x_lo = g.origin.x(), x_hi = g.origin.x() + g.nx * g.resolution;
  const double y_lo = g.origin.y(), y_hi = g.origin.y() + g.ny * g.resolution;
  auto gap = [&](double s) {
    const Eigen::Vector3d p = o + s * d;
    if (p.x() < x_lo || p.x() > x_hi || p.y() < y_lo || p.y() > y_hi) return 1.0;
    return p.z() - t.HeightAt(p.x(), p.y());
  };
  constexpr double kStep = 0.002;
  double prev = 0;
  for (double s = kStep; s <= max_range; s += kStep) {
    if (gap(s) <= 0) {
      double lo = prev, hi = s;
      for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (gap(mid) <= 0 ? hi : lo) = mid;
      }
      return hi;
    }
    prev = s;
  }
  return -1;
}

void RoughTerrain(plant::Terrain& t, std::uint64_t seed, int ix0, int iy0, int ix1, int iy1) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> noise(-0.03, 0.03);
  for (int iy = iy0; iy <= iy1; ++iy) {
    for (int ix = ix0; ix <= ix1; ++ix) {
      const Eigen::Vector2d p = t.CellCenter(ix, iy);
      const double z =
          1.0 + 0.8 * std::sin(0.7 * p.x() + static_cast<double>(seed)) * std::cos(0.5 * p.y()) +
          0.4 * std::sin(2.1 * p.y() + 0.3 * p.x()) + noise(rng);
      t.SetHeight(ix, iy, std::max(z, 0.0));
      t.SetMaterial(ix, iy, 0);
    }
  }
}

void ExpectMatchesBruteForce(const RaycastScene& scene, std::uint64_t seed, int min_hits) {
  const plant::Terrain& t = scene.world().terrain;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> az(-kPi, kPi), el(-1.2, -0.12), xy(-6, 6), z(2.6, 6);
  int hits = 0;
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d o(xy(rng), xy(rng), z(rng));
    const Eigen::Vector3d d = Dir(az(rng), el(rng));
    const double expected = BruteForceRange(t, o, d, 60);
    const RayHit hit = scene.CastTerrain(o, d, 60);
    ASSERT_EQ(hit.hit, expected >= 0) << "ray " << i;
    if (!hit.hit) continue;
    ++hits;
    EXPECT_NEAR(hit.range, expected, 1e-7) << "ray " << i;
    EXPECT_NEAR(hit.point.z(), t.HeightAt(hit.point.x(), hit.point.y()), 1e-9);
  }
  EXPECT_GE(hits, min_hits);
}

TEST(RaycastScene, PyramidTraversalMatchesBruteForceMarch) {
  plant::World world = FlatWorld(20, 20, 0.1);
  RoughTerrain(world.terrain, 1, 0, 0, world.terrain.nx() - 1, world.terrain.ny() - 1);
  const RaycastScene scene(world);
  EXPECT_NEAR(scene.max_terrain_height(), world.terrain.MaxHeight(), 1e-6);
  EXPECT_GE(scene.max_terrain_height(), world.terrain.MaxHeight());
  ExpectMatchesBruteForce(scene, 11, 200);
}

TEST(RaycastScene, IncrementalUpdateOfADirtyRegion) {
  plant::World world = FlatWorld(20, 20, 0.1);
  RaycastScene scene(world);
  // Dig and dump in a 7 m × 5 m rectangle; refresh only that rectangle.
  RoughTerrain(world.terrain, 2, 40, 60, 109, 109);
  scene.UpdateTerrain(40, 60, 109, 109);
  ExpectMatchesBruteForce(scene, 12, 150);
  // A tall spike in one cell must be seen after its update (and the pyramid's top with it).
  world.terrain.SetHeight(150, 150, 7.5);
  scene.UpdateTerrain(150, 150, 150, 150);
  EXPECT_FLOAT_EQ(static_cast<float>(scene.max_terrain_height()), 7.5f);
  const Eigen::Vector2d c = world.terrain.CellCenter(150, 150);
  const RayHit hit = scene.CastTerrain({c.x(), c.y(), 10}, -Eigen::Vector3d::UnitZ(), 20);
  ASSERT_TRUE(hit.hit);
  EXPECT_NEAR(hit.range, 2.5, 1e-9);
}

TEST(RaycastScene, ClassesAndReflectivity) {
  plant::World world = FlatWorld(20, 20, 0.05);
  testing::AddCone(world.terrain, {3, 0}, 2.0, 3.0, 1);  // small gravel, ρ = 0.32
  world.obstacles.push_back(
      MakeBox("p", {-3, 0, 0.9}, {0.3, 0.3, 0.9}, 0, SemanticClass::kPerson, 0.6));
  RaycastScene scene(world,
                     {MakeBox("own", {0, 5, 1.5}, {1, 1, 1.5}, 0, SemanticClass::kOwnLoader, 0.5)});
  ASSERT_EQ(scene.boxes().size(), 2u);
  const Eigen::Vector3d down = -Eigen::Vector3d::UnitZ();
  RayHit hit = scene.Cast({3, 0.1, 5}, down, 20);
  EXPECT_EQ(hit.semantic_class, SemanticClass::kPile);
  EXPECT_DOUBLE_EQ(hit.reflectivity, 0.32);
  EXPECT_EQ(hit.box, -1);
  hit = scene.Cast({8, 0, 5}, down, 20);
  EXPECT_EQ(hit.semantic_class, SemanticClass::kGround);
  EXPECT_DOUBLE_EQ(hit.reflectivity, 0.2);
  hit = scene.Cast({-3, 0, 5}, down, 20);
  EXPECT_EQ(hit.semantic_class, SemanticClass::kPerson);
  EXPECT_NEAR(hit.range, 3.2, 1e-12);
  EXPECT_DOUBLE_EQ(hit.reflectivity, 0.6);
  hit = scene.Cast({0, 5, 5}, down, 20);
  EXPECT_EQ(hit.semantic_class, SemanticClass::kOwnLoader);
  // The nearer of box and terrain wins: the person stands in front of the pile.
  hit = scene.Cast({-6, 0, 1}, Eigen::Vector3d::UnitX(), 20);
  EXPECT_EQ(hit.semantic_class, SemanticClass::kPerson);
  EXPECT_NEAR(hit.range, 2.7, 1e-12);
  // With the person moved away, the pile: the cone surface at z = 1 is r = 1.5 from the apex.
  world.obstacles.clear();
  scene.UpdateBoxes();
  hit = scene.Cast({-6, 0, 1}, Eigen::Vector3d::UnitX(), 20);
  EXPECT_EQ(hit.semantic_class, SemanticClass::kPile);
  EXPECT_NEAR(hit.range, 7.5, 0.05 * 2.0 / 3.0 / std::sqrt(2.0) * 1.5 + 1e-9);
}

// The box grid must give exactly what testing every box in order gives (nearest entry; of equal
// entries the highest index), for rays from inside and outside the grid, along the axes, straight
// down, grazing, and after the boxes move.
TEST(RaycastScene, BoxGridMatchesTestingEveryBox) {
  plant::World world = FlatWorld(60, 60, 0.1);
  std::mt19937 rng(20261204);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto scatter = [&](int n) {
    world.obstacles.clear();
    for (int i = 0; i < n; ++i) {
      const bool wall = i % 7 == 0;  // long thin walls cross many cells
      const Eigen::Vector3d half =
          wall ? Eigen::Vector3d(0.3, 6 + 8 * std::abs(u(rng)), 2.0)
               : Eigen::Vector3d(0.1 + 2 * std::abs(u(rng)), 0.1 + 2 * std::abs(u(rng)),
                                 0.2 + 1.5 * std::abs(u(rng)));
      world.obstacles.push_back(MakeBox("b" + std::to_string(i),
                                        {25 * u(rng), 25 * u(rng), half.z() + 0.5 * u(rng)}, half,
                                        kPi * u(rng), SemanticClass::kWall));
    }
    world.obstacles.push_back(world.obstacles[3]);  // an exact twin: a tie on every hit
  };
  scatter(60);
  RaycastScene scene(world);
  int hits = 0, ties = 0;
  auto check = [&](const Eigen::Vector3d& o, const Eigen::Vector3d& d, double max_range) {
    int expected_box = -1;
    double best = max_range, t;
    Eigen::Vector3d n;
    for (std::size_t i = 0; i < scene.boxes().size(); ++i) {
      if (IntersectBox(scene.boxes()[i], o, d, best, t, n))
        best = t, expected_box = static_cast<int>(i);
    }
    const RayHit hit = scene.CastBoxes(o, d, max_range);
    ASSERT_EQ(hit.box, expected_box)
        << "origin " << o.transpose() << " direction " << d.transpose();
    ASSERT_EQ(hit.hit, expected_box >= 0);
    if (hit.hit) {
      ++hits;
      ties += expected_box == static_cast<int>(scene.boxes().size()) - 1;
      EXPECT_NEAR(hit.range, best, 1e-12);
    }
  };
  for (int round = 0; round < 2; ++round) {
    for (int k = 0; k < 4000; ++k) {
      const Eigen::Vector3d o(40 * u(rng), 40 * u(rng), 1.5 + 2.5 * u(rng));
      Eigen::Vector3d d;
      switch (k % 5) {
        case 0:
          d = Eigen::Vector3d(u(rng) > 0 ? 1 : -1, 0, 0);
          break;  // along x
        case 1:
          d = Eigen::Vector3d(0, u(rng) > 0 ? 1 : -1, 0);
          break;  // along y
        case 2:
          d = -Eigen::Vector3d::UnitZ();
          break;  // straight down
        default:
          d = Dir(kPi * u(rng), 0.3 * u(rng));
          break;
      }
      check(o, d.normalized(), k % 3 == 0 ? 15.0 : 80.0);
    }
    scatter(25);  // the boxes move: the grid is rebuilt
    scene.UpdateBoxes();
  }
  // The rays must exercise the walk: thousands of hits, some on the twin.
  EXPECT_GT(hits, 1500);
  EXPECT_GT(ties, 5);
}

// Shadow rays towards the sun test only the boxes whose shadow covers their origin: the answer
// must be CastBoxes' for any origin, including ones inside a box, on its faces' planes, or far
// outside the shadows' grid.
TEST(ParallelRayBoxes, OccludedIsExactlyWhetherCastBoxesHits) {
  plant::World world = FlatWorld(60, 60, 0.1);
  std::mt19937 rng(20261207);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 40; ++i) {
    const Eigen::Vector3d half(0.1 + 3 * std::abs(u(rng)), 0.1 + 3 * std::abs(u(rng)),
                               0.2 + 1.5 * std::abs(u(rng)));
    world.obstacles.push_back(MakeBox("b" + std::to_string(i),
                                      {25 * u(rng), 25 * u(rng), half.z() + 0.3 * u(rng)}, half,
                                      kPi * u(rng), SemanticClass::kWall));
  }
  const RaycastScene scene(world);
  int occluded = 0, checked = 0;
  for (const Eigen::Vector3d& sun :
       {Eigen::Vector3d(-0.5, -0.5, 0.70710678118654757), Eigen::Vector3d(0.2, 0.9, 0.3),
        Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 0, 0)}) {
    const ParallelRayBoxes boxes(scene, sun);
    const Eigen::Vector3d d = sun.normalized();
    for (int k = 0; k < 6000; ++k) {
      const Eigen::Vector3d o(35 * u(rng), 35 * u(rng), 0.01 + 2.5 * std::abs(u(rng)));
      const double max_range = k % 4 == 0 ? 3.0 : 400.0;
      const bool expected = scene.CastBoxes(o, d, max_range).hit;
      ASSERT_EQ(boxes.Occluded(o, max_range), expected)
          << "origin " << o.transpose() << " towards " << d.transpose();
      occluded += expected;
      ++checked;
    }
  }
  // Both answers must occur often, or the comparison says little.
  EXPECT_GT(occluded, checked / 20);
  EXPECT_LT(occluded, checked - checked / 20);
  EXPECT_THROW(ParallelRayBoxes(scene, Eigen::Vector3d::Zero()), std::invalid_argument);
  const plant::World bare = FlatWorld(10, 10, 0.1);
  const RaycastScene empty(bare);
  EXPECT_FALSE(ParallelRayBoxes(empty, Eigen::Vector3d::UnitZ()).Occluded({1, 1, 0.1}, 100));
}

TEST(RaycastScene, RaysLeavingTheYardOrBeyondRangeReturnNothing) {
  const plant::World world = FlatWorld(10, 10, 0.05);
  const RaycastScene scene(world);
  // Ground would be reached 20 m out, outside the 10 m yard.
  EXPECT_FALSE(scene.Cast({0, 0, 2}, Dir(0, -std::atan(0.1)), 100).hit);
  // From outside the yard, coming in.
  const RayHit in = scene.Cast({-20, 0, 2}, Dir(0, -std::atan(2.0 / 17.0)), 100);
  ASSERT_TRUE(in.hit);
  EXPECT_NEAR(in.point.x(), -3.0, 1e-9);
  // Range limit.
  EXPECT_FALSE(scene.Cast({0, 0, 2}, -Eigen::Vector3d::UnitZ(), 1.99).hit);
  EXPECT_TRUE(scene.Cast({0, 0, 2}, -Eigen::Vector3d::UnitZ(), 2.01).hit);
}

}  // namespace
}  // namespace autoshovel::sensors
