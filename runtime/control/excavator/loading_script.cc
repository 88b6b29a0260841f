#include "runtime/control/excavator/loading_script.h"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <utility>

namespace autoshovel::control {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

std::string Degrees(double rad) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.1f°", rad * kDeg);
  return buffer;
}

}  // namespace

bool ConditionTerm::Holds(const JointVector& q) const {
  const double x = q[JointIndex(joint)];
  switch (comparison) {
    case Comparison::kAbove:
      return x > value;
    case Comparison::kBelow:
      return x < value;
    case Comparison::kNear:
      return std::abs(x - value) <= tolerance;
  }
  return false;
}

std::string ConditionTerm::ToString() const {
  const std::string name(JointName(joint));
  switch (comparison) {
    case Comparison::kAbove:
      return name + " > " + Degrees(value);
    case Comparison::kBelow:
      return name + " < " + Degrees(value);
    case Comparison::kNear:
      return name + " = " + Degrees(value) + " ± " + Degrees(tolerance);
  }
  return "?";
}

LoadingScript::LoadingScript(std::array<JointScript, kNumExcavatorJoints> scripts)
    : scripts_(std::move(scripts)) {
  for (ExcavatorJoint joint : kAllExcavatorJoints) {
    const JointScript& s = scripts_[JointIndex(joint)];
    const std::string name(JointName(joint));
    if (s.joint != joint) {
      throw std::invalid_argument("LoadingScript: script " + std::to_string(JointIndex(joint)) +
                                  " must be the " + name + "'s");
    }
    if (s.rules.empty()) throw std::invalid_argument("LoadingScript: " + name + " has no rules");
    for (std::size_t r = 0; r < s.rules.size(); ++r) {
      const ScriptRule& rule = s.rules[r];
      const std::string where = "LoadingScript: " + name + " rule " + std::to_string(r + 1);
      if (r == 0 && !rule.condition.empty()) {
        throw std::invalid_argument(where +
                                    ": the first rule starts with the script, no condition");
      }
      if (r > 0 && rule.condition.empty()) {
        throw std::invalid_argument(where + ": needs a condition");
      }
      if (!std::isfinite(rule.command)) throw std::invalid_argument(where + ": command not finite");
      for (const ConditionTerm& term : rule.condition) {
        if (!std::isfinite(term.value) || !std::isfinite(term.tolerance) || term.tolerance < 0 ||
            (term.comparison == Comparison::kNear && !(term.tolerance > 0))) {
          throw std::invalid_argument(where + ": condition value or tolerance invalid");
        }
      }
    }
  }
}

ScriptOutput LoadingScript::Step(const JointVector& q) {
  ScriptOutput out;
  const int bad = FirstNonFinite(q);
  if (bad >= 0) {
    out.command.stop = true;
    out.command.position = Commands();
    out.active_rule = active_;
    out.reason = "non-finite " + std::string(JointName(kAllExcavatorJoints[bad])) +
                 " position in the state: stop";
    return out;
  }
  for (int j = 0; j < kNumExcavatorJoints; ++j) {
    const std::vector<ScriptRule>& rules = scripts_[j].rules;
    const int next = active_[j] + 1;
    if (next >= static_cast<int>(rules.size())) continue;
    bool holds = true;
    for (const ConditionTerm& term : rules[next].condition) holds = holds && term.Holds(q);
    if (holds) active_[j] = next;
  }
  out.command.position = Commands();
  out.active_rule = active_;
  return out;
}

JointVector LoadingScript::Commands() const {
  JointVector c;
  for (int j = 0; j < kNumExcavatorJoints; ++j) c[j] = scripts_[j].rules[active_[j]].command;
  return c;
}

bool LoadingScript::AtFinalRules() const {
  for (int j = 0; j < kNumExcavatorJoints; ++j) {
    if (active_[j] + 1 != static_cast<int>(scripts_[j].rules.size())) return false;
  }
  return true;
}

bool LoadingScript::Finished(const ExcavatorState& state, double position_tolerance,
                             double velocity_tolerance) const {
  if (!AtFinalRules()) return false;
  const JointVector c = Commands();
  for (int j = 0; j < kNumExcavatorJoints; ++j) {
    if (!(std::abs(state.q[j] - c[j]) <= position_tolerance)) return false;
    if (!(std::abs(state.qd[j]) <= velocity_tolerance)) return false;
  }
  return true;
}

std::string LoadingScript::Describe() const {
  std::string out;
  constexpr ExcavatorJoint kSeedOrder[] = {ExcavatorJoint::kSwing, ExcavatorJoint::kBoom,
                                           ExcavatorJoint::kStick, ExcavatorJoint::kBucket};
  for (ExcavatorJoint joint : kSeedOrder) {
    const JointScript& s = scripts_[JointIndex(joint)];
    out += "Joint: " + std::string(JointName(joint)) + "\n";
    for (std::size_t r = 0; r < s.rules.size(); ++r) {
      const ScriptRule& rule = s.rules[r];
      std::string lhs = r == 0 ? "when digging finishes" : "if ";
      for (std::size_t t = 0; t < rule.condition.size(); ++t) {
        lhs += (t > 0 ? " and " : "") + rule.condition[t].ToString();
      }
      out += "  " + std::to_string(r + 1) + ") " + lhs + ", " + rule.action + ": " +
             std::string(JointName(joint)) + " = " + Degrees(rule.command) + "\n";
    }
  }
  return out;
}

}  // namespace autoshovel::control
