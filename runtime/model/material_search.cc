// Where a description's materials are found (LoadOptions): the folders searched, in order, and
// the process-wide defaults the command line sets (`autoshovel --materials DIR`, `--models DIR`).
#include <filesystem>
#include <mutex>

#include "runtime/model/description.h"

namespace autoshovel::model {
namespace {

struct Defaults {
  std::mutex mutex;
  std::string materials_dir;
  std::string models_dir;
};

Defaults& ProcessDefaults() {
  static Defaults defaults;
  return defaults;
}

}  // namespace

void SetDefaultMaterialFolders(const std::string& materials_dir, const std::string& models_dir) {
  Defaults& d = ProcessDefaults();
  const std::lock_guard<std::mutex> lock(d.mutex);
  d.materials_dir = materials_dir;
  d.models_dir = models_dir;
}

std::vector<std::string> MaterialFolders(const std::string& path, const LoadOptions& options) {
  namespace fs = std::filesystem;
  std::string materials_dir = options.materials_dir, models_dir = options.models_dir;
  {
    Defaults& d = ProcessDefaults();
    const std::lock_guard<std::mutex> lock(d.mutex);
    if (materials_dir.empty()) materials_dir = d.materials_dir;
    if (models_dir.empty()) models_dir = d.models_dir;
  }
  if (!materials_dir.empty()) return {materials_dir};
  std::vector<std::string> candidates{
      (fs::path(path).parent_path() / ".." / "materials").lexically_normal().string()};
  if (!models_dir.empty()) {
    candidates.push_back((fs::path(models_dir) / "materials").lexically_normal().string());
  }
  // The same folder reached two ways is searched once.
  std::vector<std::string> folders;
  std::vector<fs::path> seen;
  for (const std::string& folder : candidates) {
    std::error_code error;
    const fs::path canonical = fs::weakly_canonical(folder, error);
    const fs::path key = error ? fs::path(folder) : canonical;
    bool duplicate = false;
    for (const fs::path& s : seen) duplicate = duplicate || s == key;
    if (duplicate) continue;
    seen.push_back(key);
    folders.push_back(folder);
  }
  return folders;
}

}  // namespace autoshovel::model
