// Writing an identification overlay (model::LoadOptions::overlays) without ever leaving a half
// written file behind: the text goes to `<path>.tmp` and is renamed over `path` only once it is
// complete, so a failed or interrupted run keeps the previous overlay intact.
#pragma once

#include <string>

#include "runtime/model/description.h"

namespace autoshovel::identification {

/// The first lines every overlay starts with: a comment naming the command that wrote it, then
/// `machine` and `base_sha256` of the description it was identified against (the loader checks
/// both). `command_line` is free text, e.g. "autoshovel identify hydraulics log.csv".
std::string OverlayHeader(const model::MachineDescription& machine,
                          const std::string& command_line);

/// Writes `text` to `path` atomically: core::WriteFileAtomically (temporary file, fsync, rename).
/// Throws core::OutputError naming the path when it cannot be written; the old file, if any, is
/// then untouched.
void WriteFileAtomically(const std::string& path, const std::string& text);

}  // namespace autoshovel::identification
