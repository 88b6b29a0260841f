// `autoshovel gen`'s last step (issue 39): the generated code of a machine compiled into a
// machine library in the per-user cache (runtime/machines/machine_cache.h), so that every
// command can load it without rebuilding autoshovel.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "runtime/model/description.h"

namespace autoshovel::codegen {

/// Flags every machine library is compiled with (the sources' folder and output follow).
inline constexpr const char* kLibraryFlags = "-std=c++20 -O2 -fPIC -shared -fvisibility=hidden";

struct CompileOptions {
  std::filesystem::path cache_root;  ///< empty: machines::DefaultCacheRoot()
  /// The ABI tag of the autoshovel that will load the library (`autoshovel gen` passes its
  /// own): a library with another tag is a failure now rather than a refusal later. Empty: the
  /// tag must only name this generator's toolchain and the interface header it emitted.
  std::string expected_abi;
  /// Tests only: the ABI tag the library embeds instead of its real one (a foreign build).
  std::string abi_tag_override;
};

struct CompileOutcome {
  enum class Status { kBuilt, kNoCompiler, kFailed };
  Status status = Status::kFailed;
  std::filesystem::path library;  ///< kBuilt
  std::string message;            ///< kNoCompiler / kFailed: why (compiler output included)
};

/// Compiles the code EmitMachine wrote for `machine` into `generated_dir` (its
/// `<name>/<name>.{h,cc}` and the interface header `machine_functions.h`), with an entry
/// source exporting the library's functions, its ABI tag and the description's SHA-256, into
/// `<cache root>/<sha256>/lib<name>.so` beside a manifest; a progress line goes to `progress`
/// while the compiler runs. The folder is built aside and renamed into place, then checked as
/// a loader would check it.
CompileOutcome CompileMachineLibrary(const model::MachineDescription& machine,
                                     const std::filesystem::path& generated_dir,
                                     const CompileOptions& options, std::ostream& progress);

/// `gen`'s step after emitting into `generated_dir`: CompileMachineLibrary for each machine,
/// a line per library on `out`, failures (with the compiler's output) on `err`. No compiler at
/// all is not a failure: it is said on `err` with what commands will do instead. Returns 0, or
/// 2 when a library could not be built.
int CompileGenerated(const std::vector<model::MachineDescription>& machines,
                     const std::filesystem::path& generated_dir, const CompileOptions& options,
                     std::ostream& out, std::ostream& err);

}  // namespace autoshovel::codegen
