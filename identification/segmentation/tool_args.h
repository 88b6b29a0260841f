// Minimal `--key value` argument reading for the segmentation tools (CLI11 is slow to compile and
// these tools take a handful of options).
#pragma once

#include <atomic>
#include <cstdint>
#include <iostream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace autoshovel::identification {

class ToolArgs {
 public:
  /// `known`: accepted option names without the leading "--". "--help" / "-h" sets help().
  ToolArgs(int argc, char** argv, const std::set<std::string>& known) {
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--help" || a == "-h") {
        help_ = true;
        continue;
      }
      if (a.rfind("--", 0) != 0 || !known.count(a.substr(2))) {
        throw std::invalid_argument("unknown argument '" + a + "' (see --help)");
      }
      if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
      values_[a.substr(2)] = argv[++i];
    }
  }

  bool help() const { return help_; }
  bool has(const std::string& key) const { return values_.count(key) > 0; }
  std::string String(const std::string& key, const std::string& fallback) const {
    const auto it = values_.find(key);
    return it == values_.end() ? fallback : it->second;
  }
  std::int64_t Int(const std::string& key, std::int64_t fallback) const {
    const auto it = values_.find(key);
    if (it == values_.end()) return fallback;
    std::size_t used = 0;
    std::int64_t v = 0;
    try {
      v = std::stoll(it->second, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != it->second.size()) {
      throw std::invalid_argument("--" + key + ": expected an integer, got '" + it->second + "'");
    }
    return v;
  }
  /// A comma-separated list; empty when absent.
  std::vector<std::string> List(const std::string& key) const {
    std::vector<std::string> out;
    std::stringstream ss(String(key, ""));
    for (std::string item; std::getline(ss, item, ',');) {
      if (!item.empty()) out.push_back(item);
    }
    return out;
  }

 private:
  std::map<std::string, std::string> values_;
  bool help_ = false;
};

/// Runs body(k) for k in [0, count) on `jobs` threads, each taking the next index. The first
/// exception stops the others from taking more and is rethrown (as std::runtime_error) here.
template <typename Body>
void ParallelFor(std::int64_t count, std::int64_t jobs, Body&& body) {
  std::atomic<std::int64_t> next{0};
  std::mutex error_mutex;
  std::string error;
  auto worker = [&] {
    for (std::int64_t k = next++; k < count; k = next++) {
      try {
        body(k);
      } catch (const std::exception& e) {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (error.empty()) error = e.what();
        next = count;
      }
    }
  };
  std::vector<std::thread> threads;
  for (std::int64_t j = 0; j < jobs; ++j) threads.emplace_back(worker);
  for (std::thread& t : threads) t.join();
  if (!error.empty()) throw std::runtime_error(error);
}

/// A tool's main: runs `run`, turning an escaped exception into "<tool>: <what>" and exit 1.
inline int RunTool(const char* tool, int (*run)(int, char**), int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << tool << ": " << e.what() << '\n';
    return 1;
  }
}

}  // namespace autoshovel::identification
