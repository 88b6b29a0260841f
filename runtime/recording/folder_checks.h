// What every recording's reader checks first (docs/recording_format.md): that the folder is one
// and has its manifest, and the manifest's format and version. Shared by the loader's and the
// truck-loading job's readers; only core, for the fuzz targets.
#pragma once

#include <filesystem>

#include "runtime/core/yaml_reader.h"

namespace autoshovel::recording {

/// `dir`/recording.yaml. Refuses (core::InputError) a `dir` that is not a folder, and a folder
/// without the manifest (not a recording, or one whose run did not finish: it is written last).
std::filesystem::path ManifestOf(const std::filesystem::path& dir);

/// Reads `format` and `version` from the manifest's root and reports to `sink` (through `root`)
/// a format other than kFormatName or a version this build does not read. Returns the version.
int CheckFormatAndVersion(core::MapReader& root, const core::DiagnosticSink& sink);

}  // namespace autoshovel::recording
