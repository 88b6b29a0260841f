#include "runtime/app/campaign/campaign_store.h"

#include <sqlite3.h>

#include <algorithm>
#include <memory>
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
          "INTEGER NOT NULL, cycles_planned INTEGER NOT NULL)",
          where);
  Execute(db.get(), "BEGIN", where);
  for (const CampaignJob& job : jobs) {
    Execute(db.get(),
            "INSERT OR IGNORE INTO campaign_runs VALUES (" + Quote(job.run_id) + ", " +
                Quote(spec.name) + ", " + std::to_string(job.week) + ", " +
                std::to_string(job.shift) + ", " + Quote(job.policy) + ", " +
                std::to_string(static_cast<std::int64_t>(job.seed)) + ", " +
                std::to_string(spec.cycles_per_shift) + ")",
            where);
  }
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
