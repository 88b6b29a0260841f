#include "runtime/app/campaign/campaign_spec.h"

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

}  // namespace

control::ScoopPolicy ParseScoopPolicy(const std::string& name) {
  if (name == "auto") return control::ScoopPolicy::kAutoSelection;
  if (name == "just_in_out") return control::ScoopPolicy::kJustInOut;
  if (name == "stairway") return control::ScoopPolicy::kStairway;
  if (name == "stairway_fixed") return control::ScoopPolicy::kStairwayFixed;
  throw std::invalid_argument("unknown scooping policy '" + name +
                              "' (auto, just_in_out, stairway, stairway_fixed)");
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
    spec.scenario = root.String("scenario");
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
    if (root.Has("yard_variation")) {
      spec.yard_variation = root.Number("yard_variation", core::NumberRule::Closed(0.0, 0.9, ""));
    }
    spec.faults = plant::ReadFaults(root);
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
    for (const std::string& policy : spec.policies) {
      CampaignJob job;
      job.index = static_cast<int>(jobs.size());
      job.week = week;
      job.shift = shift;
      job.policy = policy;
      job.run_id = spec.name + "/" + label + "/" + policy;
      job.seed = Mix(spec.seed * 0x100000001b3ULL + static_cast<std::uint64_t>(s));
      jobs.push_back(job);
    }
  }
  return jobs;
}

}  // namespace autoshovel::app
