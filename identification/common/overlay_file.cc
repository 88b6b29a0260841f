#include "identification/common/overlay_file.h"

#include "runtime/core/file_output.h"

namespace autoshovel::identification {

std::string OverlayHeader(const model::MachineDescription& machine,
                          const std::string& command_line) {
  return "# Identified values (" + command_line +
         ").\n# They replace those of the description when loaded as an overlay.\n"
         "machine: " +
         machine.name + "\nbase_sha256: " + machine.sha256 + "\n";
}

void WriteFileAtomically(const std::string& path, const std::string& text) {
  core::WriteFileAtomically(path, text);
}

}  // namespace autoshovel::identification
