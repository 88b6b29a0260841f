#include "runtime/machines/machine_cache.h"

#include <fcntl.h>
#include <pwd.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <sstream>
#include <stdexcept>

#include "runtime/core/diagnostics.h"
#include "runtime/core/sha256.h"

namespace autoshovel::machines {

namespace fs = std::filesystem;

namespace {

std::string Octal(mode_t mode) {
  std::array<char, 8> text{};
  std::snprintf(text.data(), text.size(), "%04o", static_cast<unsigned>(mode & 07777));
  return text.data();
}

bool IsSha256Hex(const std::string& text) {
  if (text.size() != 64) return false;
  for (char c : text) {
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  }
  return true;
}

std::string Environment(const char* name) {
  const char* value = std::getenv(name);
  return value == nullptr ? std::string() : std::string(value);
}

// One entry: this user's, not group/world-writable, not a link.
std::string CheckEntry(const fs::path& path, const struct stat& st) {
  if (S_ISLNK(st.st_mode)) return path.string() + ": is a symbolic link";
  if (!S_ISDIR(st.st_mode) && !S_ISREG(st.st_mode)) {
    return path.string() + ": neither a file nor a folder";
  }
  if (st.st_uid != geteuid()) {
    return path.string() + ": belongs to uid " + std::to_string(st.st_uid) +
           ", not to this user (uid " + std::to_string(geteuid()) + ")";
  }
  if ((st.st_mode & S_IWGRP) != 0)
    return path.string() + ": group-writable (mode " + Octal(st.st_mode) + ")";
  if ((st.st_mode & S_IWOTH) != 0)
    return path.string() + ": world-writable (mode " + Octal(st.st_mode) + ")";
  return "";
}

// A library of the same machine built from another version of its description, if any: the
// reason a lookup by hash found nothing is then most likely an edited description.
std::string StaleSibling(const fs::path& root, const std::string& machine,
                         const std::string& sha256) {
  std::error_code ec;
  if (!fs::is_directory(root, ec)) return "";
  for (const auto& entry : fs::directory_iterator(root, ec)) {
    const std::string name = entry.path().filename().string();
    if (name == sha256 || !IsSha256Hex(name)) continue;
    try {
      const LibraryManifest m = ParseManifest(core::ReadFileBytes(entry.path() / kManifestFile),
                                              (entry.path() / kManifestFile).string());
      if (m.machine == machine) return entry.path().string();
    } catch (const std::exception&) {
      // Not a readable manifest: not evidence of anything here.
    }
  }
  return "";
}

}  // namespace

std::string AbiTagPrefix(std::string_view interface_header_text) {
  return "v" + std::to_string(kMachineLayoutVersion) +
         "/interface=" + core::Sha256Hex(interface_header_text).substr(0, 16) + "/functions=";
}

fs::path DefaultCacheRoot() {
  const std::string explicit_root = Environment("AUTOSHOVEL_MACHINE_CACHE");
  if (!explicit_root.empty()) return fs::path(explicit_root);
  // XDG Base Directory: a relative $XDG_CACHE_HOME is invalid and to be ignored.
  const std::string xdg = Environment("XDG_CACHE_HOME");
  if (!xdg.empty() && xdg[0] == '/') return fs::path(xdg) / "autoshovel" / "machines";
  std::string home = Environment("HOME");
  if (home.empty()) {
    const struct passwd* pw = getpwuid(geteuid());
    if (pw != nullptr && pw->pw_dir != nullptr) home = pw->pw_dir;
  }
  if (home.empty()) {
    throw std::runtime_error(
        "no folder for the machine cache: set AUTOSHOVEL_MACHINE_CACHE, XDG_CACHE_HOME or HOME");
  }
  return fs::path(home) / ".cache" / "autoshovel" / "machines";
}

fs::path MachineDir(const fs::path& root, const std::string& sha256) { return root / sha256; }

std::string LibraryFileName(const std::string& machine) { return "lib" + machine + ".so"; }

std::string FormatManifest(const LibraryManifest& m) {
  std::ostringstream out;
  out << "# autoshovel machine library, written by `autoshovel gen` and checked before the\n"
         "# library is loaded (docs/adding_a_machine.md). Do not edit: the library is then "
         "refused.\n"
      << "format: " << m.format << "\nmachine: " << m.machine << "\nsource_file: " << m.source_file
      << "\nsource_sha256: " << m.source_sha256 << "\nabi: " << m.abi << "\nlibrary: " << m.library
      << "\nlibrary_sha256: " << m.library_sha256 << "\ncompiler: " << m.compiler
      << "\ncompiler_version: " << m.compiler_version << "\n";
  return out.str();
}

LibraryManifest ParseManifest(std::string_view text, const std::string& path) {
  core::DiagnosticSink sink;
  LibraryManifest m;
  std::map<std::string, std::string LibraryManifest::*> fields{
      {"machine", &LibraryManifest::machine},
      {"source_file", &LibraryManifest::source_file},
      {"source_sha256", &LibraryManifest::source_sha256},
      {"abi", &LibraryManifest::abi},
      {"library", &LibraryManifest::library},
      {"library_sha256", &LibraryManifest::library_sha256},
      {"compiler", &LibraryManifest::compiler},
      {"compiler_version", &LibraryManifest::compiler_version}};
  std::map<std::string, int> seen;  // key -> line
  int line_number = 0;
  std::size_t start = 0;
  if (text.find('\0') != std::string_view::npos) {
    sink.Add({path, 0, 0}, "", "not a text file (holds a NUL byte)");
    sink.ThrowIfAny();
  }
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    const std::string line(text.substr(start, end - start));
    start = end + 1;
    ++line_number;
    if (line.empty() || line[0] == '#') continue;
    const std::size_t colon = line.find(": ");
    if (colon == std::string::npos || colon == 0) {
      sink.Add({path, line_number, 1}, "", "expected `key: value`, got '" + line + "'");
      continue;
    }
    const std::string key = line.substr(0, colon);
    const std::string value = line.substr(colon + 2);
    const int value_column = static_cast<int>(colon) + 3;
    if (seen.count(key) != 0) {
      sink.Add({path, line_number, 1}, key,
               "given twice (first on line " + std::to_string(seen[key]) + ")");
      continue;
    }
    seen[key] = line_number;
    if (key == "format") {
      if (value != "1") {
        sink.Add({path, line_number, value_column}, key,
                 "unsupported format '" + value + "' (this autoshovel reads 1)");
      }
      continue;
    }
    const auto field = fields.find(key);
    if (field == fields.end()) {
      sink.Add({path, line_number, 1}, key, "unknown key");
      continue;
    }
    m.*(field->second) = value;
    if ((key == "source_sha256" || key == "library_sha256") && !IsSha256Hex(value)) {
      sink.Add({path, line_number, value_column}, key,
               "expected 64 lower-case hex digits, got '" + value + "'");
    }
  }
  for (const char* key :
       {"format", "machine", "source_sha256", "abi", "library", "library_sha256"}) {
    if (seen.count(key) == 0) sink.Add({path, 0, 0}, key, "missing");
  }
  if (seen.count("library") != 0 && seen.count("machine") != 0 &&
      m.library != LibraryFileName(m.machine)) {
    sink.Add({path, seen["library"], 10}, "library",
             "expected '" + LibraryFileName(m.machine) + "' (the machine's library), got '" +
                 m.library + "'");
  }
  sink.ThrowIfAny();
  return m;
}

std::optional<Compiler> FindCompiler(std::string* searched) {
  auto executable = [](const std::string& path) {
    struct stat st {};
    return stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) && access(path.c_str(), X_OK) == 0;
  };
  auto on_path = [&](const std::string& name) -> std::string {
    if (name.find('/') != std::string::npos) return executable(name) ? name : "";
    std::stringstream dirs(Environment("PATH"));
    std::string dir;
    while (std::getline(dirs, dir, ':')) {
      if (dir.empty()) continue;
      const std::string candidate = dir + "/" + name;
      if (executable(candidate)) return candidate;
    }
    return "";
  };
  const std::string cxx = Environment("CXX");
  if (!cxx.empty()) {
    std::istringstream words(cxx);
    std::vector<std::string> command;
    for (std::string word; words >> word;) command.push_back(word);
    if (!command.empty()) {
      const std::string resolved = on_path(command[0]);
      if (!resolved.empty()) {
        command[0] = resolved;
        return Compiler{command, "$CXX"};
      }
      if (searched != nullptr) *searched = "$CXX=" + cxx + " (no such executable)";
      return std::nullopt;
    }
  }
  for (const char* name : {"c++", "g++", "clang++"}) {
    const std::string resolved = on_path(name);
    if (!resolved.empty()) return Compiler{{resolved}, "PATH"};
  }
  if (searched != nullptr) *searched = "$CXX (unset), then c++, g++ and clang++ on PATH";
  return std::nullopt;
}

std::string CheckPrivate(const fs::path& path, bool recursive) {
  struct stat st {};
  if (lstat(path.c_str(), &st) != 0) return path.string() + ": " + std::strerror(errno);
  std::string problem = CheckEntry(path, st);
  if (!problem.empty() || !recursive || !S_ISDIR(st.st_mode)) return problem;
  std::error_code ec;
  for (fs::directory_iterator it(path, ec), end; !ec && it != end; it.increment(ec)) {
    problem = CheckPrivate(it->path(), true);
    if (!problem.empty()) return problem;
  }
  if (ec) return path.string() + ": cannot list: " + ec.message();
  return "";
}

std::string CheckAncestors(const fs::path& root) {
  std::error_code ec;
  const fs::path resolved = fs::canonical(root, ec);
  if (ec) return root.string() + ": " + ec.message();
  for (fs::path dir = resolved.parent_path();; dir = dir.parent_path()) {
    struct stat st {};
    if (stat(dir.c_str(), &st) != 0) return dir.string() + ": " + std::strerror(errno);
    if (st.st_uid != geteuid() && st.st_uid != 0) {
      return dir.string() + ": belongs to uid " + std::to_string(st.st_uid) +
             ", neither this user nor root";
    }
    if ((st.st_mode & (S_IWGRP | S_IWOTH)) != 0 && (st.st_mode & S_ISVTX) == 0) {
      return dir.string() + ": writable by others and not sticky (mode " + Octal(st.st_mode) + ")";
    }
    if (dir == dir.root_path() || dir.empty()) break;
  }
  return "";
}

std::vector<std::string> EmbeddedStrings(std::string_view bytes, std::string_view marker) {
  std::vector<std::string> found;
  for (std::size_t at = bytes.find(marker); at != std::string_view::npos;
       at = bytes.find(marker, at + 1)) {
    const std::size_t begin = at + marker.size();
    const std::size_t end = bytes.find('\0', begin);
    if (end == std::string_view::npos || end - begin > 512) continue;
    found.emplace_back(bytes.substr(begin, end - begin));
  }
  return found;
}

OpenLibrary& OpenLibrary::operator=(OpenLibrary&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) close(fd_);
    fd_ = other.fd_;
    other.fd_ = -1;
  }
  return *this;
}

OpenLibrary::~OpenLibrary() {
  if (fd_ >= 0) close(fd_);
}

LibraryCheck CheckMachineLibrary(const std::string& machine, const std::string& sha256,
                                 const std::string& abi, const fs::path& root) {
  LibraryCheck check;
  check.dir = MachineDir(root, sha256);
  const fs::path manifest_path = check.dir / kManifestFile;
  auto refuse = [&](const std::string& why) {
    check.status = LibraryCheck::Status::kRefused;
    check.reason = why;
    check.file = OpenLibrary();
    return std::move(check);
  };
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(manifest_path, ec))) {
    check.status = LibraryCheck::Status::kMissing;
    check.reason = "no machine library for this description in " + check.dir.string();
    const std::string stale = StaleSibling(root, machine, sha256);
    if (!stale.empty()) {
      check.reason = "stale: the library of '" + machine + "' in " + stale +
                     " was built from another version of the description (its SHA-256 is now " +
                     sha256 + ")";
    }
    return check;
  }
  // Who could have written what is about to run: the folders above the root, the root, the
  // machine's folder and everything in it.
  std::string problem = CheckAncestors(root);
  if (problem.empty()) problem = CheckPrivate(root, false);
  if (problem.empty()) problem = CheckPrivate(check.dir, true);
  if (!problem.empty()) return refuse("unsafe cache: " + problem);

  try {
    check.manifest = ParseManifest(core::ReadFileBytes(manifest_path), manifest_path.string());
  } catch (const core::InputError& e) {
    std::string first = e.diagnostics().empty() ? e.what() : e.diagnostics()[0].ToString();
    return refuse("bad manifest: " + first);
  } catch (const std::exception& e) {
    return refuse(std::string("bad manifest: ") + e.what());
  }
  const LibraryManifest& m = check.manifest;
  check.library = check.dir / m.library;
  if (m.machine != machine) {
    return refuse("tampered: " + manifest_path.string() + " is for machine '" + m.machine +
                  "', the description names '" + machine + "'");
  }
  if (m.source_sha256 != sha256) {
    return refuse("tampered: " + manifest_path.string() + " records description SHA-256 " +
                  m.source_sha256 + " in the folder of " + sha256);
  }
  if (m.abi != abi) {
    return refuse("foreign: built for ABI " + m.abi + ", this autoshovel is " + abi);
  }

  // Hash what will be loaded through the descriptor that will load it.
  const int fd = open(check.library.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return refuse(check.library.string() + ": cannot open: " + std::strerror(errno));
  check.file = OpenLibrary(fd);
  struct stat st {};
  if (fstat(fd, &st) != 0) return refuse(check.library.string() + ": " + std::strerror(errno));
  problem = CheckEntry(check.library, st);
  if (!problem.empty()) return refuse("unsafe cache: " + problem);
  if (!S_ISREG(st.st_mode)) return refuse(check.library.string() + ": not a file");
  std::string bytes;
  bytes.resize(static_cast<std::size_t>(st.st_size));
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = pread(fd, bytes.data() + done, bytes.size() - done, static_cast<off_t>(done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return refuse(check.library.string() + ": cannot read: " + std::strerror(errno));
    done += static_cast<std::size_t>(n);
  }
  const std::string library_sha = core::Sha256Hex(bytes);
  if (library_sha != m.library_sha256) {
    return refuse("tampered: " + check.library.string() + " has SHA-256 " + library_sha +
                  ", the manifest recorded " + m.library_sha256 + " when it was built");
  }
  const std::vector<std::string> shas = EmbeddedStrings(bytes, kSourceSha256Marker);
  if (shas.size() != 1) {
    return refuse("not a machine library: " + check.library.string() + " embeds " +
                  std::to_string(shas.size()) + " description hashes (expected 1)");
  }
  if (shas[0] != sha256) {
    return refuse("stale: " + check.library.string() + " was generated from description SHA-256 " +
                  shas[0] + ", the description's is " + sha256);
  }
  const std::vector<std::string> tags = EmbeddedStrings(bytes, kAbiTagMarker);
  if (tags.size() != 1) {
    return refuse("not a machine library: " + check.library.string() + " embeds " +
                  std::to_string(tags.size()) + " ABI tags (expected 1)");
  }
  if (tags[0] != abi) {
    return refuse("foreign: " + check.library.string() + " was built for ABI " + tags[0] +
                  ", this autoshovel is " + abi);
  }
  check.status = LibraryCheck::Status::kValid;
  return check;
}

}  // namespace autoshovel::machines
