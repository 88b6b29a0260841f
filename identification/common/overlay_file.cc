#include "identification/common/overlay_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace autoshovel::identification {

std::string OverlayHeader(const model::MachineDescription& machine,
                          const std::string& command_line) {
  return "# Identified values (" + command_line +
         ").\n# They replace those of the description when loaded as an overlay.\n"
         "machine: " +
         machine.name + "\nbase_sha256: " + machine.sha256 + "\n";
}

void WriteFileAtomically(const std::string& path, const std::string& text) {
  const std::string temporary = path + ".tmp";
  {
    std::ofstream file(temporary, std::ios::binary | std::ios::trunc);
    if (!file) {
      throw std::runtime_error("cannot write " + temporary + ": " + std::strerror(errno));
    }
    file << text;
    file.flush();
    if (!file) {
      std::error_code ignored;
      std::filesystem::remove(temporary, ignored);
      throw std::runtime_error("cannot write " + temporary + ": " + std::strerror(errno));
    }
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw std::runtime_error("cannot replace " + path + ": " + error.message());
  }
}

}  // namespace autoshovel::identification
