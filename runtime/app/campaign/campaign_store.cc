#include "runtime/app/campaign/campaign_store.h"

#include <sqlite3.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <ostream>
#include <stdexcept>

#include "runtime/results/results_db.h"

namespace autoshovel::app {
namespace {

struct CloseDb {
  void operator()(sqlite3* db) const { sqlite3_close(db); }
};
using Db = std::unique_ptr<sqlite3, CloseDb>;

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
      while (sqlite3_step(columns) == SQLITE_ROW) {
        const unsigned char* name = sqlite3_column_text(columns, 0);
        has_fault_case |=
            name != nullptr && std::string(reinterpret_cast<const char*>(name)) == "fault_case";
      }
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
  sqlite3_stmt* statement = nullptr;
  long long count = 0;
  if (sqlite3_prepare_v2(db.get(), "SELECT count(*) FROM cycles", -1, &statement, nullptr) ==
          SQLITE_OK &&
      sqlite3_step(statement) == SQLITE_ROW) {
    count = sqlite3_column_int64(statement, 0);
  }
  sqlite3_finalize(statement);
  return count;
}

bool PrintFaultTable(const std::filesystem::path& merged, std::ostream& out) {
  if (!std::filesystem::exists(merged)) return false;
  Db db = Open(merged, SQLITE_OPEN_READONLY);
  sqlite3_stmt* s = nullptr;
  if (sqlite3_prepare_v2(db.get(),
                         "SELECT fault_case, scenario, cycles, completed, mean_fill_rate, "
                         "safety_violations, safe_stops, recoveries, refused_frames, "
                         "min_clearance_m FROM fault_summary",
                         -1, &s, nullptr) != SQLITE_OK) {
    sqlite3_finalize(s);
    return false;
  }
  out << "| fault | scenario | cycles | completed | mean fill | safety violations | safe stops | "
         "recoveries | late frames refused | min clearance m |\n"
         "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  auto text = [&](int column) {
    const unsigned char* t = sqlite3_column_text(s, column);
    return t == nullptr ? std::string("?") : std::string(reinterpret_cast<const char*>(t));
  };
  // NULL counts come from rows written before the counts were recorded.
  auto count = [&](int column) {
    return sqlite3_column_type(s, column) == SQLITE_NULL ? std::string("n/a") : text(column);
  };
  while (sqlite3_step(s) == SQLITE_ROW) {
    char numbers[96];
    std::snprintf(numbers, sizeof numbers, "%.1f %%", 100 * sqlite3_column_double(s, 4));
    char clearance[32];
    std::snprintf(clearance, sizeof clearance, "%.2f", sqlite3_column_double(s, 9));
    out << "| " << (text(0).empty() ? std::string("(none)") : text(0)) << " | " << text(1) << " | "
        << text(2) << " | " << text(3) << " | " << numbers << " | " << count(5) << " | " << count(6)
        << " | " << count(7) << " | " << count(8) << " | " << clearance << " |\n";
  }
  sqlite3_finalize(s);
  return true;
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
