// The campaign's results on disk: each worker (a local process or an MPI rank) writes its own
// shard, `shards/worker-K.sqlite`, in the results schema (results_db.h: one transaction per
// cycle, WAL), so that no two processes ever write one file; the coordinator merges the shards
// into `results.sqlite`. Merging is idempotent (INSERT OR IGNORE on the primary keys): a shard
// merged twice, or a cycle present in two shards, leaves one row. A worker killed mid-cycle
// leaves its shard holding every committed cycle and nothing of the one in flight.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "runtime/app/campaign/campaign_spec.h"

namespace autoshovel::app {

/// The fault × scenario table of a campaign as a view over `cycles` and `campaign_runs`
/// (issue 9): per fault case and scenario, cycles run, completed, mean fill rate, safety
/// violations, safe stops, recoveries, refused frames and the smallest clearance. Cases in the
/// order the spec lists them ("" for a campaign without fault cases).
inline constexpr const char* kFaultSummaryView = R"sql(
CREATE VIEW fault_summary AS
SELECT r.fault_case AS fault_case, c.scenario AS scenario, count(*) AS cycles,
       sum(c.completed) AS completed, avg(c.fill_rate) AS mean_fill_rate,
       sum(c.safety_violations) AS safety_violations, sum(c.safe_stops) AS safe_stops,
       sum(c.recoveries) AS recoveries, sum(c.refused_frames) AS refused_frames,
       min(c.safety_margin_m) AS min_clearance_m, min(r.rowid) AS spec_order
FROM cycles c JOIN campaign_runs r USING (run_id)
GROUP BY r.fault_case, c.scenario
ORDER BY spec_order;
)sql";

/// Creates the merged database (results schema) if needed, the `campaign_runs` table (run_id →
/// week, shift, policy, seed, scenario, fault case of every job) and the `fault_summary` view.
void PrepareCampaignDatabase(const std::filesystem::path& merged, const CampaignSpec& spec,
                             const std::vector<CampaignJob>& jobs);

/// Merges one shard into `merged` in one transaction. Throws std::runtime_error naming both
/// files on any failure (the merged file is then unchanged).
void MergeShard(const std::filesystem::path& merged, const std::filesystem::path& shard);

/// Rows of `cycles` in a results database; 0 when the file does not exist yet.
long long CountCycles(const std::filesystem::path& file);

/// Prints the `fault_summary` view of a campaign database as a Markdown table. Returns false
/// (nothing printed) when the file has no such view.
bool PrintFaultTable(const std::filesystem::path& merged, std::ostream& out);

/// Prints the per-policy summary of a campaign database (cycles, completed, mean fill, scoop and
/// cycle time and energy, safety) and, for a fault campaign, the fault table. The file is opened
/// read-only and checked (integrity, then every value through results::ColumnReader); NULL
/// values are left out of the means and counted in a note. Throws results::ResultsDbError.
void PrintCampaignSummary(const std::filesystem::path& merged, std::ostream& out);

/// The shard files under `dir`, sorted.
std::vector<std::filesystem::path> ShardFiles(const std::filesystem::path& dir);

}  // namespace autoshovel::app
