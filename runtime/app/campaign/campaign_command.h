// `autoshovel campaign SPEC.yaml [-o DIR] [--workers N] [--resume]`: a production campaign
// (campaign_spec.h) over every local core by default, or over MPI ranks when started with
// `mpirun -np N autoshovel campaign …` (OpenMPI; detected from its environment).
//
// The campaign folder (default runs/campaign_<name>) holds campaign.yaml (the spec as given),
// shards/ (one results database per worker), worker-K.log, and results.sqlite: every cycle of
// every shift and policy, merged, with `campaign_runs` naming each run's week, shift and
// policy. `autoshovel report production results.sqlite` reads it.
//
// Local workers are processes (this executable again, with hidden --worker options), so that a
// crash of one cycle takes down one worker, not the campaign; a worker dies with the
// coordinator (PR_SET_PDEATHSIG), so no orphan races a resumed campaign for its shard. Each worker
// runs the jobs k, k + N, k + 2N, …; jobs are shifts × policies, and within a job the cycles run in
// order because the yard evolves as it is dug.
//
// Crash safety and resume: a worker commits each cycle in one transaction to its own shard. A
// campaign killed at any point (SIGKILL included, or a rank lost under mpirun) is continued by
// the same command with --resume: the shards are merged (idempotently), and every job with
// missing cycles is run again from its first cycle with the same seed, writing only the cycles
// not yet stored (the earlier ones are replayed, unrecorded, to rebuild the dug yard). No row is
// lost but the cycle in flight, and none is duplicated (the primary key is run and cycle).
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>

namespace autoshovel::app {

struct CampaignOptions {
  std::string spec;  ///< the campaign YAML
  std::string models_dir;
  std::filesystem::path out_dir;  ///< empty: runs/campaign_<name>
  int workers = 0;                ///< local processes; 0: every core
  bool resume = false;            ///< continue the campaign in out_dir
  // Internal (a worker process started by the coordinator):
  int worker_index = -1;
  int worker_count = 0;
  int coordinator_pid = 0;  ///< the worker exits when its parent is no longer this process
};

/// 0 when every cycle of the campaign is stored, 1 when some are missing (a worker failed:
/// resume), 2 on bad input.
int RunCampaign(const CampaignOptions& options, std::ostream& out, std::ostream& err);

}  // namespace autoshovel::app
