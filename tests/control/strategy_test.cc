// Algorithm 3, triggers and the atomic-action sequences of the strategies (seed §6.2, §7.4.2).
#include <gtest/gtest.h>

#include <cmath>

#include "runtime/control/scoop_triggers.h"
#include "runtime/control/scooping_strategies.h"
#include "runtime/control/strategy_selection.h"

namespace autoshovel::control {
namespace {

TEST(Algorithm3, Cases) {
  const double vt = 3.0;
  // Line 3: no material yet, keep crowding whatever else holds.
  EXPECT_EQ(SelectStrategy({.v1 = 0, .v2 = 5, .target_volume = vt, .stopped = true}),
            ScoopDecision::kKeepCrowding);
  // Lines 7–11: the target reached; the material decides.
  EXPECT_EQ(SelectStrategy({.v1 = 1.5, .v2 = 1.5, .target_volume = vt, .difficult = false}),
            ScoopDecision::kJustInOut);
  EXPECT_EQ(SelectStrategy({.v1 = 1.5, .v2 = 1.5, .target_volume = vt, .difficult = true}),
            ScoopDecision::kStairway);
  // Line 7 wins over line 13 for an easy material even when stopped.
  EXPECT_EQ(SelectStrategy({.v1 = 2, .v2 = 1, .target_volume = vt, .stopped = true}),
            ScoopDecision::kJustInOut);
  // Lines 13–14: short of the target and stopped: "Stairway" whatever the material.
  EXPECT_EQ(SelectStrategy({.v1 = 1, .v2 = 0.5, .target_volume = vt, .stopped = true}),
            ScoopDecision::kStairway);
  // Short of the target and moving: crowd on.
  EXPECT_EQ(SelectStrategy({.v1 = 1, .v2 = 0.5, .target_volume = vt, .difficult = true}),
            ScoopDecision::kKeepCrowding);
  // A NaN V2 never reaches the target.
  EXPECT_EQ(SelectStrategy({.v1 = 1, .v2 = std::nan(""), .target_volume = vt}),
            ScoopDecision::kKeepCrowding);
}

TEST(ScoopTriggers, Thresholds) {
  PredictedVolumeTrigger predicted(3.0);
  EXPECT_FALSE(predicted.Fire({.v1 = 1.0, .v2 = 1.9}));
  EXPECT_TRUE(predicted.Fire({.v1 = 1.0, .v2 = 2.0}));
  EXPECT_FALSE(predicted.Fire({.v1 = 0.0, .v2 = 3.0}));  // not in the pile
  EXPECT_FALSE(predicted.Fire({.v1 = 1.0, .v2 = std::nan("")}));
  // With the model's intake factor κ: κ·(V1 + V2) ≥ V_t.
  EXPECT_TRUE(predicted.Fire({.v1 = 1.0, .v2 = 1.5, .intake_factor = 1.2}));
  EXPECT_FALSE(predicted.Fire({.v1 = 1.0, .v2 = 1.4, .intake_factor = 1.2}));
  EXPECT_FALSE(predicted.Fire({.v1 = 1.0, .v2 = 2.5, .intake_factor = 0.0}));
  PerceptionTrigger perception(3.0);
  EXPECT_FALSE(perception.Fire({.v1 = 1.0, .v2 = 2.5}));  // V2 is not read
  EXPECT_TRUE(perception.Fire({.v1 = 3.0}));
  BoomPressureTrigger pressure(150e5, 2);
  EXPECT_FALSE(pressure.Fire({.boom_pressure = 160e5}));
  EXPECT_FALSE(pressure.Fire({.boom_pressure = 140e5}));  // a spike does not count
  EXPECT_FALSE(pressure.Fire({.boom_pressure = 160e5}));
  EXPECT_TRUE(pressure.Fire({.boom_pressure = 151e5}));
  EXPECT_THROW(PredictedVolumeTrigger(0.0), std::invalid_argument);
  EXPECT_THROW(BoomPressureTrigger(1e7, 0), std::invalid_argument);
}

const ArmLimits kLimits{.boom_max = 0.7, .bucket_max = 1.0};

std::vector<AtomicAction> Drain(ScoopSequencer& sequencer, ArmTargets targets,
                                const std::vector<double>& volumes, double vt) {
  std::vector<AtomicAction> out;
  for (std::size_t i = 0; i < 20; ++i) {
    const double volume = volumes.empty() ? 0 : volumes[std::min(i, volumes.size() - 1)];
    const std::optional<AtomicAction> a = sequencer.Next(targets, volume, vt);
    if (!a) break;
    targets = TargetsAfter(*a, targets, kLimits);
    out.push_back(*a);
  }
  return out;
}

TEST(ScoopingStrategies, JustInAndOutIsOneRetractAndOneLift) {
  ScoopSequencer s(ScoopStrategy::kJustInOut, StrategyParameters{}, kLimits);
  const std::vector<AtomicAction> a = Drain(s, {.boom = -0.3, .bucket = 0.1}, {}, 3.0);
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a[0].kind, AtomicKind::kRetractBucket);
  EXPECT_NEAR(a[0].travel, 0.9, 1e-12);  // to racked back
  EXPECT_EQ(a[1].kind, AtomicKind::kLiftBoom);
  EXPECT_EQ(s.actions(), 2);
  EXPECT_EQ(s.steps(), 0);
}

TEST(ScoopingStrategies, FixedStairwayMakesItsStepsWhateverTheVolume) {
  StrategyParameters p;
  p.fixed_steps = 3;
  ScoopSequencer s(ScoopStrategy::kStairwayFixed, p, kLimits);
  const std::vector<AtomicAction> a = Drain(s, {.boom = -0.3, .bucket = 0.0}, {10.0}, 3.0);
  EXPECT_EQ(s.steps(), 3);
  // 3 × (lift, retract) then the rack-back remainder (0.1 rad) and the exit lift.
  ASSERT_EQ(a.size(), 8u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(a[2 * k].kind, AtomicKind::kLiftBoom);
    EXPECT_EQ(a[2 * k + 1].kind, AtomicKind::kRetractBucket);
    EXPECT_DOUBLE_EQ(a[2 * k + 1].pause, p.step_pause);
  }
  EXPECT_EQ(a[6].kind, AtomicKind::kRetractBucket);
  EXPECT_EQ(a[7].kind, AtomicKind::kLiftBoom);
  EXPECT_DOUBLE_EQ(a[7].travel, p.exit_boom_lift);
}

TEST(ScoopingStrategies, AdaptiveStairwayStopsOnVolumeFeedback) {
  // Volume checked between steps: below target after step 1, at target after step 2.
  ScoopSequencer s(ScoopStrategy::kStairway, StrategyParameters{}, kLimits);
  // Next() is called before each action: [step1 lift, step1 retract, check, …].
  const std::vector<AtomicAction> a =
      Drain(s, {.boom = -0.3, .bucket = 0.0}, {0.0, 1.0, 2.0, 2.5, 3.2, 3.2}, 3.0);
  EXPECT_EQ(s.steps(), 2);
  EXPECT_EQ(a.back().kind, AtomicKind::kLiftBoom);
  // One step at least, even when the target is already met.
  ScoopSequencer full(ScoopStrategy::kStairway, StrategyParameters{}, kLimits);
  Drain(full, {.boom = -0.3, .bucket = 0.0}, {5.0}, 3.0);
  EXPECT_EQ(full.steps(), 1);
  // Never beyond max_steps, and never past the racked bucket.
  StrategyParameters p;
  p.step_retract = 0.1;
  ScoopSequencer capped(ScoopStrategy::kStairway, p, kLimits);
  Drain(capped, {.boom = -0.3, .bucket = 0.0}, {0.0}, 3.0);
  EXPECT_EQ(capped.steps(), p.max_steps);
}

TEST(AtomicActions, TargetsAreClippedToTheLimits) {
  const ArmTargets t = TargetsAfter(RetractBucket(2.0), {.boom = 0, .bucket = 0.5}, kLimits);
  EXPECT_DOUBLE_EQ(t.bucket, 1.0);
  EXPECT_DOUBLE_EQ(t.boom, 0.0);
  const ArmTargets u = TargetsAfter(LiftBoom(0.2), {.boom = 0.6, .bucket = 0.5}, kLimits);
  EXPECT_DOUBLE_EQ(u.boom, 0.7);
  EXPECT_THROW(TargetsAfter(LiftBoom(-0.1), t, kLimits), std::invalid_argument);
  EXPECT_THROW(TargetsAfter(LiftBoom(std::nan("")), t, kLimits), std::invalid_argument);
}

}  // namespace
}  // namespace autoshovel::control
