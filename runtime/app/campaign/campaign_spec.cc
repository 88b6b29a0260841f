#include "runtime/app/campaign/campaign_spec.h"

#include <cctype>
#include <cstdio>
#include <stdexcept>

#include "runtime/core/diagnostics.h"
#include "runtime/core/yaml_reader.h"

namespace autoshovel::app {
namespace {

const std::vector<std::string> kPolicies = {"auto", "just_in_out", "stairway", "stairway_fixed"};

// SplitMix64 finaliser: a shift's seed from the campaign's seed and the shift number.
std::uint64_t Mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// The tree in a canonical form that keeps only what a node says: no comments, no layout, no
// flow/block style (which yaml-cpp's emitter would keep); keys in their written order.
void AppendCanonical(const YAML::Node& node, std::string& out) {
  switch (node.Type()) {
    case YAML::NodeType::Scalar: {
      const std::string& text = node.Scalar();
      out += 'S' + std::to_string(text.size()) + ':' + text;
      break;
    }
    case YAML::NodeType::Sequence:
      out += '[';
      for (const YAML::Node& item : node) AppendCanonical(item, out);
      out += ']';
      break;
    case YAML::NodeType::Map:
      out += '{';
      for (const auto& entry : node) {
        AppendCanonical(entry.first, out);
        AppendCanonical(entry.second, out);
      }
      out += '}';
      break;
    default:
      out += '~';  // null or undefined
  }
}

std::string CanonicalYaml(const std::string& path) {
  std::string out;
  AppendCanonical(YAML::LoadFile(path), out);
  return out;
}

}  // namespace

bool SameCampaignContent(const std::string& path_a, const std::string& path_b) {
  try {
    return CanonicalYaml(path_a) == CanonicalYaml(path_b);
  } catch (const YAML::Exception&) {
    return false;
  }
}

control::ScoopPolicy ParseScoopPolicy(const std::string& name) {
  if (name == "auto") return control::ScoopPolicy::kAutoSelection;
  if (name == "just_in_out") return control::ScoopPolicy::kJustInOut;
  if (name == "stairway") return control::ScoopPolicy::kStairway;
  if (name == "stairway_fixed") return control::ScoopPolicy::kStairwayFixed;
  if (name == "optimal") return control::ScoopPolicy::kOptimal;
  throw std::invalid_argument("unknown scooping policy '" + name +
                              "' (auto, just_in_out, stairway, stairway_fixed, optimal)");
}

CampaignSpec LoadCampaignSpec(const std::string& path) {
  core::DiagnosticSink sink;
  const core::YamlFile file(path, sink);
  CampaignSpec spec;
  spec.source_file = path;
  if (file.ok()) {
    core::MapReader root = core::MapReader::Root(file, nullptr);
    spec.name = root.String("name");
    for (const char c : spec.name) {
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) {
        root.Error("name", "use letters, digits, '_' and '-' only (it names the runs), got '" +
                               spec.name + "'");
        break;
      }
    }
    if (root.Has("scenarios")) {
      if (root.Has("scenario")) root.Error("scenario", "give either 'scenario' or 'scenarios'");
      spec.scenarios = root.Strings("scenarios", true);
      for (std::size_t i = 0; i < spec.scenarios.size(); ++i) {
        for (std::size_t j = 0; j < i; ++j) {
          if (spec.scenarios[j] == spec.scenarios[i]) {
            root.Error("scenarios", "scenario '" + spec.scenarios[i] + "' is listed twice");
          }
        }
      }
    } else {
      spec.scenarios = {root.String("scenario")};
    }
    if (!spec.scenarios.empty()) spec.scenario = spec.scenarios.front();
    if (root.Has("machine")) spec.machine = root.String("machine");
    spec.seed = static_cast<std::uint64_t>(root.Integer("seed", 0, 2147483647, 1));
    spec.weeks = root.Integer("weeks", 1, 520);
    spec.shifts_per_week = root.Integer("shifts_per_week", 1, 100);
    spec.cycles_per_shift = root.Integer("cycles_per_shift", 1, 10000);
    spec.policies = root.Strings("policies", true);
    for (std::size_t i = 0; i < spec.policies.size(); ++i) {
      bool known = false;
      for (const std::string& p : kPolicies) known |= p == spec.policies[i];
      bool repeated = false;
      for (std::size_t j = 0; j < i; ++j) repeated |= spec.policies[j] == spec.policies[i];
      if (!known) {
        root.Error("policies", "unknown policy '" + spec.policies[i] +
                                   "' (auto, just_in_out, stairway, stairway_fixed)");
      } else if (repeated) {
        root.Error("policies", "policy '" + spec.policies[i] + "' is listed twice");
      }
    }
    spec.stairway_steps = root.Integer("stairway_steps", 1, 10, 3);
    if (root.Has("trigger"))
      spec.trigger = root.Enum("trigger", {"predicted", "perception", "pressure"});
    if (root.Has("truth_labels"))
      spec.truth_labels = root.Enum("truth_labels", {"true", "false"}) == "true";
    if (root.Has("attack_speed")) {
      spec.attack_speed = root.Number("attack_speed", core::NumberRule::Closed(0.1, 4.0, "m/s"));
    }
    if (root.Has("scoop_deceleration")) {
      spec.scoop_deceleration =
          root.Number("scoop_deceleration", core::NumberRule::Closed(0.05, 5.0, "m/s^2"));
    }
    if (root.Has("predictor")) {
      spec.predictor = root.String("predictor");
      if (spec.predictor.empty()) root.Error("predictor", "empty model name");
    }
    if (root.Has("yard_variation")) {
      spec.yard_variation = root.Number("yard_variation", core::NumberRule::Closed(0.0, 0.9, ""));
    }
    if (root.Has("max_cycle_time_s")) {
      spec.max_cycle_time_s =
          root.Number("max_cycle_time_s", core::NumberRule::Closed(5.0, 3600.0, "s"));
    }
    spec.faults = plant::ReadFaults(root);
    for (core::MapReader& entry : root.MapList("fault_cases", /*required=*/false)) {
      FaultCase c;
      c.name = entry.String("name");
      bool bad_name = c.name.empty();
      for (const char ch : c.name) {
        bad_name |= !(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-');
      }
      if (bad_name) {
        entry.Error("name", "use letters, digits, '_' and '-' only (it names the runs), got '" +
                                c.name + "'");
      }
      for (const FaultCase& earlier : spec.fault_cases) {
        if (earlier.name == c.name)
          entry.Error("name", "fault case '" + c.name + "' is listed twice");
      }
      c.faults = plant::ReadFaults(entry);
      entry.Finish();
      spec.fault_cases.push_back(std::move(c));
    }
    root.Finish();
    if (sink.empty() && spec.cycles() > 10'000'000) {
      root.Error("cycles_per_shift", "the campaign would run " + std::to_string(spec.cycles()) +
                                         " cycles; at most 10 million");
    }
  }
  sink.ThrowIfAny();
  return spec;
}

std::vector<CampaignJob> CampaignJobs(const CampaignSpec& spec) {
  std::vector<CampaignJob> jobs;
  for (int s = 0; s < spec.shifts(); ++s) {
    const int week = s / spec.shifts_per_week + 1, shift = s % spec.shifts_per_week + 1;
    char label[32];
    std::snprintf(label, sizeof label, "w%02ds%02d", week, shift);
    const std::vector<FaultCase> cases =
        spec.fault_cases.empty() ? std::vector<FaultCase>{FaultCase{}} : spec.fault_cases;
    // A spec built in code may give `scenario` alone.
    const std::vector<std::string> scenarios =
        spec.scenarios.empty() ? std::vector<std::string>{spec.scenario} : spec.scenarios;
    // Case-major, so that the fault table (campaign_store.h) lists cases in the spec's order.
    for (const FaultCase& fault_case : cases) {
      for (const std::string& scenario : scenarios) {
        for (const std::string& policy : spec.policies) {
          CampaignJob job;
          job.index = static_cast<int>(jobs.size());
          job.week = week;
          job.shift = shift;
          job.policy = policy;
          job.scenario = scenario;
          job.fault_case = fault_case.name;
          job.faults = spec.faults;
          job.faults.insert(job.faults.end(), fault_case.faults.begin(), fault_case.faults.end());
          job.run_id = spec.matrix() ? spec.name + "/" + scenario + "/" +
                                           (fault_case.name.empty() ? "-" : fault_case.name) + "/" +
                                           label + "/" + policy
                                     : spec.name + "/" + label + "/" + policy;
          job.seed = Mix(spec.seed * 0x100000001b3ULL + static_cast<std::uint64_t>(s));
          jobs.push_back(job);
        }
      }
    }
  }
  return jobs;
}

}  // namespace autoshovel::app
