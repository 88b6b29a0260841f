#include "runtime/results/run_folder.h"

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <ctime>
#include <fstream>
#include <limits>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "runtime/core/file_output.h"

namespace autoshovel::results {
namespace fs = std::filesystem;

namespace {

std::tm UtcNow(int* milliseconds) {
  const auto now = std::chrono::system_clock::now();
  const std::time_t seconds = std::chrono::system_clock::to_time_t(now);
  if (milliseconds != nullptr) {
    *milliseconds = static_cast<int>(
        std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() %
        1000);
  }
  std::tm utc{};
  gmtime_r(&seconds, &utc);
  return utc;
}

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

std::string UtcTimestampForFileName() {
  const std::tm utc = UtcNow(nullptr);
  char buffer[32];
  std::strftime(buffer, sizeof(buffer), "%Y-%m-%dT%H-%M-%SZ", &utc);
  return buffer;
}

std::string UtcTimestampIso() {
  int ms = 0;
  const std::tm utc = UtcNow(&ms);
  char buffer[32];
  std::strftime(buffer, sizeof(buffer), "%Y-%m-%dT%H:%M:%S", &utc);
  char out[48];
  std::snprintf(out, sizeof(out), "%s.%03dZ", buffer, ms);
  return out;
}

std::string_view LogLevelName(LogLevel level) {
  switch (level) {
    case LogLevel::kDebug:
      return "DEBUG";
    case LogLevel::kInfo:
      return "INFO";
    case LogLevel::kWarning:
      return "WARN";
    case LogLevel::kError:
      return "ERROR";
  }
  return "?";
}

RunLog::RunLog(const fs::path& path, LogLevel min_level)
    : path_(path), min_level_(min_level), sim_time_s_(std::numeric_limits<double>::quiet_NaN()) {
  file_ = std::fopen(path.c_str(), "a");
  if (file_ == nullptr) {
    throw std::runtime_error(path.string() + ": cannot open the log for appending");
  }
}

RunLog::~RunLog() {
  if (file_ != nullptr) std::fclose(file_);
}

void RunLog::SetSimulatedTime(double t_s) {
  std::lock_guard lock(mutex_);
  sim_time_s_ = t_s;
}

void RunLog::SetMinLevel(LogLevel level) {
  std::lock_guard lock(mutex_);
  min_level_ = level;
}

void RunLog::Log(LogLevel level, std::string_view message) {
  std::lock_guard lock(mutex_);
  if (level < min_level_) return;
  char sim[32];
  if (std::isnan(sim_time_s_)) {
    std::snprintf(sim, sizeof(sim), "%10s", "-");
  } else {
    std::snprintf(sim, sizeof(sim), "%10.3f", sim_time_s_);
  }
  const std::string name(LogLevelName(level));
  const int written =
      std::fprintf(file_, "%s  sim=%s s  %-5s  %.*s\n", UtcTimestampIso().c_str(), sim,
                   name.c_str(), static_cast<int>(message.size()), message.data());
  // A log line lost to a full disk is a lost record: the run stops rather than go on unlogged.
  if (written < 0 || std::fflush(file_) != 0) {
    const int error_number = errno;
    std::clearerr(file_);
    throw core::OutputError(path_, std::strerror(error_number));
  }
}

std::string KeyValuesToYaml(const KeyValues& key_values) {
  YAML::Node root(YAML::NodeType::Map);
  for (const auto& [key, value] : key_values) {
    if (key.empty()) throw std::invalid_argument("config: empty key (value '" + value + "')");
    std::vector<std::string> parts;
    std::size_t start = 0;
    while (true) {
      const std::size_t dot = key.find('.', start);
      parts.push_back(key.substr(start, dot - start));
      if (parts.back().empty()) {
        throw std::invalid_argument("config: key '" + key + "' has an empty component");
      }
      if (dot == std::string::npos) break;
      start = dot + 1;
    }
    YAML::Node node = root;
    for (std::size_t i = 0; i < parts.size(); ++i) {
      YAML::Node child = node[parts[i]];
      const bool last = i + 1 == parts.size();
      if (child.IsDefined() && !child.IsNull() && (last || !child.IsMap())) {
        throw std::invalid_argument("config: key '" + key +
                                    "' conflicts with another key (given twice, or both a value "
                                    "and a parent)");
      }
      if (last) {
        child = value;
      } else if (!child.IsDefined() || child.IsNull()) {
        child = YAML::Node(YAML::NodeType::Map);
      }
      node.reset(child);
    }
  }
  YAML::Emitter out;
  out << root;
  std::string text = out.c_str();
  if (key_values.empty()) text = "{}";
  return text + "\n";
}

RunFolder::RunFolder(const RunFolderOptions& options) {
  std::error_code error;
  if (options.resume) {
    if (options.dir.empty()) {
      throw std::runtime_error("run folder: resuming needs the folder of the interrupted run");
    }
    if (!fs::is_directory(options.dir)) {
      throw std::runtime_error(options.dir.string() +
                               ": cannot resume: no such run folder (is the path right?)");
    }
    dir_ = options.dir;
    resumed_ = true;
  } else if (!options.dir.empty()) {
    dir_ = options.dir;
    if (fs::exists(dir_)) {
      if (!fs::is_directory(dir_)) {
        throw std::runtime_error(dir_.string() + ": exists and is not a folder");
      }
      if (!fs::is_empty(dir_)) {
        throw std::runtime_error(dir_.string() +
                                 ": run folder is not empty; choose another (a run never "
                                 "writes over earlier results)");
      }
    }
    fs::create_directories(dir_, error);
    if (error) throw std::runtime_error(dir_.string() + ": cannot create: " + error.message());
  } else {
    fs::create_directories(options.root, error);
    if (error) {
      throw std::runtime_error(options.root.string() + ": cannot create: " + error.message());
    }
    // create_directory is atomic: two runs started in the same second get -1, -2, ...
    const std::string stamp = UtcTimestampForFileName();
    for (int suffix = 0;; ++suffix) {
      fs::path candidate =
          options.root / (suffix == 0 ? stamp : stamp + "-" + std::to_string(suffix));
      if (fs::create_directory(candidate, error)) {
        dir_ = candidate;
        break;
      }
      if (error) {
        throw std::runtime_error(candidate.string() + ": cannot create: " + error.message());
      }
      if (suffix > 1000) throw std::runtime_error(candidate.string() + ": too many runs");
    }
  }
  fs::create_directories(dir_ / "figures", error);
  if (error) {
    throw std::runtime_error((dir_ / "figures").string() + ": cannot create: " + error.message());
  }
  log_ = std::make_unique<RunLog>(LogPath(), options.log_level);
}

std::unique_ptr<RunFolder> RunFolder::OpenWithConfig(const fs::path& dir,
                                                     std::string_view config_yaml,
                                                     std::ostream& err, std::string_view who) {
  RunFolderOptions options;
  options.dir = dir;
  try {
    auto folder = std::make_unique<RunFolder>(options);
    folder->WriteConfig(config_yaml);
    return folder;
  } catch (const std::exception& e) {
    err << who << ": " << e.what() << "\n";
    return nullptr;
  }
}

fs::path RunFolder::FigurePath(std::string_view file_name) const {
  return dir_ / "figures" / fs::path(file_name);
}

void RunFolder::WriteConfig(std::string_view yaml) {
  std::string text(yaml);
  if (text.empty() || text.back() != '\n') text += '\n';
  const fs::path path = ConfigPath();
  if (resumed_ && fs::exists(path)) {
    if (ReadFile(path) != text) {
      throw std::runtime_error(path.string() +
                               ": the resumed run's configuration differs from this one; resume "
                               "with the same configuration or start a new run");
    }
    return;
  }
  core::WriteFileAtomically(path, text);
}

void RunFolder::WriteConfig(const KeyValues& key_values) {
  WriteConfig(KeyValuesToYaml(key_values));
}

}  // namespace autoshovel::results
