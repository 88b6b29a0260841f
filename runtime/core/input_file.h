// What a reader should say before it opens a path that is not a plain file. Opening a named pipe
// for reading blocks until something writes to it (a reader would hang), a folder reads as an
// empty file (an arm calibration CSV that is a folder was "no header row"), and a name that
// exists is not "no such file" (issue 38).
#pragma once

#include <filesystem>
#include <string>

namespace autoshovel::core {

/// "" when `path` is a regular file or a link to one; otherwise the reason, ready for a message:
/// "no such file", "is a folder, not a file", "is a named pipe (FIFO), not a file", "is a device,
/// not a file", "is a socket, not a file", or the system's reason it cannot be examined.
std::string NotARegularFile(const std::filesystem::path& path);

}  // namespace autoshovel::core
