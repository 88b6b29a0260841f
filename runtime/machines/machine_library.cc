#include "runtime/machines/machine_library.h"

#include <dlfcn.h>

#include <cstring>

#include "runtime/machines/machine_abi.h"

namespace autoshovel::machines {

std::string RunningAbiTag() {
  return AbiTagPrefix(CompiledInterfaceHeaderText()) +
         std::to_string(sizeof(generated::MachineFunctions)) + "/" +
         AUTOSHOVEL_MACHINE_ABI_TOOLCHAIN;
}

LibraryLoad LoadMachineLibrary(const std::string& machine, const std::string& sha256,
                               const std::filesystem::path& root) {
  LibraryLoad load;
  LibraryCheck check = CheckMachineLibrary(machine, sha256, RunningAbiTag(), root);
  load.status = check.status;
  load.library = check.library;
  load.reason = check.reason;
  if (check.status != LibraryCheck::Status::kValid) return load;
  auto refuse = [&](const std::string& why) {
    load.status = LibraryCheck::Status::kRefused;
    load.reason = why;
    return load;
  };

  // Through the descriptor that was checked: a file swapped in after the check is not loaded.
  const std::string by_fd = "/proc/self/fd/" + std::to_string(check.file.fd());
  void* handle = dlopen(by_fd.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* error = dlerror();
    return refuse(load.library.string() + ": cannot load: " + (error ? error : "dlopen failed"));
  }
  using StringEntry = const char* (*)();
  using FunctionsEntry = const generated::MachineFunctions* (*)();
  const auto abi = reinterpret_cast<StringEntry>(dlsym(handle, kAbiTagSymbol));
  const auto source = reinterpret_cast<StringEntry>(dlsym(handle, kSourceSha256Symbol));
  const auto functions = reinterpret_cast<FunctionsEntry>(dlsym(handle, kFunctionsSymbol));
  if (abi == nullptr || source == nullptr || functions == nullptr) {
    dlclose(handle);
    return refuse("not a machine library: " + load.library.string() + " lacks " + kFunctionsSymbol +
                  ", " + kAbiTagSymbol + " or " + kSourceSha256Symbol);
  }
  const std::string running = RunningAbiTag();
  if (running != abi()) {
    const std::string tag = abi();
    dlclose(handle);
    return refuse("foreign: " + load.library.string() + " reports ABI " + tag +
                  ", this autoshovel is " + running);
  }
  if (sha256 != source()) {
    const std::string reported = source();
    dlclose(handle);
    return refuse("stale: " + load.library.string() + " reports description SHA-256 " + reported +
                  ", the description's is " + sha256);
  }
  const generated::MachineFunctions* f = functions();
  if (f == nullptr || f->name == nullptr || f->source_sha256 == nullptr || machine != f->name ||
      sha256 != f->source_sha256) {
    dlclose(handle);
    return refuse("not a machine library: " + load.library.string() +
                  " describes another machine than '" + machine + "'");
  }
  load.functions = f;  // the handle is kept: the functions live as long as the process
  // So is the descriptor: the loader knows the library by the name /proc/self/fd/N and would
  // take a later library opened at the same N for this one.
  check.file.Release();
  return load;
}

}  // namespace autoshovel::machines
