#include "codegen/generate.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <ostream>
#include <set>

#include "codegen/compile_library.h"
#include "codegen/emitter.h"
#include "runtime/core/diagnostics.h"
#include "runtime/model/description.h"

namespace autoshovel::codegen {

namespace fs = std::filesystem;

std::vector<std::string> FindDescriptions(const std::string& models_dir) {
  return model::FindMachineDescriptions(models_dir);
}

namespace {

// Emits one machine in a child process that starts from the parent's state, which has built
// no GiNaC expression. Why: GiNaC numbers symbols from a process-wide counter and orders the
// operands of sums and products by it, and it folds numeric coefficients in that order, so the
// same description printed after another machine was built in the same process came out in a
// different term order and, for some constants, rounded differently (issue 39). A fresh child
// per machine makes the output a function of the description (and the generator binary) alone.
// Returns the child's exit status; errors are written by the child to standard error.
int EmitInChild(const model::MachineDescription& machine, const EmitOptions& options) {
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  const pid_t child = fork();
  if (child < 0) {
    throw std::runtime_error(std::string("cannot start a generator process: ") +
                             std::strerror(errno));
  }
  if (child == 0) {
    int status = 0;
    try {
      EmitMachine(machine, options);
    } catch (const fs::filesystem_error& e) {
      std::cerr << "codegen: " << e.path1().string() << ": cannot write: " << e.code().message()
                << '\n';
      status = 1;
    } catch (const std::exception& e) {
      std::cerr << "codegen: " << e.what() << '\n';
      status = 1;
    }
    std::cerr.flush();
    _exit(status);
  }
  int status = 0;
  while (waitpid(child, &status, 0) < 0) {
    if (errno != EINTR) throw std::runtime_error("cannot wait for the generator process");
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  std::cerr << "codegen: generating " << machine.name << " was killed by signal "
            << (WIFSIGNALED(status) ? WTERMSIG(status) : 0) << '\n';
  return 2;
}

}  // namespace

int Generate(const GenerateRequest& request, std::ostream& out, std::ostream& err) {
  std::vector<std::string> descriptions = request.descriptions;
  if (!request.models_dir.empty()) {
    const auto found = FindDescriptions(request.models_dir);
    descriptions.insert(descriptions.end(), found.begin(), found.end());
    if (found.empty()) {
      err << request.models_dir << ": no machine descriptions found\n";
      return 1;
    }
  }
  if (descriptions.empty()) {
    err << "codegen: no description given\n";
    return 1;
  }
  // Load everything first: nothing is written unless every description is valid.
  std::vector<model::MachineDescription> machines;
  bool invalid = false;
  for (const auto& path : descriptions) {
    try {
      model::LoadOptions options;
      options.materials_dir = request.materials_dir;
      machines.push_back(model::LoadMachineDescription(path, options));
    } catch (const core::InputError& e) {
      for (const auto& d : e.diagnostics()) err << d.ToString() << '\n';
      invalid = true;
    }
  }
  if (invalid) return 1;
  std::set<std::string> names;
  for (const auto& m : machines) {
    if (!names.insert(m.name).second) {
      err << m.source_file << ":1:1: name: machine name '" << m.name
          << "' is used by another description\n";
      return 1;
    }
  }
  try {
    EmitOptions options{request.output_dir, ""};
    for (const auto& m : machines) {
      // Said once the files are written, never before (a failed write is not a success).
      if (const int status = EmitInChild(m, options); status != 0) return status;
      out << "codegen: " << m.source_file << " -> " << (request.output_dir / m.name).string() << "/"
          << std::endl;
    }
    if (request.clean && fs::is_directory(request.output_dir)) {
      for (const auto& entry : fs::directory_iterator(request.output_dir)) {
        if (entry.is_directory() && fs::exists(entry.path() / ".autoshovel-machine") &&
            names.count(entry.path().filename().string()) == 0) {
          out << "codegen: removing stale " << entry.path().string() << "/" << std::endl;
          fs::remove_all(entry.path());
        }
      }
      EmitRegistry(options);
    }
  } catch (const fs::filesystem_error& e) {
    // std::filesystem's what() is "filesystem error: cannot create directories: ... [path]":
    // said here as the path and the reason, like every other write failure.
    err << "codegen: " << e.path1().string() << ": cannot write: " << e.code().message() << '\n';
    return 1;
  } catch (const std::exception& e) {
    err << "codegen: " << e.what() << '\n';
    return 1;
  }
  if (request.compile) {
    CompileOptions options;
    options.cache_root = request.cache_root;
    options.expected_abi = request.expected_abi;
    return CompileGenerated(machines, request.output_dir, options, out, err);
  }
  return 0;
}

}  // namespace autoshovel::codegen
