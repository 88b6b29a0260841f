// Every file the project writes goes through here, so that no write can fail silently: a full
// disk, a read-only folder or a vanished directory is an exception naming the path and the
// system's reason, and the caller's command exits non-zero (issue 38: `plant step -o /dev/full`
// used to print "wrote" and exit 0).
//
// Regular files are written atomically: the bytes go to a temporary file beside the target,
// which is flushed, fsync'ed and closed (each checked), then renamed over the target. An
// interrupted or failed write therefore leaves the previous file byte for byte as it was and no
// half-written one. A target that exists and is not a regular file (a character device such as
// /dev/stdout or /dev/full, a FIFO) cannot be replaced by a rename: it is written in place, every
// write checked.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

namespace autoshovel::core {

/// A file could not be written. `what()` is one line: `path: cannot write: reason`.
class OutputError : public std::runtime_error {
 public:
  OutputError(const std::filesystem::path& path, const std::string& reason);
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// Writes `bytes` to `path` as described above. Throws OutputError; on failure the target is
/// unchanged and no temporary file is left behind.
void WriteFileAtomically(const std::filesystem::path& path, std::string_view bytes);

/// Creates `folder` and its missing parents (std::filesystem::create_directories), reporting a
/// failure as OutputError `folder: cannot write: cannot create the folder: reason` rather than
/// std::filesystem's "filesystem error: cannot create directories: ... [path]".
void CreateFolders(const std::filesystem::path& folder);

/// Flushes standard output and checks that every byte written to it so far reached the file
/// descriptor: std::cout's stream state and stdio's error flag (a full disk behind `> file`,
/// a closed pipe). Throws OutputError naming "standard output".
void FlushStandardOutput();

}  // namespace autoshovel::core
