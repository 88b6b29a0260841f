// Loading a machine library from the cache (runtime/machines/machine_cache.h) with dlopen, after
// every check there has passed.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "generated/machine_functions.h"
#include "runtime/machines/machine_cache.h"

namespace autoshovel::machines {

/// The text of generated/machine_functions.h this binary was compiled with (embedded at build
/// time): its hash is part of the ABI tag.
std::string_view CompiledInterfaceHeaderText();

/// This binary's ABI tag: AbiTagPrefix(interface), sizeof(MachineFunctions), compiler and C++
/// library major versions, e.g. "v1/interface=0123456789abcdef/functions=176/gcc-12/libstdc++-12".
std::string RunningAbiTag();

/// The outcome of looking a machine up in the cache.
struct LibraryLoad {
  LibraryCheck::Status status = LibraryCheck::Status::kMissing;
  const generated::MachineFunctions* functions = nullptr;  ///< kValid: never unloaded
  std::filesystem::path library;                           ///< the file looked at
  std::string reason;                                      ///< kMissing / kRefused: why
};

/// Checks (CheckMachineLibrary with RunningAbiTag) and loads (RTLD_NOW | RTLD_LOCAL) the
/// library of `machine` built from a description with SHA-256 `sha256`; after loading, the
/// strings its entry points return and the machine it describes must agree again. A loaded
/// library stays loaded for the life of the process.
LibraryLoad LoadMachineLibrary(const std::string& machine, const std::string& sha256,
                               const std::filesystem::path& root);

}  // namespace autoshovel::machines
