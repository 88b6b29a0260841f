#include "runtime/recording/folder_checks.h"

#include <string>
#include <system_error>

#include "runtime/recording/csv_rows.h"
#include "runtime/recording/recording_format.h"

namespace autoshovel::recording {

std::filesystem::path ManifestOf(const std::filesystem::path& dir) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) Refuse(dir.string(), 0, 0, "not a folder");
  const std::filesystem::path manifest = dir / "recording.yaml";
  if (!std::filesystem::exists(manifest, ec)) {
    Refuse(manifest.string(), 0, 0,
           "missing: not a recording, or one whose run did not finish (the manifest is written "
           "last)");
  }
  return manifest;
}

int CheckFormatAndVersion(core::MapReader& root, const core::DiagnosticSink& sink) {
  const std::string format = root.String("format");
  if (sink.empty() && format != kFormatName) {
    root.Error("format", "expected '" + std::string(kFormatName) + "', got '" + format + "'");
  }
  const int version = root.Integer("version", 1, 1000);
  if (sink.empty() && version != kFormatVersion) {
    root.Error("version", "this build reads version " + std::to_string(kFormatVersion) +
                              ", the recording is version " + std::to_string(version));
  }
  return version;
}

}  // namespace autoshovel::recording
