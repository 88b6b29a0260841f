#include "runtime/core/file_output.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>

namespace autoshovel::core {
namespace fs = std::filesystem;

namespace {

std::string Reason(int error_number) { return std::strerror(error_number); }

// write(2) may write less than asked (signals, pipes); EINTR is retried.
bool WriteAll(int fd, std::string_view bytes, int& error_number) {
  const char* data = bytes.data();
  std::size_t left = bytes.size();
  while (left > 0) {
    const ssize_t written = ::write(fd, data, left);
    if (written < 0) {
      if (errno == EINTR) continue;
      error_number = errno;
      return false;
    }
    data += written;
    left -= static_cast<std::size_t>(written);
  }
  return true;
}

// A device or FIFO: written where it is (a rename would replace the node itself).
void WriteInPlace(const fs::path& path, std::string_view bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0) throw OutputError(path, Reason(errno));
  int error_number = 0;
  if (!WriteAll(fd, bytes, error_number)) {
    ::close(fd);
    throw OutputError(path, Reason(error_number));
  }
  // fsync is meaningless on a terminal or pipe (EINVAL, EROFS): only real errors count.
  if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) {
    error_number = errno;
    ::close(fd);
    throw OutputError(path, Reason(error_number));
  }
  if (::close(fd) != 0) throw OutputError(path, Reason(errno));
}

}  // namespace

OutputError::OutputError(const fs::path& path, const std::string& reason)
    : std::runtime_error(path.string() + ": cannot write: " + reason), path_(path) {}

void WriteFileAtomically(const fs::path& path, std::string_view bytes) {
  if (path.empty()) throw OutputError(path, "empty path");
  struct stat target {};
  if (::stat(path.c_str(), &target) == 0) {
    if (S_ISDIR(target.st_mode)) throw OutputError(path, "it is a folder");
    if (!S_ISREG(target.st_mode)) {
      WriteInPlace(path, bytes);
      return;
    }
  }
  const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
  {
    struct stat parent {};
    if (::stat(folder.c_str(), &parent) != 0) {
      throw OutputError(path, "folder " + folder.string() + ": " + Reason(errno));
    }
    if (!S_ISDIR(parent.st_mode)) {
      throw OutputError(path, folder.string() + " is not a folder");
    }
  }
  // mkstemp: a unique name, so two writers of the same target never share a temporary file.
  std::string temporary = path.string() + ".tmp.XXXXXX";
  const int fd = ::mkstemp(temporary.data());
  if (fd < 0) throw OutputError(path, Reason(errno));
  const auto fail = [&](int error_number) {
    ::close(fd);
    ::unlink(temporary.c_str());
    throw OutputError(path, Reason(error_number));
  };
  int error_number = 0;
  if (!WriteAll(fd, bytes, error_number)) fail(error_number);
  // mkstemp creates 0600; a result file is as readable as any other the user makes.
  const mode_t mask = ::umask(0);
  ::umask(mask);
  if (::fchmod(fd, 0666 & ~mask) != 0) fail(errno);
  if (::fsync(fd) != 0) fail(errno);
  if (::close(fd) != 0) {
    error_number = errno;
    ::unlink(temporary.c_str());
    throw OutputError(path, Reason(error_number));
  }
  if (::rename(temporary.c_str(), path.c_str()) != 0) {
    error_number = errno;
    ::unlink(temporary.c_str());
    throw OutputError(path, Reason(error_number));
  }
  // The rename itself is durable once the folder is synced; a folder that cannot be opened for
  // that (unusual permissions) does not make the completed write a failure.
  const int folder_fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (folder_fd >= 0) {
    ::fsync(folder_fd);
    ::close(folder_fd);
  }
}

void CreateFolders(const fs::path& folder) {
  if (folder.empty()) return;
  std::error_code error;
  fs::create_directories(folder, error);
  if (error) throw OutputError(folder, "cannot create the folder: " + error.message());
  // create_directories succeeds without creating anything when the path is an existing file.
  if (!fs::is_directory(folder, error)) {
    throw OutputError(folder, "cannot create the folder: a file of that name exists");
  }
}

void FlushStandardOutput() {
  std::cout.flush();
  const bool stream_failed = !std::cout;
  const bool stdio_failed = std::fflush(stdout) != 0 || std::ferror(stdout) != 0;
  if (stream_failed || stdio_failed) {
    throw OutputError("standard output", stdio_failed ? Reason(errno) : "the write failed");
  }
}

}  // namespace autoshovel::core
