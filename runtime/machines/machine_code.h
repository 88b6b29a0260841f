// The one way every command finds a machine's functions from its description
// (docs/adding_a_machine.md):
//   1. compiled in: generated/ holds a machine of that name generated from the same bytes
//      (name and SHA-256 match);
//   2. else the machine library `autoshovel gen FILE` built into the per-user cache, loaded only
//      after every check of runtime/machines/machine_cache.h passed;
//   3. else, when no C++ compiler is present at all (so `gen` could not build one), the
//      interpreted model, said once on stderr;
//   4. else an error saying why and what to run.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <optional>
#include <stdexcept>
#include <string>

#include "generated/machine_functions.h"
#include "runtime/model/description.h"

namespace autoshovel::machines {

enum class CodeSource { kCompiledIn, kLibrary, kInterpreted };

const char* ToString(CodeSource source);

struct MachineCode {
  const generated::MachineFunctions* functions = nullptr;  ///< never null; lives forever
  CodeSource source = CodeSource::kCompiledIn;
  std::string where;  ///< "generated/<name>/", the library's path, or why it is interpreted
};

/// A machine with no code it may run: the message says why and what to run.
class MachineCodeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ResolveOptions {
  std::filesystem::path cache_root;  ///< empty: DefaultCacheRoot()
  /// Whether a C++ compiler counts as present; unset: FindCompiler() decides (tests set it).
  std::optional<bool> compiler_present;
  /// Where the interpreted fallback is announced; nullptr: not at all.
  std::ostream* notes = nullptr;
};

/// Resolves as in the header comment. Throws MachineCodeError.
MachineCode ResolveMachineCode(const model::MachineDescription& machine,
                               const ResolveOptions& options);

/// ResolveMachineCode with the default cache, the interpreted fallback announced on std::cerr
/// (once per machine and process), and the functions returned. Throws MachineCodeError.
const generated::MachineFunctions& MachineFunctionsFor(const model::MachineDescription& machine);

}  // namespace autoshovel::machines
