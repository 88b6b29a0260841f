#include "codegen/compile_library.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <ostream>
#include <sstream>
#include <thread>
#include <vector>

#include "runtime/core/progress_line.h"
#include "runtime/core/sha256.h"
#include "runtime/machines/machine_abi.h"
#include "runtime/machines/machine_cache.h"

extern char** environ;

namespace autoshovel::codegen {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

// Creates every missing folder of `dir` private to this user (0700 whatever the umask).
void MakePrivateDirs(const fs::path& dir) {
  fs::path path;
  for (const fs::path& part : dir) {
    path /= part;
    if (fs::exists(path)) continue;
    if (mkdir(path.c_str(), 0700) != 0 && errno != EEXIST) {
      throw fs::filesystem_error("cannot create folder", path,
                                 std::error_code(errno, std::generic_category()));
    }
    chmod(path.c_str(), 0700);
  }
}

void WritePrivateFile(const fs::path& path, std::string_view bytes) {
  const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (fd < 0) {
    throw fs::filesystem_error("cannot write", path,
                               std::error_code(errno, std::generic_category()));
  }
  fchmod(fd, 0600);
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int error = errno;
      close(fd);
      throw fs::filesystem_error("cannot write", path,
                                 std::error_code(error, std::generic_category()));
    }
    done += static_cast<std::size_t>(n);
  }
  if (close(fd) != 0) {
    throw fs::filesystem_error("cannot write", path,
                               std::error_code(errno, std::generic_category()));
  }
}

std::string CppString(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string Join(const std::vector<std::string>& words) {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "" : " ") + w;
  return out;
}

// The entry source: the three extern "C" functions a loader looks up. The ABI tag is assembled
// at compile time from what the library's own compiler sees (the size of MachineFunctions, its
// version macros), behind a marker that is split in the source so that it occurs once in the
// binary, right before the tag.
std::string EntrySource(const model::MachineDescription& m, const std::string& abi_prefix,
                        const std::string& abi_override) {
  std::ostringstream s;
  s << "// Written by autoshovel gen: the entry points of the machine library of `" << m.name
    << "`\n// (runtime/machines/machine_cache.h). Do not edit: the library is checked against "
       "its manifest.\n"
    << "#include <cstddef>\n\n#include \"generated/" << m.name << "/" << m.name
    << ".h\"\n#include \"machine_abi.h\"\n\nnamespace {\n\n"
    << "using autoshovel::generated::MachineFunctions;\n\n"
    << "struct Text {\n  char chars[512];\n};\n\n"
    << "constexpr void Put(Text& t, std::size_t& n, const char* s) {\n"
    << "  while (*s != '\\0') t.chars[n++] = *s++;\n}\n\n"
    << "constexpr Text AbiTag() {\n  Text t{};\n  std::size_t n = 0;\n"
    << "  Put(t, n, \"AUTOSHOVEL-MACHINE-\");\n  Put(t, n, \"ABI=\");\n";
  if (!abi_override.empty()) {
    s << "  Put(t, n, " << CppString(abi_override) << ");\n";
  } else {
    s << "  Put(t, n, " << CppString(abi_prefix) << ");\n"
      << "  char digits[24] = {};\n  std::size_t size = sizeof(MachineFunctions), k = 0;\n"
      << "  do {\n    digits[k++] = static_cast<char>('0' + size % 10);\n    size /= 10;\n"
      << "  } while (size != 0);\n  while (k != 0) t.chars[n++] = digits[--k];\n"
      << "  Put(t, n, \"/\" AUTOSHOVEL_MACHINE_ABI_TOOLCHAIN);\n";
  }
  s << "  return t;\n}\n\n"
    << "constexpr std::size_t kMarker = sizeof(\"AUTOSHOVEL-MACHINE-ABI=\") - 1;\n"
    << "constexpr Text kAbiTag = AbiTag();\n"
    << "constexpr char kSourceSha256[] = \"AUTOSHOVEL-MACHINE-SHA256=" << m.sha256 << "\";\n"
    << "constexpr std::size_t kShaMarker = sizeof(\"AUTOSHOVEL-MACHINE-SHA256=\") - 1;\n\n"
    << "}  // namespace\n\n"
    << "extern \"C\" {\n\n"
    << "__attribute__((visibility(\"default\"))) const char* autoshovel_machine_abi_tag() {\n"
    << "  return kAbiTag.chars + kMarker;\n}\n\n"
    << "__attribute__((visibility(\"default\"))) const char* "
       "autoshovel_machine_source_sha256() {\n"
    << "  return kSourceSha256 + kShaMarker;\n}\n\n"
    << "__attribute__((visibility(\"default\"))) const MachineFunctions* "
       "autoshovel_machine_functions() {\n"
    << "  return &autoshovel::generated::" << m.name << "::Functions();\n}\n\n"
    << "}  // extern \"C\"\n";
  return s.str();
}

struct RunResult {
  int exit_code = -1;  // -1: could not start or killed
  std::string error;   // could not start
};

// Runs `argv` with stdout and stderr into `log`, showing `label` and the seconds elapsed.
RunResult Run(const std::vector<std::string>& argv, const fs::path& log, core::ProgressLine* line,
              const std::string& label) {
  RunResult result;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) {
    result.error = argv[0] + ": " + std::strerror(spawned);
    return result;
  }
  const auto start = Clock::now();
  int shown = -1;
  for (;;) {
    int status = 0;
    const pid_t done = waitpid(pid, &status, WNOHANG);
    if (done == pid) {
      if (WIFEXITED(status)) result.exit_code = WEXITSTATUS(status);
      if (WIFSIGNALED(status))
        result.error = "killed by signal " + std::to_string(WTERMSIG(status));
      return result;
    }
    if (done < 0 && errno != EINTR) {
      result.error = std::string("waitpid: ") + std::strerror(errno);
      return result;
    }
    const int seconds = static_cast<int>(
        std::chrono::duration_cast<std::chrono::seconds>(Clock::now() - start).count());
    if (line != nullptr && seconds != shown) {
      line->Update(label + " " + std::to_string(seconds) + " s", shown < 0);
      shown = seconds;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

// The first `parts` '/'-separated parts of an ABI tag, with the trailing '/'.
std::string AbiPart(const std::string& tag, int parts) {
  std::size_t at = 0;
  for (int p = 0; p < parts && at != std::string::npos; ++p) {
    at = tag.find('/', at);
    if (at != std::string::npos) ++at;
  }
  return at == std::string::npos ? tag : tag.substr(0, at);
}

std::string FirstLine(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  return line;
}

}  // namespace

CompileOutcome CompileMachineLibrary(const model::MachineDescription& machine,
                                     const fs::path& generated_dir, const CompileOptions& options,
                                     std::ostream& progress) {
  CompileOutcome outcome;
  std::string searched;
  const std::optional<machines::Compiler> compiler = machines::FindCompiler(&searched);
  if (!compiler) {
    outcome.status = CompileOutcome::Status::kNoCompiler;
    outcome.message = "no C++ compiler found (searched " + searched + ")";
    return outcome;
  }
  const fs::path root =
      options.cache_root.empty() ? machines::DefaultCacheRoot() : options.cache_root;
  MakePrivateDirs(root);
  const fs::path final_dir = machines::MachineDir(root, machine.sha256);
  const fs::path work =
      root / (".build-" + machine.sha256.substr(0, 16) + "-" + std::to_string(getpid()));
  fs::remove_all(work);
  MakePrivateDirs(work);
  struct Cleanup {
    fs::path dir;
    ~Cleanup() {
      std::error_code ec;
      if (!dir.empty()) fs::remove_all(dir, ec);
    }
  } cleanup{work};

  // The sources, copied so that the library can be rebuilt and read without the output folder.
  const fs::path src = work / machines::kSourceFolder;
  const fs::path machine_src = src / "generated" / machine.name;
  MakePrivateDirs(machine_src);
  const std::string interface_header = core::ReadFileBytes(generated_dir / "machine_functions.h");
  WritePrivateFile(src / "generated" / "machine_functions.h", interface_header);
  for (const char* ext : {".h", ".cc"}) {
    const std::string file = machine.name + ext;
    WritePrivateFile(machine_src / file, core::ReadFileBytes(generated_dir / machine.name / file));
  }
  WritePrivateFile(src / "machine_abi.h", machines::MachineAbiHeaderText());
  const std::string abi_prefix = machines::AbiTagPrefix(interface_header);
  WritePrivateFile(src / "entry.cc", EntrySource(machine, abi_prefix, options.abi_tag_override));

  const std::string library_name = machines::LibraryFileName(machine.name);
  const fs::path library = work / library_name;
  std::vector<std::string> argv = compiler->command;
  std::istringstream flags(kLibraryFlags);
  for (std::string flag; flags >> flag;) argv.push_back(flag);
  argv.insert(argv.end(), {"-I", src.string(), "-o", library.string(), (src / "entry.cc").string(),
                           (machine_src / (machine.name + ".cc")).string()});
  const fs::path log = work / "compile.log";
  core::ProgressLine line(progress);
  const auto start = Clock::now();
  const RunResult run =
      Run(argv, log, &line, "codegen: compiling " + machine.name + " (" + argv[0] + " -O2)");
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  std::ostringstream took;
  took << std::fixed << std::setprecision(1) << seconds << " s";
  if (run.exit_code != 0) {
    line.Finish("codegen: compiling " + machine.name + " failed after " + took.str());
    outcome.message =
        "compiling " + machine.name + " failed (" +
        (run.error.empty() ? "exit code " + std::to_string(run.exit_code) : run.error) +
        "): " + Join(argv) + "\n" + (fs::exists(log) ? core::ReadFileBytes(log) : "");
    return outcome;
  }
  chmod(library.c_str(), 0700);

  // The library must carry the tag this build expects from that compiler; a different compiler
  // (or C++ library) than the one autoshovel was built with would be refused at load time, so
  // it is refused now with the remedy.
  const std::string bytes = core::ReadFileBytes(library);
  const std::vector<std::string> tags = machines::EmbeddedStrings(bytes, machines::kAbiTagMarker);
  if (tags.size() != 1) {
    outcome.message =
        library.string() + ": expected one embedded ABI tag, found " + std::to_string(tags.size());
    return outcome;
  }
  const std::string toolchain = "/" AUTOSHOVEL_MACHINE_ABI_TOOLCHAIN;
  const std::string& tag = tags[0];
  if (options.abi_tag_override.empty() && !options.expected_abi.empty() &&
      tag != options.expected_abi) {
    line.Finish("codegen: compiled " + machine.name + " in " + took.str());
    outcome.message = "the library's ABI is " + tag + ", autoshovel's " + options.expected_abi +
                      ": it would refuse it. " +
                      (tag.rfind(AbiPart(options.expected_abi, 2), 0) != 0
                           ? "The generated interface (machine_functions.h) differs from the one "
                             "autoshovel was built with: rebuild autoshovel (cmake --build build)."
                           : "Set CXX to the compiler autoshovel was built with.");
    return outcome;
  }
  if (options.abi_tag_override.empty() &&
      (tag.rfind(abi_prefix, 0) != 0 || tag.size() < toolchain.size() ||
       tag.compare(tag.size() - toolchain.size(), toolchain.size(), toolchain) != 0)) {
    line.Finish("codegen: compiled " + machine.name + " in " + took.str());
    outcome.message = Join(compiler->command) + " built a library with ABI " + tag +
                      ", but this autoshovel was built with " + toolchain.substr(1) +
                      " and would refuse it: set CXX to that compiler";
    return outcome;
  }

  machines::LibraryManifest manifest;
  manifest.machine = machine.name;
  manifest.source_file = fs::absolute(machine.source_file).lexically_normal().string();
  manifest.source_sha256 = machine.sha256;
  manifest.abi = tag;
  manifest.library = library_name;
  manifest.library_sha256 = core::Sha256Hex(bytes);
  manifest.compiler = Join(compiler->command) + " " + kLibraryFlags;
  const fs::path version_log = work / "version.log";
  std::vector<std::string> version_argv = compiler->command;
  version_argv.push_back("--version");
  if (Run(version_argv, version_log, nullptr, "").exit_code == 0) {
    manifest.compiler_version = FirstLine(version_log);
  }
  fs::remove(log);
  fs::remove(version_log);
  WritePrivateFile(work / machines::kManifestFile, machines::FormatManifest(manifest));

  // Into place: an older build of the same description is replaced whole.
  std::error_code ec;
  fs::remove_all(final_dir, ec);
  fs::rename(work, final_dir);
  cleanup.dir.clear();
  outcome.library = final_dir / library_name;
  line.Finish("codegen: compiled " + machine.name + " in " + took.str() + " -> " +
              outcome.library.string());

  const machines::LibraryCheck check =
      machines::CheckMachineLibrary(machine.name, machine.sha256, tag, root);
  if (check.status != machines::LibraryCheck::Status::kValid) {
    outcome.message = "the new library would be refused: " + check.reason;
    return outcome;
  }
  outcome.status = CompileOutcome::Status::kBuilt;
  return outcome;
}

int CompileGenerated(const std::vector<model::MachineDescription>& machines,
                     const fs::path& generated_dir, const CompileOptions& options,
                     std::ostream& out, std::ostream& err) {
  int status = 0;
  for (const model::MachineDescription& machine : machines) {
    CompileOutcome outcome;
    try {
      outcome = CompileMachineLibrary(machine, generated_dir, options, out);
    } catch (const fs::filesystem_error& e) {
      outcome.message = e.path1().string() + ": " + e.code().message();
    } catch (const std::exception& e) {
      outcome.message = e.what();
    }
    if (outcome.status == CompileOutcome::Status::kNoCompiler) {
      err << "codegen: " << outcome.message
          << ": no machine library built; commands will run these machines on the interpreted "
             "model (slower). Install a compiler (scripts/setup) and run gen again.\n";
      return 0;
    }
    if (outcome.status == CompileOutcome::Status::kFailed) {
      err << "codegen: " << machine.name << ": " << outcome.message << '\n';
      status = 2;
    }
  }
  return status;
}

}  // namespace autoshovel::codegen
