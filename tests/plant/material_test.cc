// Bucket–material interaction: conservation, filling, spilling, repose, resistance.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "runtime/model/interpreted_model.h"
#include "runtime/plant/bucket_terrain.h"
#include "runtime/plant/earthmoving.h"
#include "runtime/plant/plant.h"
#include "tests/plant/plant_test_support.h"

namespace autoshovel::plant {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// McKyes (1985) tabulates the factors for a vertical blade in a frictional soil; the Coulomb
// wedge gives, for α = 90°, δ = 0: N_γ = tan(45° + φ/2)²/2 at β = 45° − φ/2 (Rankine passive),
// a closed form the search must reproduce.
TEST(Earthmoving, VerticalSmoothBladeIsRankinePassive) {
  for (double phi_deg : {25.0, 30.0, 35.0, 40.0}) {
    const double phi = phi_deg * kDeg;
    const ReeceFactors n = ComputeReeceFactors(90 * kDeg, phi, 0.0);
    const double kp = std::pow(std::tan(std::numbers::pi / 4 + phi / 2), 2);
    EXPECT_NEAR(n.n_gamma, kp / 2, 1e-6 * kp) << phi_deg;
    EXPECT_NEAR(n.failure_angle, std::numbers::pi / 4 - phi / 2, 1e-4) << phi_deg;
    // Cohesion: N_c = 2 sqrt(K_p) for the same wedge.
    EXPECT_NEAR(n.n_c, 2 * std::sqrt(kp), 1e-3 * kp) << phi_deg;
  }
}

TEST(Earthmoving, TabulatedFactorsMatchTheSearch) {
  const ReeceTable table(36 * kDeg, 28 * kDeg);
  for (double a = 10.0; a <= 90.0; a += 0.37) {
    const ReeceFactors direct = ComputeReeceFactors(a * kDeg, 36 * kDeg, 28 * kDeg);
    const ReeceFactors looked_up = table.At(a * kDeg);
    EXPECT_NEAR(looked_up.n_gamma, direct.n_gamma, 1e-3 * direct.n_gamma) << a;
    EXPECT_NEAR(looked_up.n_c, direct.n_c, 1e-3 * direct.n_c) << a;
    EXPECT_NEAR(looked_up.n_q, direct.n_q, 1e-3 * direct.n_q) << a;
  }
}

TEST(Earthmoving, ResistanceGrowsWithDepthSquaredAndCohesion) {
  CuttingInput in;
  in.width = 3;
  in.rake_angle = 30 * kDeg;
  in.density = 1600;
  in.friction_angle = 40 * kDeg;
  in.interface_angle = 24 * kDeg;
  in.depth = 0.5;
  const double f1 = ComputeCuttingResistance(in).total;
  in.depth = 1.0;
  const double f2 = ComputeCuttingResistance(in).total;
  EXPECT_NEAR(f2 / f1, 4.0, 1e-9);  // no cohesion: pure γ d² term
  in.cohesion = 4000;
  EXPECT_GT(ComputeCuttingResistance(in).total, f2);
  in.depth = 0;
  EXPECT_EQ(ComputeCuttingResistance(in).total, 0.0);
}

// River sand (denser, moist: cohesive) resists clearly more than big gravel at the same cut.
TEST(Earthmoving, SandResistsMoreThanGravel) {
  const model::MachineDescription machine = testing::LoadMachine("xcmg_968ev");
  auto force = [&](const std::string& name) {
    const model::Material* m = machine.FindMaterial(name);
    CuttingInput in;
    in.width = 3;
    in.depth = 0.9;
    in.rake_angle = 30 * kDeg;
    in.density = m->density;
    in.cohesion = m->cohesion;
    in.adhesion = 0.5 * m->cohesion;
    in.surcharge = m->density * 9.81 * 0.5;
    in.friction_angle = m->friction_angle;
    in.interface_angle = m->interface_friction_angle;
    return ComputeCuttingResistance(in).along;
  };
  EXPECT_GT(force("river_sand"), 1.2 * force("big_gravel"));
}

// A loader drives its flat bucket into a cone, stalls, scoops (boom up, bucket curled) and backs
// out; terrain volume + bucket volume is conserved to round-off at every tick.
struct CycleResult {
  double max_relative_volume_error = 0;
  double payload_volume = 0;
  double crowd_depth = 0;      // how far the tip went past the pile toe before the scoop [m]
  double stall_cut_depth = 0;  // material above the cutting edge when the push stopped [m]
  bool stalled = false;
  double time_to_stall = 0;
};

CycleResult RunJustInAndOut(const std::string& material, double approach_drive = 0.6) {
  const model::MachineDescription machine = testing::LoadMachine("xcmg_968ev");
  World world = testing::FlatYard(machine, 24.0);
  testing::AddCone(world, {8.0, 0.0}, 3.5, material);
  const double toe_x =
      8.0 -
      3.5 / std::tan(world.materials[testing::MaterialIndex(world, material)].angle_of_repose);
  Plant plant(machine, testing::Functions(machine.name), world, testing::LoaderAt(machine, -1.0));
  const double volume0 = world.terrain.MaterialVolume() + plant.bucket().payload_volume();
  CycleResult result;
  core::ActuatorCommand command;
  command.valve = {0.0, 0.0};
  command.drive = approach_drive;
  double slow_since = -1;
  bool scooping = false;
  while (plant.time() < 9.0) {
    const double t = plant.time();
    if (!scooping && t > 1.0 && std::abs(plant.state().speed) < 0.15) {
      if (slow_since < 0) slow_since = t;
      if (t - slow_since > 0.3) {
        scooping = true;
        result.stalled = true;
        result.time_to_stall = t;
        result.stall_cut_depth = plant.resistance().depth;
      }
    } else if (!scooping) {
      slow_since = -1;
    }
    if (!scooping && t > 5.0) scooping = true;  // never stalled: scoop anyway
    if (scooping) {
      command.drive = 0.2;
      command.valve = {0.9, plant.state().q[1] < 0.9 ? 0.9 : 0.0};
    }
    if (scooping && t > result.time_to_stall + 3.5) command.drive = -0.4, command.valve = {0, 0};
    EXPECT_TRUE(plant.SetCommand(command));
    plant.Advance(0.01);
    if (!scooping)
      result.crowd_depth = std::max(result.crowd_depth, plant.TipInWorld().x() - toe_x);
    const double volume = world.terrain.MaterialVolume() + plant.bucket().payload_volume();
    result.max_relative_volume_error =
        std::max(result.max_relative_volume_error, std::abs(volume - volume0) / volume0);
  }
  result.payload_volume = plant.bucket().payload_volume();
  return result;
}

TEST(BucketTerrain, VolumeIsConservedOverAFullCutAndScoop) {
  const CycleResult r = RunJustInAndOut("big_gravel");
  EXPECT_LT(r.max_relative_volume_error, 1e-6);
  EXPECT_GT(r.payload_volume, 1.0);         // it did take material
  EXPECT_LE(r.payload_volume, 3.5 + 1e-9);  // never more than the heaped capacity
}

// Wheel-loader seed §6.2, §7.4: a "Just in & out" stalls early in river sand. With the same
// push, the machine stops under a markedly thinner layer of sand than of gravel.
TEST(BucketTerrain, SandStopsTheBucketUnderAThinnerCutThanGravel) {
  const CycleResult gravel = RunJustInAndOut("big_gravel");
  const CycleResult sand = RunJustInAndOut("river_sand");
  ASSERT_TRUE(sand.stalled);
  ASSERT_TRUE(gravel.stalled);
  EXPECT_LT(sand.stall_cut_depth, 0.85 * gravel.stall_cut_depth)
      << "sand " << sand.stall_cut_depth << " m, gravel " << gravel.stall_cut_depth << " m";
}

// The holding model: with the opening (cutting edge to back-wall top) level the bucket holds
// exactly its rated heaped capacity (struck volume + heap); tilted back or forward by β the heap
// shrinks smoothly and is gone at β = ρ; beyond, the free surface stands at ρ from the lower
// rim; an opening facing down holds only what lies below both rims.
TEST(BucketTerrain, HoldsTheRatedHeapWithTheOpeningLevelAndLessWhenTilted) {
  const model::MachineDescription machine = testing::LoadMachine("xcmg_968ev");
  World world = testing::FlatYard(machine, 10.0);
  BucketTerrain bucket(machine.bucket, world);
  const double level = model::BucketLevelAttitude(machine);
  BucketPlacement placement;
  placement.pivot = Eigen::Vector2d(2.0, 3.0);  // clear of the floor
  auto hold_at = [&](double attitude) {
    placement.bucket_angle = attitude;
    return bucket.HoldableVolume(placement);
  };
  const double rated = machine.bucket.rated_capacity;
  EXPECT_NEAR(hold_at(level), rated, 1e-9 * rated);
  double previous = rated;
  for (double beta_deg = 2; beta_deg <= 60; beta_deg += 2) {  // tilted back (tip up)
    const double h = hold_at(level + beta_deg * kDeg);
    EXPECT_LT(h, previous + 1e-9) << beta_deg;
    previous = h;
  }
  previous = rated;
  for (double beta_deg = 2; beta_deg <= 60; beta_deg += 2) {  // tipped forward
    const double h = hold_at(level - beta_deg * kDeg);
    EXPECT_LT(h, previous + 1e-9) << beta_deg;
    previous = h;
  }
  // Continuous where the heap vanishes (β = ρ, empty bucket: the typical 35°).
  EXPECT_NEAR(hold_at(level + 35 * kDeg - 1e-6), hold_at(level + 35 * kDeg + 1e-6), 1e-3);
  // Racked 10° past level it still carries almost all of a heaped load (a loader carries racked).
  EXPECT_GT(hold_at(level + 10 * kDeg), 0.95 * rated);
  // Upside down: nothing stays in.
  EXPECT_LT(hold_at(level + 180 * kDeg), 0.05 * rated);
}

TEST(BucketTerrain, TiltedBucketPoursOutAndTerrainRelaxesToRepose) {
  const model::MachineDescription machine = testing::LoadMachine("xcmg_968ev");
  World world = testing::FlatYard(machine, 10.0);
  testing::AddCone(world, {2.0, 0.0}, 1.5, "small_gravel");
  BucketTerrain bucket(machine.bucket, world);
  const double volume0 = world.terrain.MaterialVolume();
  // Bucket sunk into the cone, level: it captures material.
  BucketPlacement placement;
  placement.plane_origin = Eigen::Vector2d(0, 0);
  placement.pivot = Eigen::Vector2d(1.2, 0.35);
  placement.bucket_angle = -18 * kDeg;
  bucket.Exchange(placement);
  const double taken = bucket.payload_volume();
  EXPECT_GT(taken, 0.3);
  EXPECT_NEAR(world.terrain.MaterialVolume() + taken, volume0, 1e-9 * volume0);
  // Lift it clear and tip it forward: it holds less than it carries and pours out.
  placement.pivot = Eigen::Vector2d(-2.0, 3.0);
  placement.bucket_angle = -80 * kDeg;
  EXPECT_LT(bucket.HoldableVolume(placement), taken);
  const ExchangeResult poured = bucket.Exchange(placement);
  EXPECT_GT(poured.spilled_volume, 0.0);
  EXPECT_NEAR(world.terrain.MaterialVolume() + bucket.payload_volume(), volume0, 1e-9 * volume0);
  // The poured heap is steeper than repose until relaxed; afterwards no neighbour pair is.
  bucket.RelaxToRepose(Eigen::Vector2d(0.0, 0.0), 4.0, 5000);
  const Terrain& t = world.terrain;
  const int m = testing::MaterialIndex(world, "small_gravel");
  const double max_drop = t.resolution() * std::tan(world.materials[m].angle_of_repose) + 1.5e-3;
  for (int iy = 1; iy < t.ny(); ++iy) {
    for (int ix = 1; ix < t.nx(); ++ix) {
      if (t.material(ix, iy) < 0) continue;
      EXPECT_LE(t.height(ix, iy) - t.height(ix - 1, iy), max_drop) << ix << "," << iy;
      EXPECT_LE(t.height(ix, iy) - t.height(ix, iy - 1), max_drop) << ix << "," << iy;
    }
  }
  EXPECT_NEAR(world.terrain.MaterialVolume() + bucket.payload_volume(), volume0, 1e-9 * volume0);
}

}  // namespace
}  // namespace autoshovel::plant
