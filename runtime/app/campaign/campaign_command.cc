#include "runtime/app/campaign/campaign_command.h"

#include <fcntl.h>
#include <mpi.h>
#include <spawn.h>
#include <sqlite3.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <iostream>
#include <set>
#include <thread>

#include "runtime/app/campaign/campaign_spec.h"
#include "runtime/app/campaign/campaign_store.h"
#include "runtime/app/shovel_run.h"
#include "runtime/core/file_output.h"
#include "runtime/core/progress_line.h"
#include "runtime/perception/segmentation.h"
#include "runtime/results/results_db.h"

extern char** environ;

namespace autoshovel::app {
namespace {

constexpr const char* kCommand = "autoshovel campaign";

std::filesystem::path ShardPath(const std::filesystem::path& dir, int worker) {
  char name[32];
  std::snprintf(name, sizeof name, "worker-%03d.sqlite", worker);
  return dir / "shards" / name;
}

std::filesystem::path MergedPath(const std::filesystem::path& dir) {
  return dir / "results.sqlite";
}

// OpenMPI's launcher sets these in every rank's environment.
bool StartedByMpirun() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMI_SIZE") != nullptr;
}

ShovelRunOptions JobOptions(const CampaignSpec& spec, const CampaignJob& job,
                            const std::string& models_dir) {
  ShovelRunOptions o;
  o.scenario = job.scenario;
  o.models_dir = models_dir;
  o.machine = spec.machine;
  o.cycles = spec.cycles_per_shift;
  o.seed = job.seed;
  o.truth_labels = spec.truth_labels;
  o.policy = ParseScoopPolicy(job.policy);
  o.stairway_steps = spec.stairway_steps;
  o.trigger = spec.trigger == "perception" ? TriggerChoice::kPerception
              : spec.trigger == "pressure" ? TriggerChoice::kPressure
                                           : TriggerChoice::kPredicted;
  if (std::isfinite(spec.attack_speed)) o.attack_speed = spec.attack_speed;
  if (std::isfinite(spec.scoop_deceleration)) o.scoop_deceleration = spec.scoop_deceleration;
  if (!spec.predictor.empty()) {
    o.predictor = spec.predictor.find('/') == std::string::npos
                      ? models_dir + "/prediction/" + spec.predictor
                      : spec.predictor;
  }
  o.figures = false;
  o.yard_variation = spec.yard_variation;
  o.faults = job.faults;
  o.max_cycle_time = spec.max_cycle_time_s;
  return o;
}

// The segmentation network's threads for one of `workers` processes on this machine: OpenCV
// runs it on a process-wide pool as large as the machine (segmentation.h), so n workers would
// run n × cores threads on cores cores. Each takes its share, at least one.
int InferenceThreadsPerWorker(int workers) {
  const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  return std::max(1, cores / std::max(1, workers));
}

// One worker: jobs k, k + n, …; returns the number of jobs that failed. `local_workers`: the
// workers on this machine (the network's threads are shared among them).
int RunWorker(const CampaignSpec& spec, const std::vector<CampaignJob>& jobs,
              const std::filesystem::path& dir, const std::string& models_dir, int k, int n,
              int local_workers, std::ostream& log, const std::function<void()>& after_cycle = {}) {
  perception::SetInferenceThreads(InferenceThreadsPerWorker(local_workers));
  const results::ResultsDb merged(MergedPath(dir));
  results::ResultsDb shard(ShardPath(dir, k));
  int failed = 0;
  for (const CampaignJob& job : jobs) {
    if (job.index % n != k) continue;
    std::set<int> stored;
    for (const int c : merged.CompletedCycles(job.run_id)) stored.insert(c);
    for (const int c : shard.CompletedCycles(job.run_id)) stored.insert(c);
    int last_missing = -1;
    for (int c = 0; c < spec.cycles_per_shift; ++c) {
      if (!stored.count(c)) last_missing = c;
    }
    if (last_missing < 0) continue;
    try {
      ShovelJob shovel(JobOptions(spec, job, models_dir));
      results::RunInfo info;
      info.run_id = job.run_id;
      info.scenario = shovel.scenario_name();
      info.machine = shovel.machine_name();
      info.seed = job.seed;
      info.cycles_planned = spec.cycles_per_shift;
      shard.BeginRun(info);
      // Cycles before the last missing one are replayed when stored: the yard they dug is the
      // yard the next cycle meets. Same seed, same cycles (the runs are deterministic).
      for (int c = 0; c <= last_missing; ++c) {
        const CycleOutcome outcome = shovel.RunCycle(c, {}, nullptr);
        if (stored.count(c)) continue;
        try {
          shard.WriteCycle(job.run_id, outcome.record);
        } catch (const results::DuplicateCycleError& e) {
          // Stored meanwhile by another process (same seed, same cycle): the row is there, which
          // is all the campaign needs; the job goes on to its next cycle.
          log << job.run_id << " cycle " << c << ": already stored (" << e.what() << ")\n";
          continue;
        }
        const results::CycleRecord& r = outcome.record;
        char line[300];
        std::snprintf(line, sizeof line, "%s cycle %d: %s %s %s fill %.1f %% %.1f s %.0f kJ%s\n",
                      job.run_id.c_str(), c, r.bin.c_str(), r.material.c_str(), r.strategy.c_str(),
                      100 * r.fill_rate, r.time_s.total, r.energy_kj.total,
                      r.completed ? "" : (" FAILED: " + outcome.failure).c_str());
        log << line << std::flush;
        if (after_cycle) after_cycle();
      }
    } catch (const std::exception& e) {
      log << job.run_id << ": " << e.what() << "\n" << std::flush;
      ++failed;
    }
  }
  return failed;
}

// Creates the folder (or checks it for --resume) and merges what earlier workers stored.
bool PrepareFolder(const CampaignOptions& o, const CampaignSpec& spec,
                   const std::vector<CampaignJob>& jobs, const std::filesystem::path& dir,
                   std::ostream& err) {
  const std::filesystem::path stored_spec = dir / "campaign.yaml";
  if (std::filesystem::exists(stored_spec)) {
    if (!o.resume) {
      err << kCommand << ": " << dir.string()
          << " already holds a campaign; add --resume to continue it, or choose another -o\n";
      return false;
    }
    // Compared as parsed YAML: editing a comment in the spec must not strand a half-run campaign.
    if (!SameCampaignContent(stored_spec.string(), o.spec)) {
      err << kCommand << ": " << o.spec << " differs from the campaign in " << dir.string() << " ("
          << stored_spec.string()
          << "); a resumed campaign must keep its spec, or its rows would not be comparable\n";
      return false;
    }
  } else {
    if (o.resume) {
      err << kCommand << ": nothing to resume in " << dir.string() << " (no campaign.yaml)\n";
      return false;
    }
    if (std::filesystem::exists(dir) && !std::filesystem::is_empty(dir)) {
      err << kCommand << ": " << dir.string() << " exists and is not empty; choose another -o\n";
      return false;
    }
    core::CreateFolders(dir / "shards");
    std::filesystem::copy_file(o.spec, stored_spec);
  }
  core::CreateFolders(dir / "shards");
  PrepareCampaignDatabase(MergedPath(dir), spec, jobs);
  for (const auto& shard : ShardFiles(dir / "shards")) MergeShard(MergedPath(dir), shard);
  return true;
}

long long ShardRows(const std::filesystem::path& dir) {
  long long rows = 0;
  for (const auto& shard : ShardFiles(dir / "shards")) rows += CountCycles(shard);
  return rows;
}

// Progress goes to standard error (results and the summary stay on standard output), rewritten in
// place on a terminal and one line per newly stored cycle anywhere else (core/progress_line.h).
void PrintProgress(core::ProgressLine& progress, long long done, long long total, long long fresh,
                   double seconds, bool final, long long& last_done) {
  const double rate = seconds > 0 ? fresh / seconds : 0;
  // No ETA before the first cycle of this session is stored (the rate is not known yet).
  char eta[32] = "?";
  if (rate > 0) std::snprintf(eta, sizeof eta, "%.0f s", (total - done) / rate);
  char line[200];
  std::snprintf(line, sizeof line, "[%lld/%lld cycles] %.2f cycles/s, %.0f s elapsed, ETA %s", done,
                total, rate, seconds, eta);
  if (final) {
    progress.Finish(line);
  } else {
    progress.Update(line, done != last_done);
  }
  last_done = done;
}

// Per policy: cycles, completed, mean fill, time and energy; safety (campaign_store.h).
void PrintSummary(const std::filesystem::path& merged, std::ostream& out) {
  PrintCampaignSummary(merged, out);
}

// Local: worker processes of this executable, progress from their shards.
int RunLocal(const CampaignOptions& o, const CampaignSpec& spec, const std::filesystem::path& dir,
             std::ostream& out, std::ostream& err) {
  const long long total = spec.cycles();
  const long long base = CountCycles(MergedPath(dir));
  if (base >= total) {
    out << "campaign complete: " << base << "/" << total << " cycles in "
        << MergedPath(dir).string() << "\n";
    PrintSummary(MergedPath(dir), out);
    return 0;
  }
  const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  const int workers = std::clamp(o.workers > 0 ? o.workers : cores, 1, spec.jobs());
  out << kCommand << ": " << spec.name << ", " << spec.jobs() << " jobs (" << spec.shifts()
      << " shifts x "
      << (spec.matrix() ? std::to_string(spec.scenarios.size()) + " scenarios x " +
                              std::to_string(spec.cases()) + " fault cases x "
                        : std::string())
      << spec.policies.size() << " policies) of " << spec.cycles_per_shift << " cycles, " << workers
      << " worker process(es) -> " << dir.string()
      << (base > 0 ? ", resuming with " + std::to_string(base) + " stored" : "") << "\n";
  const long long shard_rows_before = ShardRows(dir);
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  std::vector<pid_t> pids;
  for (int k = 0; k < workers; ++k) {
    std::vector<std::string> args = {self,
                                     "--models",
                                     o.models_dir,
                                     "campaign",
                                     o.spec,
                                     "-o",
                                     dir.string(),
                                     "--resume",
                                     "--worker-index",
                                     std::to_string(k),
                                     "--worker-count",
                                     std::to_string(workers),
                                     "--coordinator-pid",
                                     std::to_string(getpid())};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    const std::string log = (dir / ("worker-" + std::to_string(k) + ".log")).string();
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                     O_WRONLY | O_CREAT | O_APPEND, 0644);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
    pid_t pid = 0;
    const int rc = posix_spawn(&pid, self.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) {
      err << kCommand << ": cannot start worker " << k << ": " << std::strerror(rc) << "\n";
      for (const pid_t p : pids) kill(p, SIGTERM);
      return 2;
    }
    pids.push_back(pid);
  }
  const auto t0 = std::chrono::steady_clock::now();
  core::ProgressLine progress(err);
  long long last_done = -1;
  int failed_workers = 0;
  std::vector<bool> running(pids.size(), true);
  for (int alive = workers; alive > 0;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    for (std::size_t k = 0; k < pids.size(); ++k) {
      int status = 0;
      if (running[k] && waitpid(pids[k], &status, WNOHANG) == pids[k]) {
        running[k] = false;
        --alive;
        if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
          ++failed_workers;
          err << (progress.terminal() ? "\n" : "") << kCommand << ": worker " << k << " ended with "
              << (WIFSIGNALED(status) ? "signal " + std::to_string(WTERMSIG(status))
                                      : "status " + std::to_string(WEXITSTATUS(status)))
              << " (log: " << (dir / ("worker-" + std::to_string(k) + ".log")).string() << ")\n";
        }
      }
    }
    const long long fresh = ShardRows(dir) - shard_rows_before;
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    PrintProgress(progress, base + fresh, total, fresh, seconds, false, last_done);
  }
  for (const auto& shard : ShardFiles(dir / "shards")) MergeShard(MergedPath(dir), shard);
  const long long stored = CountCycles(MergedPath(dir));
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  PrintProgress(progress, stored, total, stored - base, seconds, true, last_done);
  PrintSummary(MergedPath(dir), out);
  out << "results: " << MergedPath(dir).string() << "\n";
  if (stored < total) {
    err << kCommand << ": " << total - stored << " cycle(s) missing (" << failed_workers
        << " worker(s) failed); continue with: autoshovel campaign " << o.spec << " -o "
        << dir.string() << " --resume\n";
    return 1;
  }
  return 0;
}

// Under mpirun: rank 0 prepares and merges, every rank works; progress from rank 0's view of
// the shards (the campaign folder must be on a filesystem every rank sees).
int RunMpi(const CampaignOptions& o, const CampaignSpec& spec, const std::vector<CampaignJob>& jobs,
           const std::filesystem::path& dir, std::ostream& out, std::ostream& err) {
  MPI_Init(nullptr, nullptr);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  int ok = 1;
  if (rank == 0) {
    try {
      ok = PrepareFolder(o, spec, jobs, dir, err) ? 1 : 0;
    } catch (const std::exception& e) {
      err << kCommand << ": " << e.what() << "\n";
      ok = 0;
    }
    if (ok) {
      out << kCommand << ": " << spec.name << ", " << spec.jobs() << " jobs over " << size
          << " MPI ranks -> " << dir.string() << "\n";
    }
  }
  MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (!ok) {
    MPI_Finalize();
    return 2;
  }
  std::ofstream log(dir / ("rank-" + std::to_string(rank) + ".log"), std::ios::app);
  const auto t0 = std::chrono::steady_clock::now();
  const long long base = rank == 0 ? CountCycles(MergedPath(dir)) : 0;
  const long long shard_rows_before = rank == 0 ? ShardRows(dir) : 0;
  core::ProgressLine progress_line(err);
  long long last_done = -1;
  const auto progress = [&](bool final) {
    const long long fresh = ShardRows(dir) - shard_rows_before;
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    PrintProgress(progress_line, base + fresh, spec.cycles(), fresh, seconds, final, last_done);
  };
  // Ranks on this machine: Open MPI says how many (mpirun sets OMPI_COMM_WORLD_LOCAL_SIZE);
  // without it every rank is taken to share one machine.
  const char* local_size = std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE");
  const int local_ranks =
      local_size != nullptr && std::atoi(local_size) > 0 ? std::atoi(local_size) : size;
  int failed = RunWorker(
      spec, jobs, dir, o.models_dir, rank, size, local_ranks, log,
      rank == 0 ? std::function<void()>([&] { progress(false); }) : std::function<void()>());
  // The rank's log is the only record of why a job failed: losing it (a full disk) is a
  // failure of the rank, said on its standard error, not a silent success.
  log.flush();
  if (!log) {
    err << kCommand << ": " << (dir / ("rank-" + std::to_string(rank) + ".log")).string()
        << ": cannot write the rank's log\n";
    ++failed;
  }
  // Rank 0 keeps reporting from the shards until every rank is done (a non-blocking barrier:
  // collectives must match in kind on every rank).
  MPI_Request done;
  MPI_Ibarrier(MPI_COMM_WORLD, &done);
  for (int finished = 0; !finished;) {
    MPI_Test(&done, &finished, MPI_STATUS_IGNORE);
    if (rank == 0) progress(finished != 0);
    if (!finished) std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }
  int failed_total = 0;
  MPI_Reduce(&failed, &failed_total, 1, MPI_INT, MPI_SUM, 0, MPI_COMM_WORLD);
  int status = 0;
  if (rank == 0) {
    for (const auto& shard : ShardFiles(dir / "shards")) MergeShard(MergedPath(dir), shard);
    const long long stored = CountCycles(MergedPath(dir));
    PrintSummary(MergedPath(dir), out);
    out << "results: " << MergedPath(dir).string() << "\n";
    if (stored < spec.cycles()) {
      err << kCommand << ": " << spec.cycles() - stored << " cycle(s) missing (" << failed_total
          << " job(s) failed); continue with --resume\n";
      status = 1;
    }
  }
  MPI_Bcast(&status, 1, MPI_INT, 0, MPI_COMM_WORLD);
  MPI_Finalize();
  return status;
}

}  // namespace

int RunCampaign(const CampaignOptions& o, std::ostream& out, std::ostream& err) {
  CampaignSpec spec;
  try {
    spec = LoadCampaignSpec(o.spec);
  } catch (const std::exception& e) {
    err << kCommand << ": " << e.what() << "\n";
    return 2;
  }
  const std::vector<CampaignJob> jobs = CampaignJobs(spec);
  const std::filesystem::path dir =
      o.out_dir.empty() ? std::filesystem::path("runs") / ("campaign_" + spec.name) : o.out_dir;
  try {
    if (o.worker_index >= 0) {  // a worker process of a local campaign
      // A worker dies with its coordinator: an orphan would go on writing its shard while the
      // resumed campaign's new worker writes the same one. The parent may have gone before
      // prctl took effect, hence the check after it.
      prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (o.coordinator_pid > 0 && getppid() != o.coordinator_pid) {
        err << kCommand << ": worker " << o.worker_index << ": the coordinator (pid "
            << o.coordinator_pid << ") is gone\n";
        return 1;
      }
      return RunWorker(spec, jobs, dir, o.models_dir, o.worker_index, o.worker_count,
                       o.worker_count, out) == 0
                 ? 0
                 : 1;
    }
    if (StartedByMpirun()) return RunMpi(o, spec, jobs, dir, out, err);
    // Check that the jobs can be set up (scenario, machine, models) before starting workers.
    // Each yard under each fault case once (a fault may name a sensor the machine lacks).
    // A predictor trained on another machine is warned about once (model_provenance.h).
    std::set<std::string> warned;
    for (const CampaignJob& job : jobs) {
      if (job.week != 1 || job.shift != 1 || job.policy != spec.policies.front()) continue;
      ShovelJob probe(JobOptions(spec, job, o.models_dir));
      const std::string mismatch = probe.PredictorMachineMismatch();
      if (!mismatch.empty() && warned.insert(mismatch).second) {
        err << kCommand << ": warning: " << mismatch << "\n";
      }
    }
    if (!PrepareFolder(o, spec, jobs, dir, err)) return 2;
    return RunLocal(o, spec, dir, out, err);
  } catch (const std::exception& e) {
    err << kCommand << ": " << e.what() << "\n";
    return 2;
  }
}

}  // namespace autoshovel::app
