// The run folder of `autoshovel run` (DESIGN.md, "Outputs"): one directory per run holding the
// resolved configuration, the results database, the log, report.html and its figures.
//
//   runs/2025-06-01T12-00-00Z/   (default name: UTC start time; `-o DIR` chooses another)
//     config.yaml     resolved configuration
//     results.sqlite  results database (results_db.h)
//     log.txt         RunLog lines
//     report.html     report (report.h), linking figures/*.png
//     figures/        PNG figures
//
// Layout and guarantees: docs/results_and_reports.md.
#pragma once

#include <cstdio>
#include <filesystem>
#include <iosfwd>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace autoshovel::results {

enum class LogLevel { kDebug = 0, kInfo = 1, kWarning = 2, kError = 3 };

/// "DEBUG", "INFO", "WARN", "ERROR".
std::string_view LogLevelName(LogLevel level);

/// A small append-only logger. Each line carries the wall time (UTC, ms), the simulated time and
/// the level:
///   2025-06-01T12:00:00.123Z  sim=    12.350 s  INFO   crowd: triggered at V1+V2 = 2.9 m3
/// The simulated time is the last value given to SetSimulatedTime ("sim=         - s" before the
/// first). Lines below the minimum level are dropped. Every line is flushed when written, so a
/// killed run keeps its log up to the last line. Safe to call from several threads.
class RunLog {
 public:
  /// Opens (appends to) `path`. Throws std::runtime_error naming the file when it cannot.
  explicit RunLog(const std::filesystem::path& path, LogLevel min_level = LogLevel::kInfo);
  ~RunLog();
  RunLog(const RunLog&) = delete;
  RunLog& operator=(const RunLog&) = delete;

  /// @param t_s simulated time [s]; NaN means "not running" and prints "-".
  void SetSimulatedTime(double t_s);
  void SetMinLevel(LogLevel level);

  void Log(LogLevel level, std::string_view message);
  void Debug(std::string_view message) { Log(LogLevel::kDebug, message); }
  void Info(std::string_view message) { Log(LogLevel::kInfo, message); }
  void Warning(std::string_view message) { Log(LogLevel::kWarning, message); }
  void Error(std::string_view message) { Log(LogLevel::kError, message); }

  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  std::FILE* file_ = nullptr;
  std::mutex mutex_;
  LogLevel min_level_;
  double sim_time_s_;
};

/// A resolved configuration as flat key/values. Dotted keys nest: {"plant.rate_hz", "100"}
/// becomes `plant:\n  rate_hz: 100`. Values are written as YAML scalars (quoted when needed).
using KeyValues = std::vector<std::pair<std::string, std::string>>;

struct RunFolderOptions {
  /// The run folder. Empty: `<root>/<UTC timestamp>` (a new, unique folder).
  std::filesystem::path dir;
  /// Parent of the timestamped folders when `dir` is empty.
  std::filesystem::path root = "runs";
  /// Reopen an existing run folder (`dir` required, must exist) to complete an interrupted run.
  /// Without it an existing non-empty `dir` is refused, so no run overwrites another's results.
  bool resume = false;
  LogLevel log_level = LogLevel::kInfo;
};

class RunFolder {
 public:
  /// Creates (or, with `resume`, reopens) the folder and its figures/ subfolder and opens
  /// log.txt for appending. Throws std::runtime_error naming the folder when it is refused.
  explicit RunFolder(const RunFolderOptions& options);

  const std::filesystem::path& dir() const { return dir_; }
  /// The folder's name: the default run id of the results database.
  std::string name() const { return dir_.filename().string(); }
  bool resumed() const { return resumed_; }

  std::filesystem::path ConfigPath() const { return dir_ / "config.yaml"; }
  std::filesystem::path DatabasePath() const { return dir_ / "results.sqlite"; }
  std::filesystem::path LogPath() const { return dir_ / "log.txt"; }
  std::filesystem::path ReportPath() const { return dir_ / "report.html"; }
  /// `figures/<file_name>`, e.g. FigurePath("volume_cycle_3.png").
  std::filesystem::path FigurePath(std::string_view file_name) const;

  /// Writes config.yaml (atomically: a temporary file renamed over it). When resuming and a
  /// config.yaml exists, it must be identical, otherwise throws std::runtime_error naming it:
  /// a resumed run with another configuration would mix incomparable rows.
  /// @param yaml a YAML document, written as given (a final newline is added if missing).
  void WriteConfig(std::string_view yaml);
  void WriteConfig(const KeyValues& key_values);

  RunLog& log() { return *log_; }

  /// A new run folder at `dir` (empty: timestamped under runs/) with `config_yaml` written, or
  /// null after one line on `err`, "<who>: <why>", when the folder or its configuration is
  /// refused: the start every `autoshovel run` job shares.
  static std::unique_ptr<RunFolder> OpenWithConfig(const std::filesystem::path& dir,
                                                   std::string_view config_yaml, std::ostream& err,
                                                   std::string_view who);

 private:
  std::filesystem::path dir_;
  bool resumed_ = false;
  std::unique_ptr<RunLog> log_;
};

/// The YAML text WriteConfig(KeyValues) writes. Throws std::invalid_argument for an empty key
/// or one that is both a value and a parent (`a: 1` and `a.b: 2`).
std::string KeyValuesToYaml(const KeyValues& key_values);

/// Current UTC time as `2025-06-01T12-00-00Z` (a file-name-safe ISO 8601 form).
std::string UtcTimestampForFileName();
/// Current UTC time as `2025-06-01T12:00:00.123Z`.
std::string UtcTimestampIso();

}  // namespace autoshovel::results
