// The per-user cache of machine libraries: where `autoshovel gen` puts the compiled code of a
// description and what is checked before any of it is loaded (docs/adding_a_machine.md).
//
// Layout, keyed by the SHA-256 of the description's bytes:
//   <root>/<sha256>/lib<machine>.so   the generated code and an entry source, compiled
//   <root>/<sha256>/manifest          what was built, from what, with which compiler
//   <root>/<sha256>/src/...           the sources it was compiled from (kept for inspection)
// with <root> = $AUTOSHOVEL_MACHINE_CACHE, else
// ${XDG_CACHE_HOME:-$HOME/.cache}/autoshovel/machines.
//
// Loading a library runs its code, so nothing here trusts the cache: a library is valid only
// when the cache root, its folder and every file in it belong to this user and are not writable
// by others (nor are the folders above the root, sticky ones such as /tmp excepted), its bytes
// hash to what the manifest recorded at gen time, the description hash and ABI tag embedded in
// it are the expected ones, and no entry is a symbolic link. This file does every check that
// needs no loading; runtime/machines/machine_library.h loads.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace autoshovel::machines {

/// Version of the machine-library contract: the meaning of generated::MachineFunctions and the
/// entry points below. Part of every ABI tag; raise it when either changes meaning.
/// 2: plant_rhs with the valve sections' load check valves (issue 41).
inline constexpr int kMachineLayoutVersion = 2;

/// The extern "C" entry points of a machine library.
inline constexpr const char* kFunctionsSymbol = "autoshovel_machine_functions";
inline constexpr const char* kAbiTagSymbol = "autoshovel_machine_abi_tag";
inline constexpr const char* kSourceSha256Symbol = "autoshovel_machine_source_sha256";

/// Markers in front of the strings a library embeds, so that they can be read from its bytes
/// before it is loaded.
inline constexpr std::string_view kAbiTagMarker = "AUTOSHOVEL-MACHINE-ABI=";
inline constexpr std::string_view kSourceSha256Marker = "AUTOSHOVEL-MACHINE-SHA256=";

inline constexpr const char* kManifestFile = "manifest";
inline constexpr const char* kSourceFolder = "src";

/// The text of runtime/machines/machine_abi.h (embedded at build time), written beside each
/// library's entry source.
std::string_view MachineAbiHeaderText();

/// "v<layout>/interface=<first 16 hex of the SHA-256 of machine_functions.h's text>/functions=":
/// the start of an ABI tag; the size of MachineFunctions and the toolchain follow
/// (e.g. "…/functions=176/gcc-12/libstdc++-12").
std::string AbiTagPrefix(std::string_view interface_header_text);

/// The cache root (see above). Throws std::runtime_error when neither the variables nor the
/// password database give a home folder.
std::filesystem::path DefaultCacheRoot();

/// `<root>/<sha256>`.
std::filesystem::path MachineDir(const std::filesystem::path& root, const std::string& sha256);

/// "lib<machine>.so".
std::string LibraryFileName(const std::string& machine);

/// What `autoshovel gen` built, written next to the library.
struct LibraryManifest {
  int format = 1;
  std::string machine;         ///< machine name
  std::string source_file;     ///< the description, as given to gen
  std::string source_sha256;   ///< of the description's bytes (also the folder's name)
  std::string abi;             ///< the library's ABI tag
  std::string library;         ///< file name of the library in the folder
  std::string library_sha256;  ///< of the library's bytes right after compiling
  std::string compiler;        ///< the command line it was compiled with
  std::string compiler_version;
};

std::string FormatManifest(const LibraryManifest& manifest);

/// Parses a manifest; `path` names it in diagnostics. Throws core::InputError with
/// `path:line:column: key: message` for every problem (unknown or repeated key, missing key,
/// malformed hash, a library name that is not lib<machine>.so).
LibraryManifest ParseManifest(std::string_view text, const std::string& path);

/// A C++ compiler to build machine libraries with.
struct Compiler {
  std::vector<std::string> command;  ///< the executable's path, then any words $CXX carried
  std::string origin;                ///< "$CXX" or "PATH"
};

/// $CXX when set (it may carry words, e.g. "ccache g++"), else c++, g++ or clang++ on PATH.
/// nullopt when none is found; `searched` then says where it looked (and why $CXX failed).
std::optional<Compiler> FindCompiler(std::string* searched = nullptr);

/// Empty when `path` (not followed if a link) and, for a folder, everything below it belong to
/// this user, are not group- or world-writable and are no symbolic links; else the first
/// problem, e.g. "/c/abc/libm.so: group-writable (mode 0664)".
std::string CheckPrivate(const std::filesystem::path& path, bool recursive);

/// Empty when every folder above `root` (resolved) belongs to this user or to root and is not
/// writable by others, unless sticky (/tmp); else the first problem.
std::string CheckAncestors(const std::filesystem::path& root);

/// Every string embedded after `marker` (up to its NUL) in `bytes`; empty if none.
std::vector<std::string> EmbeddedStrings(std::string_view bytes, std::string_view marker);

/// A library file opened for checking and then loading (by the same descriptor, so that what
/// was hashed is what gets loaded).
class OpenLibrary {
 public:
  OpenLibrary() = default;
  explicit OpenLibrary(int fd) : fd_(fd) {}
  OpenLibrary(OpenLibrary&& other) noexcept : fd_(other.fd_) { other.fd_ = -1; }
  OpenLibrary& operator=(OpenLibrary&& other) noexcept;
  OpenLibrary(const OpenLibrary&) = delete;
  OpenLibrary& operator=(const OpenLibrary&) = delete;
  ~OpenLibrary();
  int fd() const { return fd_; }
  /// Gives the descriptor up (it stays open for the life of the process).
  int Release() {
    const int fd = fd_;
    fd_ = -1;
    return fd;
  }

 private:
  int fd_ = -1;
};

/// The outcome of checking the cache for one description.
struct LibraryCheck {
  enum class Status { kMissing, kRefused, kValid };
  Status status = Status::kMissing;
  std::string reason;             ///< kMissing / kRefused: why, one line
  std::filesystem::path dir;      ///< <root>/<sha256>
  std::filesystem::path library;  ///< the library file (when a manifest named one)
  LibraryManifest manifest;       ///< kValid (and kRefused after the manifest was read)
  OpenLibrary file;               ///< kValid: the library, open
};

/// Every check of the header comment that needs no loading, for the machine `machine` whose
/// description hashes to `sha256`, expecting ABI tag `abi`. kMissing: no folder or manifest for
/// that hash (the reason then names a library of the same machine from another version of the
/// description, if the cache holds one: a stale build).
LibraryCheck CheckMachineLibrary(const std::string& machine, const std::string& sha256,
                                 const std::string& abi, const std::filesystem::path& root);

}  // namespace autoshovel::machines
