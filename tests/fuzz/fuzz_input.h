// libFuzzer hands a fuzz target bytes; the project's readers take a path (they name it in their
// errors, and the description loader hashes the file and finds materials beside it). So each
// input is written to a file first.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace autoshovel::fuzz {

/// Writes the input to `$TMPDIR/autoshovel-fuzz-<pid><extension>` and returns that path. One file
/// per process (parallel fuzzing jobs do not share it), overwritten by every input and removed at
/// exit. The extension matters: the point cloud reader picks the format by it.
inline std::string WriteInput(const std::uint8_t* data, std::size_t size,
                              const std::string& extension) {
  static const std::string path = [&] {
    const std::filesystem::path p = std::filesystem::temp_directory_path() /
                                    ("autoshovel-fuzz-" + std::to_string(getpid()) + extension);
    static std::string remove_at_exit;
    remove_at_exit = p.string();
    std::atexit([] { std::remove(remove_at_exit.c_str()); });
    return p.string();
  }();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) std::abort();  // a full disk is not a finding in the reader: stop loudly
  return path;
}

}  // namespace autoshovel::fuzz
