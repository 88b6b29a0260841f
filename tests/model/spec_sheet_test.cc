// Spec-sheet figures (runtime/model/spec_sheet.h) against hand computations on a machine simple
// enough to work out on paper: bucket frame aligned with the base frame at the breakout pose,
// cylinders pinned straight between a parent and its child (no four-bar).
#include "runtime/model/spec_sheet.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "runtime/model/interpreted_model.h"
#include "runtime/model/machine_summary.h"
#include "runtime/model/plant_constants.h"

namespace autoshovel::model {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kG = plant::kGravity;

// A 12 t loader on paper: M at (1, 2), boom 3 m, bucket link 1.2 m, floor along the bucket x axis.
MachineDescription PaperLoader() {
  MachineDescription m;
  m.name = "paper_loader";
  m.kind = MachineKind::kWheelLoader;
  m.chassis.operating_mass = 12000;
  m.chassis.hinge_to_front_axle = 1.5;
  m.chassis.hinge_to_rear_axle = 1.5;
  m.chassis.track_width = 2.0;
  m.chassis.wheel_radius = 0.7;
  m.chassis.front_axle_load_fraction = 0.45;
  m.chassis.max_articulation = 40 * kPi / 180;
  m.arm_pivot = {1.0, 2.0};
  Link boom;
  boom.name = "boom";
  boom.length = 3.0;
  boom.joint_min = -50 * kPi / 180;
  boom.joint_max = 50 * kPi / 180;
  boom.mass = 1500;
  boom.center_of_mass = {1.5, 0.0};
  boom.inertia = 1000;
  Link bucket;
  bucket.name = "bucket";
  bucket.length = 1.2;
  bucket.joint_min = -95 * kPi / 180;
  bucket.joint_max = 65 * kPi / 180;
  bucket.mass = 900;
  bucket.center_of_mass = {0.5, 0.2};
  bucket.inertia = 300;
  m.links = {boom, bucket};
  Actuator lift;
  lift.name = "lift";
  lift.joint = "boom";
  lift.count = 2;
  lift.bore = 0.14;
  lift.rod = 0.08;
  lift.stroke = 1.5;
  lift.retracted_length = 0.5;
  lift.base_mount = {"chassis", {0.2, -1.2}};
  lift.rod_mount = {"boom", {1.0, -0.2}};
  lift.dead_volume = 0.002;
  lift.relief_pressure = 250e5;
  lift.valve.rated_flow = 300e-3 / 60;
  lift.valve.rated_pressure_drop = 15e5;
  lift.valve.flow_gain = lift.valve.rated_flow / std::sqrt(15e5);
  lift.valve.spool_time_constant = 0.05;
  Actuator tilt = lift;
  tilt.name = "tilt";
  tilt.joint = "bucket";
  tilt.count = 1;
  tilt.bore = 0.18;
  tilt.rod = 0.09;
  tilt.base_mount = {"boom", {1.5, 0.6}};
  tilt.rod_mount = {"bucket", {-0.2, 0.7}};
  m.hydraulics.pump_pressure = 230e5;
  m.hydraulics.tank_pressure = 2e5;
  m.hydraulics.bulk_modulus = 1.2e9;
  m.hydraulics.pump_efficiency = 0.85;
  m.hydraulics.actuators = {lift, tilt};
  m.bucket.width = 2.5;
  m.bucket.rated_capacity = 2.0;
  m.bucket.rated_load = 3500;
  // Tip, bottom back corner, top of back: the bottom runs along the bucket x axis.
  m.bucket.profile = {{1.2, 0.0}, {0.2, 0.0}, {-0.1, 0.5}, {0.1, 0.9}};
  return m;
}

Eigen::Vector2d Rotate(double angle, const Eigen::Vector2d& v) {
  return {std::cos(angle) * v.x() - std::sin(angle) * v.y(),
          std::sin(angle) * v.x() + std::cos(angle) * v.y()};
}
Eigen::Vector2d Perp(const Eigen::Vector2d& v) { return {-v.y(), v.x()}; }

TEST(SpecSheet, BreakoutPoseHasTheBottomLevelAndTheTipOnTheGround) {
  const MachineDescription m = PaperLoader();
  const BreakoutForce b = ComputeBreakoutForce(m, MachineMassModel(m));
  // Bottom along the bucket x axis: level when φ2 = q0 + q1 = 0; tip height 2 + 3 sin q0 = 0.
  EXPECT_NEAR(b.pose[0], std::asin(-2.0 / 3.0), 1e-12);
  EXPECT_NEAR(b.pose[0] + b.pose[1], 0.0, 1e-12);
  EXPECT_TRUE(b.pose_in_range);
  EXPECT_NEAR(b.p_base_point.x(), 1.0 + 3.0 * std::cos(b.pose[0]) + 1.1, 1e-12);
  EXPECT_NEAR(b.p_base_point.y(), 0.0, 1e-12);
}

TEST(SpecSheet, BreakoutByTiltEqualsTheHandComputedVirtualWork) {
  const MachineDescription m = PaperLoader();
  const BreakoutForce b = ComputeBreakoutForce(m, MachineMassModel(m));
  const double q0 = std::asin(-2.0 / 3.0);
  // Pins in M; the bucket frame is parallel to M (φ2 = 0).
  const Eigen::Vector2d a(3 * std::cos(q0), 3 * std::sin(q0));  // bucket pivot
  const Eigen::Vector2d base = Rotate(q0, {1.5, 0.6});
  const Eigen::Vector2d rod_offset(-0.2, 0.7);  // from the bucket pivot, φ2 = 0
  const Eigen::Vector2d rod = a + rod_offset;
  const Eigen::Vector2d axis = (rod - base).normalized();
  const double lever = axis.dot(Perp(rod_offset));  // dL/dq1: rotating the rod pin about A
  const double cap = kPi / 4 * 0.18 * 0.18, annulus = kPi / 4 * (0.18 * 0.18 - 0.09 * 0.09);
  const double force = lever > 0 ? 250e5 * cap - 2e5 * annulus : 250e5 * annulus - 2e5 * cap;
  const double gravity = -900 * kG * 0.5;  // bucket centre 0.5 m ahead of its pivot
  const double expected = (force * std::abs(lever) + gravity) / 1.1;  // P 1.1 m ahead of A
  EXPECT_NEAR(b.by_tilt, expected, 1e-6 * expected);
  EXPECT_GT(b.by_tilt, 50e3);
}

TEST(SpecSheet, BreakoutByLiftEqualsTheHandComputedVirtualWork) {
  const MachineDescription m = PaperLoader();
  const BreakoutForce b = ComputeBreakoutForce(m, MachineMassModel(m));
  const double q0 = std::asin(-2.0 / 3.0);
  const Eigen::Vector2d base(0.2, -1.2), rod_arm = Rotate(q0, {1.0, -0.2});
  const Eigen::Vector2d axis = (rod_arm - base).normalized();
  const double lever = axis.dot(Perp(rod_arm));
  const double cap = 2 * kPi / 4 * 0.14 * 0.14, annulus = 2 * kPi / 4 * (0.14 * 0.14 - 0.08 * 0.08);
  const double force = lever > 0 ? 250e5 * cap - 2e5 * annulus : 250e5 * annulus - 2e5 * cap;
  // The tilt cylinder locks the bucket to the boom: everything turns about M.
  const double boom_x = 1.5 * std::cos(q0);
  const double bucket_x = 3 * std::cos(q0) + 0.5;
  const double gravity = -kG * (1500 * boom_x + 900 * bucket_x);
  const double expected = (force * std::abs(lever) + gravity) / (3 * std::cos(q0) + 1.1);
  EXPECT_NEAR(b.by_lift, expected, 1e-6 * expected);
}

TEST(SpecSheet, StraightTippingLoadIsTheMomentBalanceAboutTheFrontAxle) {
  const MachineDescription m = PaperLoader();
  const MassModel mass = MachineMassModel(m);
  const TippingLoad t = ComputeTippingLoad(m, mass);
  EXPECT_DOUBLE_EQ(t.pose[0], 0.0);
  EXPECT_DOUBLE_EQ(t.pose[1], m.links[1].joint_max);
  // Machine centre: the axle-load reference moved by the arm between carry and this pose.
  const auto arm_x = [&](double q0, double q1) {
    const double phi2 = q0 + q1;
    return 1500 * (1 + 1.5 * std::cos(q0)) +
           900 * (1 + 3 * std::cos(q0) + Rotate(phi2, {0.5, 0.2}).x());
  };
  const double q_carry0 = -50 * kPi / 180 + 0.2 * 100 * kPi / 180, q1 = 65 * kPi / 180;
  const double x_ref = -1.5 + 0.45 * 3.0;
  const double x_cg = x_ref + (arm_x(0.0, q1) - arm_x(q_carry0, q1)) / 12000;
  const double expected = 12000 * (1.5 - x_cg) / (t.p_base_load.x() - 1.5);
  EXPECT_NEAR(t.straight, expected, 1e-9 * expected);
  EXPECT_LT(t.full_turn, t.straight);
  EXPECT_FALSE(t.full_turn_edge.empty());
}

TEST(SpecSheet, TippingLoadGrowsByTheAddedCounterweightMomentOverTheLoadArm) {
  MachineDescription m = PaperLoader();
  const TippingLoad before = ComputeTippingLoad(m, MachineMassModel(m));
  // 0.05 less on the front axle: the centre of mass moves 0.05 × 3 m back, a moment of
  // 12000 kg × 0.15 m about the front axle more against the load.
  m.chassis.front_axle_load_fraction -= 0.05;
  const TippingLoad after = ComputeTippingLoad(m, MachineMassModel(m));
  const double arm = before.p_base_load.x() - 1.5;
  EXPECT_NEAR(after.straight - before.straight, 12000 * 0.15 / arm, 1e-6);
  EXPECT_GT(after.full_turn, before.full_turn);
}

TEST(SpecSheet, FullTurnTippingLoadTendsToTheStraightOneAsTheArticulationVanishes) {
  MachineDescription m = PaperLoader();
  m.chassis.max_articulation = 1e-7;
  const TippingLoad t = ComputeTippingLoad(m, MachineMassModel(m));
  EXPECT_NEAR(t.full_turn, t.straight, 1e-4 * t.straight);
  double previous = t.full_turn;
  for (double deg : {10.0, 20.0, 30.0, 40.0}) {
    m.chassis.max_articulation = deg * kPi / 180;
    const double now = ComputeTippingLoad(m, MachineMassModel(m)).full_turn;
    EXPECT_LE(now, previous + 1e-9) << deg;  // turning never steadies it
    previous = now;
  }
}

TEST(SpecSheet, TurningRadiusIsWhereTheAxleLinesMeet) {
  const MachineDescription m = PaperLoader();
  const TurningRadius r = ComputeTurningRadius(m);
  // Rear frame along x, rear axle at (−1.5, 0), front frame turned by γ at the hinge (0, 0).
  const double g = 40 * kPi / 180;
  const Eigen::Vector2d front_axis(std::cos(g), std::sin(g));
  const Eigen::Vector2d front = 1.5 * front_axis;
  // O = (−1.5, y) with (front − O) ⟂ front_axis.
  const double y = (front.x() + 1.5) * front_axis.x() / front_axis.y() + front.y();
  const Eigen::Vector2d o(-1.5, y);
  EXPECT_NEAR(r.front_axle_centre, (front - o).norm(), 1e-12);
  EXPECT_NEAR(std::abs(y), (front - o).norm(), 1e-12);  // equal hinge distances: equal radii
  EXPECT_NEAR(r.tyre_width, 0.37 * 1.4, 1e-12);
  EXPECT_TRUE(r.tyre_width_assumed);
  EXPECT_NEAR(r.outside_tyre, r.front_axle_centre + 1.0 + 0.37 * 0.7, 1e-12);
  EXPECT_NEAR(r.bucket_corner, std::hypot(r.front_axle_centre + 1.25, r.bucket_ahead_of_axle),
              1e-12);
  EXPECT_GT(r.bucket_corner, r.outside_tyre);
}

TEST(SpecSheet, HeapedCapacityOfABoxIsStruckPlusAHipRoof) {
  MachineDescription m = PaperLoader();
  // A box 1 m long, 0.5 m deep, opening up: cutting edge at the top front, back top last.
  m.bucket.profile = {{1.0, 0.5}, {1.0, 0.0}, {0.0, 0.0}, {0.0, 0.5}};
  m.bucket.width = 2.0;
  const HeapedCapacity c = ComputeHeapedCapacity(m);
  EXPECT_NEAR(c.strike_length, 1.0, 1e-12);
  EXPECT_NEAR(c.struck, 1.0 * 0.5 * 2.0, 1e-12);
  // Ridge height b/4 at 2:1: a prism over W − b plus the two end halves of a square pyramid.
  const double h = 0.25;
  const double hip = 0.5 * 1.0 * h * (2.0 - 1.0) + 1.0 * 1.0 * h / 3;
  EXPECT_NEAR(c.heap, hip, 1e-12);
  EXPECT_NEAR(c.heaped, 1.0 + hip, 1e-12);
}

TEST(SpecSheet, HeapedCapacityOfATrapezoidMatchesTheHandFormula) {
  MachineDescription m = PaperLoader();
  // Strike line 1.2 m at the top, floor 0.6 m, depth 0.6 m.
  m.bucket.profile = {{1.2, 0.6}, {0.9, 0.0}, {0.3, 0.0}, {0.0, 0.6}};
  m.bucket.width = 3.0;
  const HeapedCapacity c = ComputeHeapedCapacity(m);
  const double area = (1.2 + 0.6) / 2 * 0.6, b = 1.2, w = 3.0;
  EXPECT_NEAR(c.struck_area, area, 1e-12);
  EXPECT_NEAR(c.heaped, area * w + w * b * b / 8 - b * b * b / 24, 1e-12);
}

// SAE J732 / ISO 7131: the 45° is the bucket floor's (its longest flat inside section), boom at
// full lift; clearance to the cutting edge tip, reach from the front of the tyres. The paper
// loader's floor is tilted 15° up towards the tip against the pin-to-edge line, so the edge line
// dumps 60° down and a 45° edge line (the definition before issue 39) would read 0.26 m higher.
TEST(MachineSummary, DumpIsTakenWithTheBucketFloor45DegreesDown) {
  MachineDescription m = PaperLoader();
  const double beta = 15 * kPi / 180;
  const Eigen::Vector2d tip(1.2, 0.0);
  const Eigen::Vector2d heel = tip - 0.8 * Eigen::Vector2d(std::cos(beta), std::sin(beta));
  m.bucket.profile = {tip, heel, {-0.1, 0.3}, {0.1, 0.9}};
  m.links[1].joint_min = -130 * kPi / 180;
  const MachineSummary s = Summarize(m);
  ASSERT_TRUE(s.dump_pose_reachable);
  const double q1 = 50 * kPi / 180, phi2 = -45 * kPi / 180 - beta;
  EXPECT_NEAR(s.dump_pose[0], q1, 1e-12);
  EXPECT_NEAR(s.dump_pose[1], phi2 - q1, 1e-12);
  EXPECT_NEAR(s.dump_floor_to_edge_line, beta, 1e-12);
  EXPECT_NEAR(s.dump_clearance, 2.0 + 3.0 * std::sin(q1) + 1.2 * std::sin(phi2), 1e-9);
  EXPECT_NEAR(s.dump_reach, 1.0 + 3.0 * std::cos(q1) + 1.2 * std::cos(phi2) - (1.5 + 0.7), 1e-9);
  // The floor, through the model's frames, is 45° down and the tip is the bucket's lowest point.
  const InterpretedModel model(m);
  std::vector<V2<double>> origins;
  std::vector<double> angles;
  model.LinkFrames(s.dump_pose.data(), origins, angles);
  const V2<double> floor = internal::Rotate(angles[1], Eigen::Vector2d(tip - heel));
  EXPECT_NEAR(std::atan2(floor.z, floor.x), -kPi / 4, 1e-12);
  for (const Eigen::Vector2d& p : m.bucket.profile) {
    EXPECT_GE(m.arm_pivot.y() + (origins[1] + internal::Rotate(angles[1], p)).z,
              s.dump_clearance - 1e-12);
  }
  // The old definition's figure is higher by l2 (sin(45° + β) − sin 45°).
  EXPECT_NEAR(2.0 + 3.0 * std::sin(q1) - 1.2 * std::sin(kPi / 4) - s.dump_clearance,
              1.2 * (std::sin(kPi / 4 + beta) - std::sin(kPi / 4)), 1e-9);
}

TEST(MachineSummary, DumpBeyondTheBucketRangeIsNotReachableAndSaysHowFarTheFloorGets) {
  MachineDescription m = PaperLoader();    // floor along the pin-to-edge line
  m.links[1].joint_min = -80 * kPi / 180;  // at full lift the floor gets to 30° down only
  const MachineSummary s = Summarize(m);
  EXPECT_FALSE(s.dump_pose_reachable);
  EXPECT_NEAR(s.dump_floor_at_limit, -30 * kPi / 180, 1e-12);
}

// The reachable window's ends are where the cylinder is at one of its ends (or a joint limit
// when searched within them).
TEST(SpecSheet, ReachableWindowEndsAtTheCylinderEnds) {
  MachineDescription m = PaperLoader();
  Actuator& tilt = m.hydraulics.actuators[1];
  const InterpretedModel model(m);
  std::vector<double> q = {0.2, 0.0};
  q[1] = -20 * kPi / 180;
  const double mid_length = model.CylinderLength(1, q.data());
  tilt.retracted_length = mid_length - 0.10;  // a short stroke around the pose
  tilt.stroke = 0.25;
  const JointWindow w = ReachableJointWindow(m, 1, q.data(), kPi / 2);
  ASSERT_FALSE(w.empty);
  EXPECT_LT(w.min, q[1]);
  EXPECT_GT(w.max, q[1]);
  const InterpretedModel changed(m);
  std::vector<double> at = q;
  std::vector<double> ends;
  for (double angle : {w.min, w.max}) {
    at[1] = angle;
    ends.push_back(changed.CylinderLength(1, at.data()));
  }
  const double shortest = std::min(ends[0], ends[1]), longest = std::max(ends[0], ends[1]);
  EXPECT_NEAR(shortest, tilt.retracted_length, 1e-6);
  EXPECT_NEAR(longest, tilt.retracted_length + tilt.stroke, 1e-6);
  // Within the limits only: the window is clipped to them.
  const JointWindow clipped = ReachableJointWindow(m, 1, q.data());
  EXPECT_GE(clipped.min, m.links[1].joint_min - 1e-12);
  EXPECT_LE(clipped.max, m.links[1].joint_max + 1e-12);
  EXPECT_FALSE(CylinderMovesWithEarlierJoints(m, 1));  // pinned to the boom
}

TEST(SpecSheet, ShippedLoadersGiveSpecSheetMagnitudes) {
  for (const char* name : {"xcmg_968ev", "sdlg_l955he"}) {
    const std::string models = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";
    const MachineDescription m = LoadMachineDescription(ResolveMachineDescription(name, models));
    const SpecSheet s = ComputeSpecSheet(m);
    // A 17–21 t loader: breakout 100–250 kN published (these descriptions' estimated Z-bar
    // gives more by tilt: see the report), tipping 8–16 t, turning 5.5–7.5 m.
    EXPECT_GT(s.breakout.by_tilt, 100e3) << name;
    EXPECT_LT(s.breakout.by_tilt, 450e3) << name;
    EXPECT_GT(s.breakout.by_lift, 100e3) << name;
    EXPECT_LT(s.breakout.by_lift, 300e3) << name;
    EXPECT_LT(std::abs(s.breakout.p_base_tip.y()), 0.01) << name;
    EXPECT_GT(s.tipping.straight, 8000) << name;
    EXPECT_LT(s.tipping.straight, 16000) << name;
    EXPECT_LT(s.tipping.full_turn, s.tipping.straight) << name;
    EXPECT_GT(s.turning.outside_tyre, 5.5) << name;
    EXPECT_LT(s.turning.bucket_corner, 7.5) << name;
    EXPECT_NEAR(s.capacity.heaped, m.bucket.rated_capacity, 0.25 * m.bucket.rated_capacity) << name;
  }
}

}  // namespace
}  // namespace autoshovel::model
