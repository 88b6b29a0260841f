// Writes the generated C++ of machines into an output directory (normally `generated/`).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "runtime/model/description.h"

namespace autoshovel::codegen {

struct EmitOptions {
  std::filesystem::path output_dir;  ///< gets `<machine>/`, registry and CMakeLists.txt
  std::string clang_format;          ///< executable; empty: look for clang-format on PATH
};

/// Emits `<output_dir>/<machine>/<machine>.{h,cc}` for one validated description, then
/// rewrites the machine-independent files (interface, registry, CMakeLists.txt) to list every
/// machine folder present in `output_dir`. Returns the files written.
std::vector<std::filesystem::path> EmitMachine(const model::MachineDescription& machine,
                                               const EmitOptions& options);

/// Rewrites the interface header, the registry and CMakeLists.txt of `output_dir`.
std::vector<std::filesystem::path> EmitRegistry(const EmitOptions& options);

/// The path of a description as it appears in banners: relative to the folder that holds
/// `models/` when the path goes through one, else the file name. Stable across checkouts.
std::string BannerPath(const std::string& description_path);

}  // namespace autoshovel::codegen
