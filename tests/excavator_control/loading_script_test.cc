// The rule scripts of seed §4.4, Fig. 14, on hand-made states: one active rule per joint, rules
// taken in order and at most one per evaluation, conditions on the state, a stop for NaN.
#include "runtime/control/excavator/loading_script.h"

#include <gtest/gtest.h>

#include <cmath>

namespace autoshovel::control {
namespace {

using J = ExcavatorJoint;

ConditionTerm Above(J joint, double value) { return {joint, Comparison::kAbove, value, 0}; }
ConditionTerm Below(J joint, double value) { return {joint, Comparison::kBelow, value, 0}; }
ConditionTerm Near(J joint, double value, double tolerance) {
  return {joint, Comparison::kNear, value, tolerance};
}

/// A small script in the shape of Fig. 14 (numbers in radians, made up).
std::array<JointScript, kNumExcavatorJoints> Scripts() {
  std::array<JointScript, kNumExcavatorJoints> s;
  s[JointIndex(J::kBoom)] = {J::kBoom,
                             {{"raise", {}, 0.8},
                              {"hold", {Above(J::kBucket, 0.3)}, 0.8},
                              {"lower", {Below(J::kSwing, 1.0)}, 0.3}}};
  s[JointIndex(J::kStick)] = {J::kStick,
                              {{"wait", {}, -1.8}, {"out", {Above(J::kSwing, 0.5)}, -1.4}}};
  s[JointIndex(J::kBucket)] = {
      J::kBucket,
      {{"curl", {}, -2.4}, {"open", {Above(J::kSwing, 1.4), Near(J::kStick, -1.4, 0.05)}, 0.4}}};
  s[JointIndex(J::kSwing)] = {J::kSwing,
                              {{"wait", {}, 0.0},
                               {"to truck", {Above(J::kBoom, 0.4)}, 1.6},
                               {"to dig", {Above(J::kBucket, 0.3)}, 0.0},
                               {"dig", {Near(J::kSwing, 0.0, 0.03)}, 0.0}}};
  return s;
}

JointVector Q(double boom, double stick, double bucket, double swing) {
  return JointVector(boom, stick, bucket, swing);
}

TEST(LoadingScript, StartsOnTheFirstRulesAndSendsTheirCommands) {
  LoadingScript script(Scripts());
  const ScriptOutput out = script.Step(Q(0.1, -1.8, -2.4, 0.0));
  EXPECT_FALSE(out.command.stop);
  EXPECT_EQ(out.command.position, JointVector(0.8, -1.8, -2.4, 0.0));
  for (int rule : out.active_rule) EXPECT_EQ(rule, 0);
}

TEST(LoadingScript, RulesAreTakenInOrderOnePerEvaluation) {
  LoadingScript script(Scripts());
  // Every swing condition holds at once (boom up, bucket open, swing at 0): the swing still
  // moves one rule per evaluation, never skipping one.
  const JointVector q = Q(0.5, -1.8, 0.5, 0.0);
  EXPECT_EQ(script.Step(q).active_rule[JointIndex(J::kSwing)], 1);
  EXPECT_EQ(script.Step(q).active_rule[JointIndex(J::kSwing)], 2);
  EXPECT_EQ(script.Step(q).active_rule[JointIndex(J::kSwing)], 3);
  EXPECT_EQ(script.Step(q).active_rule[JointIndex(J::kSwing)], 3);
  // The boom's "lower" (swing < 1.0) held from the start but is reached only after "hold".
  EXPECT_EQ(script.active_rule(J::kBoom), 2);
  EXPECT_EQ(script.Commands()[JointIndex(J::kBoom)], 0.3);
}

TEST(LoadingScript, ALaterRuleWaitsForItsOwnCondition) {
  LoadingScript script(Scripts());
  // The boom's second rule needs the bucket open; swinging far does not move it on.
  script.Step(Q(0.5, -1.8, -2.4, 0.0));
  for (double swing = 0.1; swing < 1.35; swing += 0.1) script.Step(Q(0.8, -1.4, -2.4, swing));
  EXPECT_EQ(script.active_rule(J::kBoom), 0);
  EXPECT_EQ(script.active_rule(J::kSwing), 1);
  EXPECT_EQ(script.active_rule(J::kStick), 1);
  // Both terms of the bucket's "open" must hold: the stick 0.1 rad off spill keeps it curled.
  script.Step(Q(0.8, -1.5, -2.4, 1.55));
  EXPECT_EQ(script.active_rule(J::kBucket), 0);
  const ScriptOutput out = script.Step(Q(0.8, -1.42, -2.4, 1.55));
  EXPECT_EQ(out.active_rule[JointIndex(J::kBucket)], 1);
  EXPECT_EQ(out.command.position[JointIndex(J::kBucket)], 0.4);
  EXPECT_FALSE(script.AtFinalRules());
}

TEST(LoadingScript, FinishedOnlyOnTheLastRulesAtRestAtTheirCommands) {
  LoadingScript script(Scripts());
  ExcavatorState state;
  state.q = Q(0.3, -1.4, 0.4, 0.0);
  EXPECT_FALSE(script.Finished(state, 0.03, 0.03));
  for (int i = 0; i < 5; ++i) script.Step(Q(0.5, -1.4, 0.5, 1.6));
  for (int i = 0; i < 5; ++i) script.Step(Q(0.5, -1.4, 0.5, 0.0));
  ASSERT_TRUE(script.AtFinalRules());
  EXPECT_TRUE(script.Finished(state, 0.03, 0.03));
  state.qd[3] = 0.1;  // still swinging
  EXPECT_FALSE(script.Finished(state, 0.03, 0.03));
  state.qd[3] = 0;
  state.q[0] = 0.4;  // boom not down yet
  EXPECT_FALSE(script.Finished(state, 0.03, 0.03));
  state.q[0] = std::nan("");
  EXPECT_FALSE(script.Finished(state, 0.03, 0.03));
}

TEST(LoadingScript, ANonFiniteStateStopsWithoutTouchingTheRules) {
  LoadingScript script(Scripts());
  script.Step(Q(0.5, -1.8, -2.4, 0.0));
  const ScriptOutput out = script.Step(Q(0.5, -1.8, std::nan(""), 0.0));
  EXPECT_TRUE(out.command.stop);
  EXPECT_TRUE(out.command.position.allFinite());
  EXPECT_NE(out.reason.find("bucket"), std::string::npos) << out.reason;
  EXPECT_EQ(script.active_rule(J::kSwing), 1);
}

TEST(LoadingScript, RejectsMalformedScriptsNamingTheJoint) {
  auto expect_throw = [](std::array<JointScript, kNumExcavatorJoints> s, const char* word) {
    try {
      LoadingScript script(std::move(s));
      ADD_FAILURE() << "accepted";
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find(word), std::string::npos) << error.what();
    }
  };
  auto s = Scripts();
  s[JointIndex(J::kStick)].rules[0].condition.push_back(Above(J::kSwing, 0));
  expect_throw(s, "stick");
  s = Scripts();
  s[JointIndex(J::kBoom)].rules[1].condition.clear();
  expect_throw(s, "boom");
  s = Scripts();
  s[JointIndex(J::kSwing)].rules[2].command = std::nan("");
  expect_throw(s, "swing");
  s = Scripts();
  s[JointIndex(J::kBucket)].rules[1].condition[1].tolerance = 0;
  expect_throw(s, "bucket");
  s = Scripts();
  std::swap(s[0], s[1]);
  expect_throw(s, "boom");
  s = Scripts();
  s[JointIndex(J::kStick)].rules.clear();
  expect_throw(s, "stick");
}

TEST(LoadingScript, DescribesItselfInTheOrderOfFigure14) {
  const std::string text = LoadingScript(Scripts()).Describe();
  EXPECT_LT(text.find("Joint: swing"), text.find("Joint: boom"));
  EXPECT_LT(text.find("Joint: boom"), text.find("Joint: stick"));
  EXPECT_LT(text.find("Joint: stick"), text.find("Joint: bucket"));
  EXPECT_NE(text.find("2) if boom > 22.9°, to truck: swing = 91.7°"), std::string::npos) << text;
  EXPECT_NE(text.find("if swing > 80.2° and stick = -80.2° ± 2.9°"), std::string::npos) << text;
}

}  // namespace
}  // namespace autoshovel::control
