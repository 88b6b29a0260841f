#include "runtime/app/campaign/campaign_store.h"

#include <sqlite3.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <optional>
#include <ostream>
#include <stdexcept>

#include "runtime/results/results_db.h"

namespace autoshovel::app {
namespace {

struct CloseDb {
  void operator()(sqlite3* db) const { sqlite3_close(db); }
};
using Db = std::unique_ptr<sqlite3, CloseDb>;
using Statement = std::unique_ptr<sqlite3_stmt, int (*)(sqlite3_stmt*)>;

Db Open(const std::filesystem::path& file, int flags) {
  sqlite3* raw = nullptr;
  const int rc = sqlite3_open_v2(file.c_str(), &raw, flags, nullptr);
  Db db(raw);
  if (rc != SQLITE_OK) {
    throw std::runtime_error(file.string() + ": cannot open: " +
                             (raw != nullptr ? sqlite3_errmsg(raw) : sqlite3_errstr(rc)));
  }
  sqlite3_busy_timeout(raw, 30000);
  return db;
}

void Execute(sqlite3* db, const std::string& sql, const std::string& where) {
  char* error = nullptr;
  if (sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error) != SQLITE_OK) {
    const std::string message = error != nullptr ? error : "unknown error";
    sqlite3_free(error);
    throw std::runtime_error(where + ": " + message);
  }
}

// SQL string literal (the paths and names are ours, but quotes in a path must not break SQL).
std::string Quote(const std::string& text) {
  std::string out = "'";
  for (const char c : text) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

}  // namespace

void PrepareCampaignDatabase(const std::filesystem::path& merged, const CampaignSpec& spec,
                             const std::vector<CampaignJob>& jobs) {
  { const results::ResultsDb schema(merged); }  // creates or checks the results schema
  Db db = Open(merged, SQLITE_OPEN_READWRITE);
  const std::string where = merged.string();
  Execute(db.get(),
          "CREATE TABLE IF NOT EXISTS campaign_runs (run_id TEXT PRIMARY KEY, campaign TEXT NOT "
          "NULL, week INTEGER NOT NULL, shift INTEGER NOT NULL, policy TEXT NOT NULL, seed "
          "INTEGER NOT NULL, cycles_planned INTEGER NOT NULL, scenario TEXT, fault_case TEXT)",
          where);
  // A campaign folder from before fault campaigns lacks the last two columns.
  bool has_fault_case = false;
  {
    sqlite3_stmt* columns = nullptr;
    if (sqlite3_prepare_v2(db.get(), "SELECT name FROM pragma_table_info('campaign_runs')", -1,
                           &columns, nullptr) == SQLITE_OK) {
      const results::ColumnReader read(columns, merged, "pragma_table_info('campaign_runs')");
      while (sqlite3_step(columns) == SQLITE_ROW) has_fault_case |= read.Text(0) == "fault_case";
    }
    sqlite3_finalize(columns);
  }
  Execute(db.get(), "BEGIN IMMEDIATE", where);
  if (!has_fault_case) {
    Execute(db.get(), "ALTER TABLE campaign_runs ADD COLUMN scenario TEXT", where);
    Execute(db.get(), "ALTER TABLE campaign_runs ADD COLUMN fault_case TEXT", where);
  }
  for (const CampaignJob& job : jobs) {
    Execute(db.get(),
            "INSERT OR IGNORE INTO campaign_runs VALUES (" + Quote(job.run_id) + ", " +
                Quote(spec.name) + ", " + std::to_string(job.week) + ", " +
                std::to_string(job.shift) + ", " + Quote(job.policy) + ", " +
                std::to_string(static_cast<std::int64_t>(job.seed)) + ", " +
                std::to_string(spec.cycles_per_shift) + ", " + Quote(job.scenario) + ", " +
                Quote(job.fault_case) + ")",
            where);
    // Rows of a folder from before fault campaigns: their scenario is the spec's.
    Execute(db.get(),
            "UPDATE campaign_runs SET scenario = " + Quote(job.scenario) +
                ", fault_case = " + Quote(job.fault_case) + " WHERE run_id = " + Quote(job.run_id) +
                " AND scenario IS NULL",
            where);
  }
  Execute(db.get(), std::string("DROP VIEW IF EXISTS fault_summary; ") + kFaultSummaryView, where);
  Execute(db.get(), "COMMIT", where);
}

void MergeShard(const std::filesystem::path& merged, const std::filesystem::path& shard) {
  { const results::ResultsDb check(shard); }  // a foreign or damaged shard is refused here
  Db db = Open(merged, SQLITE_OPEN_READWRITE);
  const std::string where = merged.string() + " <- " + shard.string();
  Execute(db.get(), "ATTACH DATABASE " + Quote(shard.string()) + " AS shard", where);
  try {
    Execute(db.get(), "BEGIN IMMEDIATE", where);
    for (const char* table : {"runs", "cycles", "samples", "crowding_samples"}) {
      Execute(db.get(),
              std::string("INSERT OR IGNORE INTO main.") + table + " SELECT * FROM shard." + table,
              where);
    }
    Execute(db.get(), "COMMIT", where);
  } catch (...) {
    sqlite3_exec(db.get(), "ROLLBACK", nullptr, nullptr, nullptr);
    sqlite3_exec(db.get(), "DETACH DATABASE shard", nullptr, nullptr, nullptr);
    throw;
  }
  Execute(db.get(), "DETACH DATABASE shard", where);
}

long long CountCycles(const std::filesystem::path& file) {
  if (!std::filesystem::exists(file)) return 0;
  Db db = Open(file, SQLITE_OPEN_READONLY);
  sqlite3_stmt* raw = nullptr;
  if (sqlite3_prepare_v2(db.get(), "SELECT count(*) FROM cycles", -1, &raw, nullptr) != SQLITE_OK) {
    const std::string why = sqlite3_errmsg(db.get());
    sqlite3_finalize(raw);
    // A shard its worker has just created holds no schema yet: nothing stored.
    if (why.rfind("no such table", 0) == 0) return 0;
    throw results::ResultsDbError(file.string() + ": cannot count the cycles: " + why);
  }
  const Statement statement(raw, sqlite3_finalize);
  if (sqlite3_step(raw) != SQLITE_ROW) {
    throw results::ResultsDbError(file.string() + " is not a valid SQLite database: " +
                                  sqlite3_errmsg(db.get()) + " (counting the cycles)");
  }
  return results::ColumnReader(raw, file, "cycles").RequiredInteger(0);
}

bool PrintFaultTable(const std::filesystem::path& merged, std::ostream& out) {
  if (!std::filesystem::exists(merged)) return false;
  // Read-only and checked: the view's AVG and SUM run over values the typed reader accepted.
  const results::SqliteConnection db = results::OpenCheckedReadOnly(merged);
  sqlite3_stmt* raw = nullptr;
  if (sqlite3_prepare_v2(db.get(),
                         "SELECT fault_case, scenario, cycles, completed, mean_fill_rate, "
                         "safety_violations, safe_stops, recoveries, refused_frames, "
                         "min_clearance_m FROM fault_summary",
                         -1, &raw, nullptr) != SQLITE_OK) {
    sqlite3_finalize(raw);
    return false;
  }
  const Statement statement(raw, sqlite3_finalize);
  results::CheckCycleValues(db.get(), merged);
  out << "| fault | scenario | cycles | completed | mean fill | safety violations | safe stops | "
         "recoveries | late frames refused | min clearance m |\n"
         "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  results::ColumnReader read(raw, merged, "fault_summary");
  // NULL counts come from rows written before the counts were recorded.
  auto count = [&](int column) {
    const std::optional<std::int64_t> value = read.Integer(column);
    return value ? std::to_string(*value) : std::string("n/a");
  };
  // NULL: no cycle of the group measured it.
  auto number = [&](int column, double scale, const char* format,
                    results::ColumnReader::Infinity infinity) {
    const std::optional<double> value = read.Real(column, infinity);
    if (!value) return std::string("n/a");
    char text[48];
    std::snprintf(text, sizeof text, format, scale * *value);
    return std::string(text);
  };
  int rc = SQLITE_ROW;
  while ((rc = sqlite3_step(raw)) == SQLITE_ROW) {
    const std::string fault = read.Text(0), scenario = read.Text(1);
    read.SetRow("fault case '" + fault + "', scenario '" + scenario + "'");
    out << "| " << (fault.empty() ? std::string("(none)") : fault) << " | " << scenario << " | "
        << count(2) << " | " << count(3) << " | "
        << number(4, 100, "%.1f %%", results::ColumnReader::Infinity::kRefused) << " | " << count(5)
        << " | " << count(6) << " | " << count(7) << " | " << count(8) << " | "
        << number(9, 1, "%.2f", results::ColumnReader::Infinity::kPlusAllowed) << " |\n";
  }
  if (rc != SQLITE_DONE) {
    throw results::ResultsDbError(merged.string() + " is not a valid SQLite database: " +
                                  sqlite3_errmsg(db.get()) + " (reading fault_summary)");
  }
  return true;
}

void PrintCampaignSummary(const std::filesystem::path& merged, std::ostream& out) {
  const results::SqliteConnection db = results::OpenCheckedReadOnly(merged);
  // The aggregates below are only as good as the values: refuse text and infinities first.
  results::CheckCycleValues(db.get(), merged);
  const char* sql =
      "SELECT r.policy, count(*), sum(c.completed), avg(c.fill_rate), avg(c.time_scoop_s), "
      "avg(c.energy_scoop_kj), avg(c.time_total_s), avg(c.energy_total_kj), "
      "sum(c.safety_violations), min(c.safety_margin_m), count(c.fill_rate), "
      "count(c.time_scoop_s), count(c.energy_scoop_kj), count(c.time_total_s), "
      "count(c.energy_total_kj) FROM cycles c JOIN campaign_runs r USING (run_id) "
      "GROUP BY r.policy ORDER BY r.policy";
  sqlite3_stmt* raw = nullptr;
  if (sqlite3_prepare_v2(db.get(), sql, -1, &raw, nullptr) != SQLITE_OK) {
    const std::string why = sqlite3_errmsg(db.get());
    sqlite3_finalize(raw);
    throw results::ResultsDbError(merged.string() + ": not a campaign database: " + why);
  }
  const Statement statement(raw, sqlite3_finalize);
  out << "| policy | cycles | completed | mean fill | scoop s | scoop kJ | cycle s | cycle kJ | "
         "safety violations | min clearance m |\n| --- | --- | --- | --- | --- | --- | --- | --- "
         "| --- | --- |\n";
  results::ColumnReader read(raw, merged, "cycles");
  auto number = [&](int column, double scale, const char* format,
                    results::ColumnReader::Infinity infinity =
                        results::ColumnReader::Infinity::kRefused) {
    const std::optional<double> value = read.Real(column, infinity);
    if (!value) return std::string("n/a");  // no cycle of the policy measured it
    char text[48];
    std::snprintf(text, sizeof text, format, scale * *value);
    return std::string(text);
  };
  std::string notes;
  int rc = SQLITE_ROW;
  while ((rc = sqlite3_step(raw)) == SQLITE_ROW) {
    const std::string policy = read.Text(0);
    read.SetRow("policy '" + policy + "' (aggregate)");
    const long long cycles = read.RequiredInteger(1);
    out << "| " << policy << " | " << cycles << " | " << read.Integer(2).value_or(0) << " | "
        << number(3, 100, "%.1f %%") << " | " << number(4, 1, "%.2f") << " | "
        << number(5, 1, "%.1f") << " | " << number(6, 1, "%.1f") << " | " << number(7, 1, "%.0f")
        << " | " << read.Integer(8).value_or(0) << " | "
        << number(9, 1, "%.2f", results::ColumnReader::Infinity::kPlusAllowed) << " |\n";
    const char* names[] = {"fill_rate", "time_scoop_s", "energy_scoop_kj", "time_total_s",
                           "energy_total_kj"};
    for (int k = 0; k < 5; ++k) {
      const long long missing = cycles - read.RequiredInteger(10 + k);
      if (missing == 0) continue;
      notes += "- " + policy + ": " + names[k] + ": " + std::to_string(missing) + " of " +
               std::to_string(cycles) + " cycles not measured, left out of the mean\n";
    }
  }
  if (rc != SQLITE_DONE) {
    throw results::ResultsDbError(merged.string() + " is not a valid SQLite database: " +
                                  sqlite3_errmsg(db.get()) + " (summarizing the cycles)");
  }
  if (!notes.empty()) out << "\nNot measured (NULL):\n" << notes;
  // A fault campaign: the fault × scenario table too.
  sqlite3_stmt* faults = nullptr;
  bool fault_campaign = false;
  if (sqlite3_prepare_v2(db.get(), "SELECT count(*) FROM campaign_runs WHERE fault_case <> ''", -1,
                         &faults, nullptr) == SQLITE_OK &&
      sqlite3_step(faults) == SQLITE_ROW) {
    fault_campaign = results::ColumnReader(faults, merged, "campaign_runs").RequiredInteger(0) > 0;
  }
  sqlite3_finalize(faults);
  if (fault_campaign) {
    out << "\nFaults x scenarios (view fault_summary):\n";
    PrintFaultTable(merged, out);
  }
}

std::vector<std::filesystem::path> ShardFiles(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> files;
  if (!std::filesystem::is_directory(dir)) return files;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && name.starts_with("worker-") && name.ends_with(".sqlite")) {
      files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace autoshovel::app
