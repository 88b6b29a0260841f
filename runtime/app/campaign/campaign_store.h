// The campaign's results on disk: each worker (a local process or an MPI rank) writes its own
// shard, `shards/worker-K.sqlite`, in the results schema (results_db.h: one transaction per
// cycle, WAL), so that no two processes ever write one file; the coordinator merges the shards
// into `results.sqlite`. Merging is idempotent (INSERT OR IGNORE on the primary keys): a shard
// merged twice, or a cycle present in two shards, leaves one row. A worker killed mid-cycle
// leaves its shard holding every committed cycle and nothing of the one in flight.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "runtime/app/campaign/campaign_spec.h"

namespace autoshovel::app {

/// Creates the merged database (results schema) if needed, and the `campaign_runs` table:
/// run_id → week, shift, policy, seed of every job.
void PrepareCampaignDatabase(const std::filesystem::path& merged, const CampaignSpec& spec,
                             const std::vector<CampaignJob>& jobs);

/// Merges one shard into `merged` in one transaction. Throws std::runtime_error naming both
/// files on any failure (the merged file is then unchanged).
void MergeShard(const std::filesystem::path& merged, const std::filesystem::path& shard);

/// Rows of `cycles` in a results database; 0 when the file does not exist yet.
long long CountCycles(const std::filesystem::path& file);

/// The shard files under `dir`, sorted.
std::vector<std::filesystem::path> ShardFiles(const std::filesystem::path& dir);

}  // namespace autoshovel::app
