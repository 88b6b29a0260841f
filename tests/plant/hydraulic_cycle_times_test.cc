// Spec-sheet hydraulic cycle times on the plant (runtime/plant/hydraulic_cycle_times.h): each
// motion at full valve must take about the cylinder's swept volume over the valve's rated flow
// (the load-sensing margin equals the rated drop, so a full spool passes rated flow), plus the
// command-to-motion delay.
#include "runtime/plant/hydraulic_cycle_times.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "runtime/machines/interpreted_functions.h"
#include "runtime/model/interpreted_model.h"
#include "tests/plant/plant_test_support.h"

namespace autoshovel::plant {
namespace {

// Oil volume that moves the cylinder from pose `from` to pose `to`, through the chamber that
// the motion fills (cap side when it extends) [m³].
double SweptVolume(const model::MachineDescription& m, int actuator,
                   const std::vector<double>& from, const std::vector<double>& to) {
  const model::InterpretedModel model(m);
  const model::Actuator& a = m.hydraulics.actuators[actuator];
  const double change =
      model.CylinderLength(actuator, to.data()) - model.CylinderLength(actuator, from.data());
  const double cap = a.count * std::numbers::pi / 4 * a.bore * a.bore;
  const double annulus = a.count * std::numbers::pi / 4 * (a.bore * a.bore - a.rod * a.rod);
  return std::abs(change) * (change > 0 ? cap : annulus);
}

TEST(HydraulicCycleTimes, StartIsTheLowestBoomAngleWithTheBucketAboveGround) {
  const model::MachineDescription m = testing::LoadMachine("xcmg_968ev");
  const double q0 = GroundBoomAngle(m);
  EXPECT_GE(q0, m.links[0].joint_min);
  EXPECT_LT(q0, m.links[0].joint_max);
  const model::InterpretedModel model(m);
  const auto lowest = [&](double boom) {
    std::vector<model::V2<double>> origins;
    std::vector<double> angles;
    const double q[2] = {boom, m.links[1].joint_max};
    model.LinkFrames(q, origins, angles);
    double z = 1e300;
    for (const auto& p : m.bucket.profile) {
      z = std::min(z, m.arm_pivot.y() + (origins[1] + model::internal::Rotate(angles[1], p)).z);
    }
    return z;
  };
  if (q0 > m.links[0].joint_min) {
    EXPECT_NEAR(lowest(q0), 0.0, 1e-6);
    EXPECT_LT(lowest(q0 - 1e-3), 0.0);
  }
}

TEST(HydraulicCycleTimes, EachMotionTakesSweptVolumeOverRatedFlowPlusItsDelay) {
  for (const char* name : {"xcmg_968ev", "sdlg_l955he"}) {
    const model::MachineDescription m = testing::LoadMachine(name);
    const HydraulicCycleTimes t = SimulateHydraulicCycleTimes(m, testing::Functions(name));
    ASSERT_GT(t.raise, 0) << name;
    ASSERT_GT(t.dump, 0) << name;
    ASSERT_GT(t.lower, 0) << name;
    const int boom = m.ActuatorOfJoint(0), tilt = m.ActuatorOfJoint(1);
    const model::Valve& boom_valve = m.hydraulics.actuators[boom].valve;
    const model::Valve& tilt_valve = m.hydraulics.actuators[tilt].valve;
    const double tol = CycleTimeOptions{}.end_tolerance;
    const std::vector<double> start = t.start_pose;
    const std::vector<double> top = {m.links[0].joint_max - tol, m.links[1].joint_max};
    const std::vector<double> dumped = {m.links[0].joint_max, m.links[1].joint_min + tol};
    const std::vector<double> top_dumped = {m.links[0].joint_max, m.links[1].joint_min};
    const std::vector<double> bottom_dumped = {start[0] + tol, m.links[1].joint_min};
    // Delay to motion: transport delay plus about two spool time constants to open.
    const auto expected = [](double volume, const model::Valve& v) {
      return v.transport_delay + 2 * v.spool_time_constant + volume / v.rated_flow;
    };
    const double raise = expected(SweptVolume(m, boom, start, top), boom_valve);
    const double dump = expected(SweptVolume(m, tilt, top, dumped), tilt_valve);
    const double lower = expected(SweptVolume(m, boom, top_dumped, bottom_dumped), boom_valve);
    EXPECT_NEAR(t.raise, raise, 0.05 * raise) << name;
    // Dumping, the bucket's weight overruns the tilt cylinder a little (the meter-out side
    // passes more than the compensated inflow): 6 % faster than the inflow alone.
    EXPECT_NEAR(t.dump, dump, 0.08 * dump) << name;
    EXPECT_NEAR(t.lower, lower, 0.05 * lower) << name;
    // Sure of magnitude: not an instant, not stuck.
    EXPECT_GT(t.raise, 3.0) << name;
    EXPECT_LT(t.total(), 30.0) << name;
  }
}

TEST(HydraulicCycleTimes, RaiseMotionScalesWithTheBoomCylindersArea) {
  // The two shipped loaders share their linkage and boom valve; the L955's boom cylinders are
  // 160 mm against the XC968's 180 mm, so at the same flow its boom rises (160/180)² as long.
  const model::MachineDescription big = testing::LoadMachine("xcmg_968ev");
  const model::MachineDescription small = testing::LoadMachine("sdlg_l955he");
  const HydraulicCycleTimes t_big = SimulateHydraulicCycleTimes(big, testing::Functions(big.name));
  const HydraulicCycleTimes t_small =
      SimulateHydraulicCycleTimes(small, testing::Functions(small.name));
  const auto motion = [](const model::MachineDescription& m, const HydraulicCycleTimes& t) {
    const model::Valve& v = m.hydraulics.actuators[m.ActuatorOfJoint(0)].valve;
    return t.raise - v.transport_delay - 2 * v.spool_time_constant;
  };
  const auto volume = [](const model::MachineDescription& m, const HydraulicCycleTimes& t) {
    const std::vector<double> top = {m.links[0].joint_max, m.links[1].joint_max};
    return SweptVolume(m, m.ActuatorOfJoint(0), t.start_pose, top);
  };
  EXPECT_NEAR(motion(small, t_small) / motion(big, t_big),
              volume(small, t_small) / volume(big, t_big), 0.05);
}

// A tilt cylinder on the front frame (Z-bar, parallel lift) slides its window over the bucket
// joint with the boom; the plant stops the bucket only where the cylinder ends. The shipped
// Hyundai descriptions end it at the dumped limit at full lift, so the bucket stops there and the
// boom lowers (the first HL740TM-7 left 0.2 m of stroke past that limit: the bucket swung 60°
// through it, the linkage wound towards its toggle and the lowering never finished). Run on the
// interpreted functions, so that it holds whatever code was generated.
TEST(HydraulicCycleTimes, FrameMountedTiltCylinderEndHoldsTheDumpedLimit) {
  constexpr double kDeg = std::numbers::pi / 180;
  for (const char* name : {"hyundai_hl740_9s", "hyundai_hl740tm_7"}) {
    const model::MachineDescription m = testing::LoadMachine(name);
    const HydraulicCycleTimes t = SimulateHydraulicCycleTimes(m, machines::InterpretedFunctions(m));
    EXPECT_GT(t.raise, 3.0) << name;
    EXPECT_GT(t.dump, 0.5) << name;
    EXPECT_GT(t.lower, 1.0) << name;
    // Some degrees of rebound off the end stop (5.4° on the HL740-9S, whose lever arm is 0.12 m/rad
    // at the limit and falls off past it), against 60–100° where no cylinder end holds the limit.
    EXPECT_LT(t.bucket_past_dump_limit, 8 * kDeg) << name;

    // 0.1 m more stroke at the retracted end: nothing holds the limit, the bucket passes it.
    model::MachineDescription longer = m;
    model::Actuator& tilt = longer.hydraulics.actuators[longer.ActuatorOfJoint(1)];
    tilt.retracted_length -= 0.1;
    tilt.stroke += 0.1;
    longer.sha256 = "longer-stroke-" + m.sha256;
    const HydraulicCycleTimes u =
        SimulateHydraulicCycleTimes(longer, machines::InterpretedFunctions(longer));
    EXPECT_GT(u.bucket_past_dump_limit, 12 * kDeg) << name;
  }
}

}  // namespace
}  // namespace autoshovel::plant
