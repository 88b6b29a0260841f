// `autoshovel train segmentation` (train_segmentation.h).
#include "runtime/app/train_segmentation.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <vector>

#include "runtime/core/file_output.h"

extern char** environ;

namespace autoshovel::app {
namespace {

namespace fs = std::filesystem;
constexpr const char* kCommand = "autoshovel train segmentation";

// Runs `args` with stdout and stderr to `log`; returns the exit status (127: could not start).
int Run(const std::vector<std::string>& args, const fs::path& log) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  std::vector<std::string> copy = args;
  std::vector<char*> argv;
  for (std::string& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) return 127;
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

std::string ReadFile(const fs::path& file) {
  std::ifstream in(file);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The "| **mean IoU** | **a** | **b** | **c** | **d** |" line of segmentation_eval: all views.
std::string MeanIou(const std::string& report) {
  const std::size_t at = report.find("| **mean IoU** | **");
  if (at == std::string::npos) return "?";
  const std::size_t from = at + std::string("| **mean IoU** | **").size();
  return report.substr(from, report.find("**", from) - from);
}

// The table of segmentation_eval's report (its lines that start with '|').
std::string Table(const std::string& report) {
  std::istringstream in(report);
  std::string line, table;
  while (std::getline(in, line)) {
    if (line.starts_with("|")) table += line + "\n";
  }
  return table;
}

}  // namespace

int RunTrainSegmentation(const TrainSegmentationOptions& o, std::ostream& out, std::ostream& err) {
  const fs::path self = fs::read_symlink("/proc/self/exe");
  const fs::path tools = self.parent_path();
  const fs::path source = fs::path(AUTOSHOVEL_SOURCE_DIR);
  const fs::path train_py = source / "identification" / "segmentation" / "train.py";
  const fs::path shipped_dir = fs::path(o.models_dir) / "segmentation";
  const fs::path base = o.base.empty() ? shipped_dir / "yard_segmenter.onnx" : o.base;
  if (o.scenario.empty() || o.out.empty()) {
    err << kCommand << ": give the site's scenario and -o for the new network\n";
    return 2;
  }
  if (o.views < 10 || o.heldout < 3 || o.steps < 1 || o.jobs < 1 || !(o.learning_rate > 0)) {
    err << kCommand << ": --views >= 10, --heldout >= 3, --steps >= 1, --jobs >= 1, --lr > 0\n";
    return 2;
  }
  // The shipped network stays as it is: no output into its folder.
  std::error_code ec;
  const fs::path out_dir = fs::weakly_canonical(fs::absolute(o.out).parent_path(), ec);
  if (out_dir == fs::weakly_canonical(fs::absolute(shipped_dir), ec)) {
    err << kCommand << ": " << o.out.string() << " is in " << shipped_dir.string()
        << ", the shipped network's folder; write the new network elsewhere\n";
    return 2;
  }
  if (!fs::exists(base)) {
    err << kCommand << ": base network " << base.string() << " not found\n";
    return 2;
  }
  for (const fs::path& tool : {tools / "segmentation_dataset", tools / "segmentation_eval"}) {
    if (!fs::exists(tool)) {
      err << kCommand << ": " << tool.string()
          << " not found (build it: cmake --build build --target " << tool.filename().string()
          << ")\n";
      return 2;
    }
  }
  const fs::path work = o.work_dir.empty() ? fs::path(o.out.string() + ".data") : o.work_dir;
  core::CreateFolders(work);
  core::CreateFolders(o.out.parent_path());
  const fs::path python = "/usr/bin/python3";
  if (Run({python.string(), "-c", "import torch, onnx"}, work / "python_check.log") != 0) {
    err << kCommand << ": " << python.string()
        << " cannot import torch and onnx; install Debian's python3-torch and python3-onnx "
           "(scripts/setup does)\n";
    return 2;
  }

  const std::string jobs = std::to_string(o.jobs);
  struct Step {
    std::string what;
    std::vector<std::string> args;
    fs::path log;
  };
  const fs::path train_data = work / "train", heldout_data = work / "heldout";
  fs::remove_all(train_data);
  fs::remove_all(heldout_data);
  const std::vector<Step> steps = {
      {"render " + std::to_string(o.views) + " training views of " + o.scenario,
       {(tools / "segmentation_dataset").string(), "--out", train_data.string(), "--count",
        std::to_string(o.views), "--seed", std::to_string(o.seed), "--scenarios", o.scenario,
        "--models", o.models_dir, "--jobs", jobs},
       work / "render_train.log"},
      {"render " + std::to_string(o.heldout) + " held-out views (seed " +
           std::to_string(o.seed + 1000) + ")",
       {(tools / "segmentation_dataset").string(), "--out", heldout_data.string(), "--count",
        std::to_string(o.heldout), "--seed", std::to_string(o.seed + 1000), "--split", "test",
        "--scenarios", o.scenario, "--models", o.models_dir, "--jobs", jobs},
       work / "render_heldout.log"},
      {"score the base network " + base.string() + " on the held-out views",
       {(tools / "segmentation_eval").string(), "--model", base.string(), "--data",
        heldout_data.string(), "--models", o.models_dir, "--threads", jobs},
       work / "eval_before.log"},
      {"fine-tune for " + std::to_string(o.steps) + " steps",
       {python.string(), train_py.string(),
        "--data",        train_data.string(),
        "--out",         o.out.string(),
        "--init-onnx",   base.string(),
        "--iters",       std::to_string(o.steps),
        "--lr",          std::to_string(o.learning_rate),
        "--eval-every",  std::to_string(o.steps + 1),
        "--threads",     jobs,
        "--seed",        std::to_string(o.seed),
        "--log",         (work / "train_log.json").string()},
       work / "train.log"},
      {"score the new network on the held-out views",
       {(tools / "segmentation_eval").string(), "--model", o.out.string(), "--data",
        heldout_data.string(), "--models", o.models_dir, "--threads", jobs},
       work / "eval_after.log"},
  };
  for (std::size_t k = 0; k < steps.size(); ++k) {
    out << "[" << k + 1 << "/" << steps.size() << "] " << steps[k].what << " ..." << std::flush;
    const int rc = Run(steps[k].args, steps[k].log);
    out << (rc == 0 ? " done\n" : " FAILED\n") << std::flush;
    if (rc != 0) {
      err << kCommand << ": step " << k + 1 << " failed (exit " << rc << "); its log, "
          << steps[k].log.string() << ", ends with:\n";
      const std::string log = ReadFile(steps[k].log);
      err << log.substr(log.size() > 2000 ? log.size() - 2000 : 0) << "\n";
      return 1;
    }
  }
  const std::string before = ReadFile(work / "eval_before.log");
  const std::string after = ReadFile(work / "eval_after.log");
  out << "\nheld-out views of " << o.scenario << " (" << o.heldout << ", seed " << o.seed + 1000
      << "), IoU %\n\nbefore: " << base.string() << "\n\n"
      << Table(before) << "\nafter: " << o.out.string() << "\n\n"
      << Table(after) << "\nmean IoU, all views: " << MeanIou(before) << " % before, "
      << MeanIou(after) << " % after\nnew network: " << o.out.string()
      << "\nlogs and data: " << work.string() << "\n";
  return 0;
}

}  // namespace autoshovel::app
