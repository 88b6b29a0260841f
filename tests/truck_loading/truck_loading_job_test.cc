// The truck-loading job on the plant: passes dig the face, swing, dump into the truck and come
// back, the material dug ends up in the bed, nothing touches the truck; and a person walking
// into the swing path is stopped short of in every trial.
#include "runtime/app/truck_loading/truck_loading_job.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace autoshovel::app {
namespace {

const std::string kModels = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";

TruckLoadingOptions Options() {
  TruckLoadingOptions o;
  o.models_dir = kModels;
  o.dig_evaluations = 6;  // a test-sized search; the job's default is 12
  return o;
}

TEST(TruckLoadingJob, PassesMoveTheFaceIntoTheBedWithoutTouchingTheTruck) {
  TruckLoadingJob job(Options());
  double dumped = 0;
  for (int i = 0; i < 2; ++i) {
    std::ostringstream progress;
    const PassOutcome pass = job.RunPass(i, &progress);
    std::cout << progress.str();
    EXPECT_TRUE(pass.completed) << pass.failure;
    EXPECT_EQ(pass.collisions, 0);
    EXPECT_GT(pass.min_truck_clearance, 0.0);
    // A bucketful dug, and most of it reached the bed: the heap above the struck bucket can
    // spill on the swing when the stick reaches out (measured up to a third of a pass's load on
    // the full run), but nothing is dumped that was not dug.
    EXPECT_GT(pass.dug_volume, 0.6);
    EXPECT_GT(pass.dumped_volume, 0.7 * pass.dug_volume);
    EXPECT_LE(pass.dumped_volume, pass.dug_volume + 1e-9);
    dumped += pass.dumped_volume;
  }
  EXPECT_NEAR(job.BedMass() / 1650.0, dumped, 1e-6);
}

// The first pass with nobody about: where the bucket goes and when. The trials below repeat it
// (the job is deterministic) with a person walking in.
const PassOutcome& ReferencePass() {
  static const PassOutcome pass = [] {
    TruckLoadingJob job(Options());
    return job.RunPass(0, nullptr);
  }();
  return pass;
}

// ISO 17757: an autonomous machine stops before any person in its path. In five trials a person
// walks 3 m into the path of the returning bucket, at places where the reference pass brought the
// tip lower than a person is tall above the ground they stand on, arriving 2.5 s to 4.5 s before
// the bucket would, from beyond the face or along it; they stand there for 6 s and walk back.
// Every time the look-ahead stops the machine, the linkage never reaches them (ground truth at
// 20 Hz), and once they have gone the pass completes.
TEST(TruckLoadingJob, StopsShortOfAPersonWalkingIntoTheSwingPath) {
  const PassOutcome& reference = ReferencePass();
  ASSERT_TRUE(reference.completed) << reference.failure;
  const double walk_in = 3.0, speed = 1.4, longest_lead = 4.5;
  std::vector<TraceSample> low;  // the tip within a person's height of the ground, on the bench
  for (const TraceSample& sample : reference.trace) {
    const Eigen::Vector3d& tip = sample.p_world_tip;
    if (sample.t > 0.5 + longest_lead + walk_in / speed &&
        tip.z() - sample.ground_below_tip < 1.7 && sample.ground_below_tip > -0.5 &&
        tip.head<2>().norm() > 4.0) {
      low.push_back(sample);
    }
  }
  ASSERT_GE(low.size(), 5u) << "the reference pass never brings the bucket low over the bench";
  for (int trial = 0; trial < 5; ++trial) {
    const TraceSample& target = low[trial * (low.size() - 1) / 4];
    PersonWalk walk;
    walk.pass = 0;
    walk.to = target.p_world_tip.head<2>();
    const Eigen::Vector2d radial = walk.to.normalized();
    const Eigen::Vector2d away_from_truck(radial.y(), -radial.x());  // the truck is at +90°
    walk.from = walk.to + walk_in * (trial % 2 == 0 ? radial : away_from_truck);
    walk.speed = speed;
    walk.stay = 6.0;
    const double lead = 2.5 + 0.5 * trial;
    walk.start_delay = target.t - lead - walk_in / speed;
    TruckLoadingOptions o = Options();
    o.person = walk;
    TruckLoadingJob job(o);
    std::ostringstream progress;
    const PassOutcome pass = job.RunPass(0, &progress);
    std::cout << "trial " << trial << ": person at (" << walk.to.transpose() << ") from "
              << target.t - lead << " s (tip " << target.p_world_tip.z() - target.ground_below_tip
              << " m above their ground at " << target.t << " s): " << pass.safety_stops
              << " stop(s), clearance " << pass.min_person_clearance << " m, load phase "
              << pass.trace.back().t << " s (" << reference.trace.back().t << " s alone)\n";
    EXPECT_GE(pass.safety_stops, 1) << progress.str();
    EXPECT_GT(pass.min_person_clearance, 0.0) << progress.str();
    EXPECT_EQ(pass.collisions, 0);
    EXPECT_TRUE(pass.completed) << pass.failure;
  }
}

// §3: a dust cloud over the truck. The first-pass scan raises the dust warning; the pass's
// load phase runs with every joint's top rate scaled by the monitor's recommendation, and is
// slower than the same pass in clear air, yet completes without touching the truck.
TEST(TruckLoadingJob, DustOverTheTruckSlowsTheLoadPhase) {
  const PassOutcome& clear = ReferencePass();
  ASSERT_TRUE(clear.completed) << clear.failure;
  EXPECT_DOUBLE_EQ(clear.speed_scale, 1.0);
  TruckLoadingOptions o = Options();
  DustCloud cloud;
  cloud.p_world_center = Eigen::Vector3d(0.0, o.truck_radius, 0.5);  // the truck at 90°
  o.dust.push_back(cloud);
  TruckLoadingJob job(o);
  std::ostringstream progress;
  const PassOutcome dusty = job.RunPass(0, &progress);
  const double clear_load = clear.total_time - clear.dig_time;
  const double dusty_load = dusty.total_time - dusty.dig_time;
  std::cout << "speed scale " << dusty.speed_scale << ", load phase " << dusty_load << " s (clear "
            << clear_load << " s), swing-back warning " << dusty.dust_warning << "\n";
  EXPECT_TRUE(dusty.completed) << dusty.failure << progress.str();
  EXPECT_EQ(dusty.collisions, 0);
  EXPECT_GT(dusty.min_truck_clearance, 0.0);
  EXPECT_LT(dusty.speed_scale, 0.7);
  EXPECT_GE(dusty.speed_scale, 0.3);  // the monitor's floor: dust alone never stops the machine
  EXPECT_GT(dusty_load, 1.2 * clear_load);
  EXPECT_TRUE(dusty.dust_warning);  // the cloud is still there on the swing back
}

}  // namespace
}  // namespace autoshovel::app
