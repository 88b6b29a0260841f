// Campaigns (runtime/app/campaign): the spec is read strictly, jobs pair the policies on the
// same shift seed, and a campaign killed with SIGKILL mid-run and resumed stores every cycle
// exactly once, each row identical to an uninterrupted campaign's.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include "runtime/app/campaign/campaign_spec.h"
#include "runtime/app/campaign/campaign_store.h"
#include "runtime/core/diagnostics.h"
#include "runtime/results/results_db.h"

namespace autoshovel::app {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() /
                       ("autoshovel_campaign_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

fs::path WriteSpec(const fs::path& dir, const std::string& text) {
  const fs::path file = dir / "spec.yaml";
  std::ofstream(file) << text;
  return file;
}

const char* kSmallSpec =
    "name: resume_test\nscenario: cone_pile\nseed: 5\nweeks: 1\nshifts_per_week: 3\n"
    "cycles_per_shift: 2\npolicies: [auto, stairway_fixed]\n";

std::string SpecError(const std::string& text) {
  const fs::path dir = TempDir("spec");
  try {
    LoadCampaignSpec(WriteSpec(dir, text).string());
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "";
}

TEST(CampaignSpec, ReadsAndRefusesWithLocations) {
  const fs::path dir = TempDir("good");
  const CampaignSpec spec = LoadCampaignSpec(WriteSpec(dir, kSmallSpec).string());
  EXPECT_EQ(spec.jobs(), 6);
  EXPECT_EQ(spec.cycles(), 12);
  EXPECT_TRUE(spec.truth_labels);
  EXPECT_EQ(spec.stairway_steps, 3);

  const std::string policy = SpecError(
      "name: a\nscenario: cone_pile\nweeks: 1\nshifts_per_week: 1\ncycles_per_shift: 1\n"
      "policies: [auto, stairs]\n");
  EXPECT_NE(policy.find("spec.yaml:6:"), std::string::npos) << policy;
  EXPECT_NE(policy.find("unknown policy 'stairs'"), std::string::npos) << policy;
  const std::string weeks = SpecError(
      "name: a\nscenario: cone_pile\nweeks: 0\nshifts_per_week: 1\ncycles_per_shift: 1\n"
      "policies: [auto]\n");
  EXPECT_NE(weeks.find("spec.yaml:3:8: weeks"), std::string::npos) << weeks;
  const std::string typo = SpecError(
      "name: a\nscenario: cone_pile\nweeks: 1\nshifts_per_week: 1\ncycles_per_shift: 1\n"
      "policies: [auto]\nseeds: 3\n");
  EXPECT_NE(typo.find("spec.yaml:7:1: seeds: unknown key"), std::string::npos) << typo;
  const std::string name = SpecError(
      "name: a/b\nscenario: cone_pile\nweeks: 1\nshifts_per_week: 1\ncycles_per_shift: 1\n"
      "policies: [auto]\n");
  EXPECT_NE(name.find("spec.yaml:1:7: name"), std::string::npos) << name;
  const std::string twice = SpecError(
      "name: a\nscenario: cone_pile\nweeks: 1\nshifts_per_week: 1\ncycles_per_shift: 1\n"
      "policies: [auto, auto]\n");
  EXPECT_NE(twice.find("listed twice"), std::string::npos) << twice;
  // The scoop profile: read as written; the main job's when left out.
  EXPECT_TRUE(std::isnan(spec.attack_speed));
  EXPECT_TRUE(spec.predictor.empty());
  const CampaignSpec braking = LoadCampaignSpec(
      WriteSpec(dir, std::string(kSmallSpec) +
                         "attack_speed: 1.0\nscoop_deceleration: 1.0\npredictor: penetration_svr\n")
          .string());
  EXPECT_DOUBLE_EQ(braking.attack_speed, 1.0);
  EXPECT_DOUBLE_EQ(braking.scoop_deceleration, 1.0);
  EXPECT_EQ(braking.predictor, "penetration_svr");
  const std::string deceleration = SpecError(
      "name: a\nscenario: cone_pile\nweeks: 1\nshifts_per_week: 1\ncycles_per_shift: 1\n"
      "policies: [auto]\nscoop_deceleration: 0\n");
  EXPECT_NE(deceleration.find("spec.yaml:7:21: scoop_deceleration"), std::string::npos)
      << deceleration;
  const std::string missing = SpecError("name: a\nscenario: cone_pile\n");
  EXPECT_NE(missing.find("weeks"), std::string::npos) << missing;
}

// A resumed campaign is checked against the stored spec by content: a comment, blank lines or
// a list in block style instead of flow style change nothing; a value or a new key does.
TEST(CampaignSpec, SameContentIgnoresCommentsAndLayoutOnly) {
  const fs::path dir = TempDir("same");
  auto write = [&](const std::string& name, const std::string& text) {
    const fs::path file = dir / name;
    std::ofstream(file) << text;
    return file.string();
  };
  const std::string stored = write("stored.yaml", kSmallSpec);
  const std::string commented = write(
      "commented.yaml",
      "# about 2 h on two cores\nname: resume_test   # the runs' prefix\n\nscenario: cone_pile\n"
      "seed: 5\nweeks: 1\nshifts_per_week: 3\ncycles_per_shift: 2\npolicies:\n  - auto\n"
      "  - stairway_fixed\n");
  EXPECT_TRUE(SameCampaignContent(stored, stored));
  EXPECT_TRUE(SameCampaignContent(stored, commented));
  EXPECT_FALSE(SameCampaignContent(
      stored,
      write(
          "seed.yaml",
          std::string(kSmallSpec).replace(std::string(kSmallSpec).find("seed: 5"), 7, "seed: 6"))));
  EXPECT_FALSE(SameCampaignContent(
      stored, write("extra.yaml", std::string(kSmallSpec) + "stairway_steps: 3\n")));
  EXPECT_FALSE(SameCampaignContent(
      stored, write("order.yaml",
                    "name: resume_test\nscenario: cone_pile\nseed: 5\nweeks: 1\n"
                    "shifts_per_week: 3\ncycles_per_shift: 2\n"
                    "policies: [stairway_fixed, auto]\n")));
  EXPECT_FALSE(SameCampaignContent(stored, write("broken.yaml", "name: [unclosed\n")));
  EXPECT_FALSE(SameCampaignContent(stored, (dir / "missing.yaml").string()));
  fs::remove_all(dir);
}

TEST(CampaignJobs, PairPoliciesOnTheShiftSeed) {
  const fs::path dir = TempDir("jobs");
  CampaignSpec spec = LoadCampaignSpec(WriteSpec(dir, kSmallSpec).string());
  spec.weeks = 2;
  const std::vector<CampaignJob> jobs = CampaignJobs(spec);
  ASSERT_EQ(jobs.size(), 12u);
  std::set<std::string> ids;
  std::set<std::uint64_t> seeds;
  for (const CampaignJob& job : jobs) {
    ids.insert(job.run_id);
    seeds.insert(job.seed);
  }
  EXPECT_EQ(ids.size(), 12u);
  EXPECT_EQ(seeds.size(), 6u);  // one per shift
  EXPECT_EQ(jobs[0].seed, jobs[1].seed);
  EXPECT_EQ(jobs[0].run_id, "resume_test/w01s01/auto");
  EXPECT_EQ(jobs[7].run_id, "resume_test/w02s01/stairway_fixed");
  EXPECT_EQ(jobs[7].week, 2);
  EXPECT_EQ(jobs[7].shift, 1);
}

const char* kFaultSpec =
    "name: faults\nscenarios: [cone_pile, mixing_station]\nseed: 3\nweeks: 1\n"
    "shifts_per_week: 1\ncycles_per_shift: 1\npolicies: [auto]\n"
    "fault_cases:\n"
    "  - name: none\n"
    "  - name: lidar_dropout\n"
    "    faults:\n"
    "      - {kind: lidar_dropout, start_s: 2.0, duration_s: 1.5}\n";

TEST(CampaignSpec, FaultCasesTimesScenarios) {
  const fs::path dir = TempDir("fault_spec");
  const CampaignSpec spec = LoadCampaignSpec(WriteSpec(dir, kFaultSpec).string());
  EXPECT_EQ(spec.scenarios, (std::vector<std::string>{"cone_pile", "mixing_station"}));
  ASSERT_EQ(spec.fault_cases.size(), 2u);
  EXPECT_TRUE(spec.fault_cases[0].faults.empty());
  ASSERT_EQ(spec.fault_cases[1].faults.size(), 1u);
  EXPECT_EQ(spec.fault_cases[1].faults[0].kind, plant::FaultKind::kLidarDropout);
  EXPECT_EQ(spec.jobs(), 4);
  const std::vector<CampaignJob> jobs = CampaignJobs(spec);
  ASSERT_EQ(jobs.size(), 4u);
  // Case-major; every case meets the same yards with the same seed.
  EXPECT_EQ(jobs[0].run_id, "faults/cone_pile/none/w01s01/auto");
  EXPECT_EQ(jobs[1].run_id, "faults/mixing_station/none/w01s01/auto");
  EXPECT_EQ(jobs[2].run_id, "faults/cone_pile/lidar_dropout/w01s01/auto");
  EXPECT_EQ(jobs[2].scenario, "cone_pile");
  EXPECT_EQ(jobs[2].faults.size(), 1u);
  EXPECT_TRUE(jobs[0].faults.empty());
  for (const CampaignJob& job : jobs) EXPECT_EQ(job.seed, jobs[0].seed);

  const std::string both = SpecError(
      "name: a\nscenario: cone_pile\nscenarios: [low_pile]\nweeks: 1\nshifts_per_week: 1\n"
      "cycles_per_shift: 1\npolicies: [auto]\n");
  EXPECT_NE(both.find("either 'scenario' or 'scenarios'"), std::string::npos) << both;
  const std::string twice = SpecError(
      "name: a\nscenarios: [low_pile]\nweeks: 1\nshifts_per_week: 1\ncycles_per_shift: 1\n"
      "policies: [auto]\nfault_cases:\n  - name: x\n  - name: x\n");
  EXPECT_NE(twice.find("spec.yaml:9:"), std::string::npos) << twice;
  EXPECT_NE(twice.find("fault case 'x' is listed twice"), std::string::npos) << twice;
  const std::string bad_fault = SpecError(
      "name: a\nscenarios: [low_pile]\nweeks: 1\nshifts_per_week: 1\ncycles_per_shift: 1\n"
      "policies: [auto]\nfault_cases:\n  - name: x\n    faults:\n      - kind: lidar_drop\n");
  EXPECT_NE(bad_fault.find("spec.yaml:10:"), std::string::npos) << bad_fault;
}

// Starts `autoshovel campaign` in its own process group; returns its pid.
pid_t StartCampaign(const std::vector<std::string>& args, const fs::path& log) {
  const pid_t pid = fork();
  if (pid == 0) {
    setpgid(0, 0);
    const FILE* out = std::freopen(log.c_str(), "a", stdout);
    const FILE* err = std::freopen(log.c_str(), "a", stderr);
    (void)out, (void)err;
    std::vector<char*> argv;
    std::vector<std::string> copy = args;
    for (std::string& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(AUTOSHOVEL_BINARY, argv.data());
    _exit(127);
  }
  setpgid(pid, pid);
  return pid;
}

int Wait(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::map<std::pair<std::string, int>, results::CycleRecord> Rows(const fs::path& db_file) {
  std::map<std::pair<std::string, int>, results::CycleRecord> rows;
  const results::ResultsDb db(db_file);
  for (const results::RunInfo& run : db.Runs()) {
    for (const results::CycleRecord& c : db.Cycles(run.run_id)) rows[{run.run_id, c.cycle}] = c;
  }
  return rows;
}

// Two shifts of two mixing-station cycles: killed as soon as a first cycle is stored, both jobs
// are caught between their cycles, so the resumed run must replay cycle 0 to rebuild the dug
// yard before it stores cycle 1.
const char* kResumeSpec =
    "name: resume_test\nscenario: mixing_station\nseed: 5\nweeks: 1\nshifts_per_week: 2\n"
    "cycles_per_shift: 2\npolicies: [auto]\n";

TEST(Campaign, KilledWithSigkillAndResumedLosesAndDuplicatesNothing) {
  const fs::path dir = TempDir("resume");
  const fs::path spec = WriteSpec(dir, kResumeSpec);
  const std::string models = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";
  auto command = [&](const fs::path& out, bool resume) {
    std::vector<std::string> args = {"autoshovel", "--models",    models,
                                     "campaign",   spec.string(), "-o",
                                     out.string(), "--workers",   "2"};
    if (resume) args.push_back("--resume");
    return args;
  };
  // The reference: uninterrupted.
  ASSERT_EQ(Wait(StartCampaign(command(dir / "reference", false), dir / "reference.log")), 0);
  const auto reference = Rows(dir / "reference" / "results.sqlite");
  ASSERT_EQ(reference.size(), 4u);

  // Killed once some cycles are stored, with every process of the campaign at once.
  const pid_t pid = StartCampaign(command(dir / "killed", false), dir / "killed.log");
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  long long stored = 0;
  while (stored < 1 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    stored = 0;
    for (const auto& shard : ShardFiles(dir / "killed" / "shards")) stored += CountCycles(shard);
  }
  ASSERT_GE(stored, 1) << "the campaign stored nothing in 120 s";
  killpg(pid, SIGKILL);
  Wait(pid);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the workers are gone too
  long long at_kill = 0;
  for (const auto& shard : ShardFiles(dir / "killed" / "shards")) at_kill += CountCycles(shard);
  EXPECT_LT(at_kill, 4) << "killed too late: nothing left to resume";

  // Starting again without --resume is refused; with another spec too.
  EXPECT_EQ(Wait(StartCampaign(command(dir / "killed", false), dir / "refused.log")), 2);
  const fs::path other = dir / "other";
  fs::create_directories(other);
  std::ofstream(other / "spec.yaml") << kResumeSpec << "stairway_steps: 2\n";
  std::vector<std::string> other_args = command(dir / "killed", true);
  other_args[4] = (other / "spec.yaml").string();
  EXPECT_EQ(Wait(StartCampaign(other_args, dir / "refused.log")), 2);

  ASSERT_EQ(Wait(StartCampaign(command(dir / "killed", true), dir / "resumed.log")), 0);
  const auto resumed = Rows(dir / "killed" / "results.sqlite");
  ASSERT_EQ(resumed.size(), reference.size());
  for (const auto& [key, row] : reference) {
    const auto it = resumed.find(key);
    ASSERT_NE(it, resumed.end()) << key.first << " " << key.second;
    EXPECT_EQ(it->second.fill_rate, row.fill_rate) << key.first << " " << key.second;
    EXPECT_EQ(it->second.energy_kj.total, row.energy_kj.total) << key.first;
    EXPECT_EQ(it->second.time_s.total, row.time_s.total) << key.first;
    EXPECT_EQ(it->second.strategy, row.strategy) << key.first;
    EXPECT_EQ(it->second.bin, row.bin) << key.first;
    EXPECT_EQ(it->second.payload_m3, row.payload_m3) << key.first;
    EXPECT_EQ(it->second.samples.size(), row.samples.size());
  }
  EXPECT_EQ(CountCycles(dir / "killed" / "results.sqlite"), 4);  // no duplicate rows
  // Resuming a complete campaign runs nothing and changes nothing.
  ASSERT_EQ(Wait(StartCampaign(command(dir / "killed", true), dir / "again.log")), 0);
  EXPECT_EQ(CountCycles(dir / "killed" / "results.sqlite"), 4);
  fs::remove_all(dir);
}

// A fault campaign of 2 yards x 2 fault cases, one cycle each: the table is printed and stored
// (view fault_summary), counted from the cycles' own rows.
TEST(Campaign, FaultCampaignPrintsAndStoresTheFaultTable) {
  const fs::path dir = TempDir("fault_campaign");
  const fs::path spec = WriteSpec(dir, kFaultSpec);
  const std::string models = std::string(AUTOSHOVEL_SOURCE_DIR) + "/models";
  const fs::path out = dir / "out";
  ASSERT_EQ(Wait(StartCampaign({"autoshovel", "--models", models, "campaign", spec.string(), "-o",
                                out.string(), "--workers", "2"},
                               dir / "campaign.log")),
            0);
  std::ifstream log_file(dir / "campaign.log");
  const std::string log((std::istreambuf_iterator<char>(log_file)), {});
  EXPECT_NE(log.find("| fault | scenario | cycles | completed |"), std::string::npos) << log;
  EXPECT_NE(log.find("| none | cone_pile | 1 | 1 |"), std::string::npos) << log;
  EXPECT_NE(log.find("| lidar_dropout | mixing_station | 1 |"), std::string::npos) << log;
  // Progress into a file (not a terminal): whole lines, never `\r` rewrites (issue 38 found one
  // 100 KB line), ending with the final count on a line of its own.
  EXPECT_EQ(log.find('\r'), std::string::npos) << log;
  EXPECT_NE(log.find("\n[4/4 cycles] "), std::string::npos) << log;

  const results::ResultsDb db(out / "results.sqlite");
  int dropout_stops = 0, none_stops = 0;
  for (const results::RunInfo& run : db.Runs()) {
    for (const results::CycleRecord& c : db.Cycles(run.run_id)) {
      EXPECT_EQ(c.safety_violations, 0) << run.run_id;
      if (run.run_id.find("/lidar_dropout/") != std::string::npos) {
        EXPECT_EQ(c.faults, "lidar_dropout");
        dropout_stops += c.safe_stops;
      } else {
        EXPECT_EQ(c.faults, "");
        none_stops += c.safe_stops;
      }
    }
  }
  EXPECT_EQ(none_stops, 0);
  EXPECT_GE(dropout_stops, 2);  // the watchdog held each yard's machine once
  std::ostringstream table;
  ASSERT_TRUE(PrintFaultTable(out / "results.sqlite", table));
  std::istringstream lines(table.str());
  std::string line;
  int rows = 0;
  while (std::getline(lines, line))
    rows += line.starts_with("| none") || line.starts_with("| lidar");
  EXPECT_EQ(rows, 4);
  EXPECT_LT(table.str().find("| none"), table.str().find("| lidar_dropout"));  // spec order
  fs::remove_all(dir);
}

}  // namespace
}  // namespace autoshovel::app
