// The generator's driver, shared by `autoshovel-codegen` and `autoshovel gen`.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

namespace autoshovel::codegen {

struct GenerateRequest {
  std::vector<std::string> descriptions;  ///< description files to generate
  std::string models_dir;                 ///< or: every machine under this models/ folder
  std::string materials_dir;              ///< empty: `<description dir>/../materials`
  std::filesystem::path output_dir;
  /// Remove machine folders of `output_dir` that no requested description produced (used by
  /// the `regen` target so that a deleted description leaves no stale code behind).
  bool clean = false;
  /// Also compile each machine into a machine library in the per-user cache (`autoshovel gen`;
  /// codegen/compile_library.h). The `regen` target does not: generated/ is compiled in.
  bool compile = false;
  std::filesystem::path cache_root;  ///< empty: the default cache (machine_cache.h)
  std::string expected_abi;          ///< CompileOptions::expected_abi
};

/// Machine descriptions under a models/ folder: every `*.yaml` except in materials/ and
/// scenarios/, sorted.
std::vector<std::string> FindDescriptions(const std::string& models_dir);

/// Loads, validates and emits. Diagnostics go to `err` one per line; returns a process exit
/// code (0 success, 1 invalid input, 2 other failure).
int Generate(const GenerateRequest& request, std::ostream& out, std::ostream& err);

}  // namespace autoshovel::codegen
