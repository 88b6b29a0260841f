// Machine libraries (issue 39): `gen` compiles a description's generated code into the per-user
// cache and every command loads it, but only when it is safe to. One real library is built from
// a renamed copy of the XCMG description once for the whole suite (emit + compile, a few
// seconds); each refusal case works on a copy of that cache with one thing broken: stale
// (description changed, or a library of another description), foreign (another ABI), tampered
// (bytes changed, manifest edited), and unsafe (group/world-writable, another owner, a link).
#include "runtime/machines/machine_library.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "codegen/compile_library.h"
#include "codegen/emitter.h"
#include "generated/registry.h"
#include "runtime/core/diagnostics.h"
#include "runtime/core/sha256.h"
#include "runtime/machines/machine_code.h"
#include "runtime/model/interpreted_model.h"

namespace autoshovel::machines {
namespace {

namespace fs = std::filesystem;

const std::string kSource = AUTOSHOVEL_SOURCE_DIR;
constexpr const char* kName = "library_test_loader";

std::string Read(const fs::path& path) { return core::ReadFileBytes(path); }

void Write(const fs::path& path, const std::string& bytes, fs::perms mode = fs::perms(0600)) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  fs::permissions(path, mode);
}

// Copies a cache folder as gen leaves it: folders 0700, files 0600 (the library 0700).
void CopyPrivate(const fs::path& from, const fs::path& to) {
  fs::create_directories(to);
  fs::permissions(to, fs::perms(0700));
  for (const auto& entry : fs::directory_iterator(from)) {
    const fs::path target = to / entry.path().filename();
    if (entry.is_directory()) {
      CopyPrivate(entry.path(), target);
    } else {
      fs::copy_file(entry.path(), target);
      fs::permissions(target, fs::status(entry.path()).permissions());
    }
  }
}

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at)) {
    text.replace(at, from.size(), to);
    at += to.size();
  }
  return text;
}

model::MachineDescription LoadDescription(const fs::path& path) {
  model::LoadOptions options;
  options.materials_dir = kSource + "/models/materials";
  return model::LoadMachineDescription(path.string(), options);
}

class MachineLibrary : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    work_ =
        fs::temp_directory_path() / ("autoshovel_machine_library_test_" + std::to_string(getpid()));
    fs::remove_all(work_);
    fs::create_directories(work_);
    fs::permissions(work_, fs::perms(0700));
    // A new machine: the XCMG description under another name (one file, nothing else).
    description_path_ = work_ / (std::string(kName) + ".yaml");
    Write(description_path_, Replace(Read(kSource + "/models/loaders/xcmg_968ev.yaml"),
                                     "name: xcmg_968ev", std::string("name: ") + kName));
    machine_ = new model::MachineDescription(LoadDescription(description_path_));
    codegen::EmitMachine(*machine_, {work_ / "generated", ""});
    root_ = work_ / "cache" / "machines";
    codegen::CompileOptions options;
    options.cache_root = root_;
    options.expected_abi = RunningAbiTag();
    std::ostringstream progress;
    const codegen::CompileOutcome outcome =
        codegen::CompileMachineLibrary(*machine_, work_ / "generated", options, progress);
    compile_status_ = outcome.status;
    compile_message_ = outcome.message;
    library_ = outcome.library;
  }
  static void TearDownTestSuite() {
    delete machine_;
    machine_ = nullptr;
    std::error_code ec;
    fs::remove_all(work_, ec);
  }
  void SetUp() override {
    ASSERT_EQ(compile_status_, codegen::CompileOutcome::Status::kBuilt) << compile_message_;
  }

  // A fresh cache root holding a copy of the built library's folder.
  fs::path CopyOfCache(const std::string& label) {
    const fs::path root = work_ / ("copy_" + label) / "machines";
    fs::create_directories(root);
    fs::permissions(root, fs::perms(0700));
    fs::permissions(root.parent_path(), fs::perms(0700));
    CopyPrivate(MachineDir(root_, machine_->sha256), MachineDir(root, machine_->sha256));
    return root;
  }
  static LibraryLoad Load(const fs::path& root) {
    return LoadMachineLibrary(machine_->name, machine_->sha256, root);
  }

  static inline fs::path work_, description_path_, root_, library_;
  static inline model::MachineDescription* machine_ = nullptr;
  static inline codegen::CompileOutcome::Status compile_status_{};
  static inline std::string compile_message_;
};

TEST_F(MachineLibrary, GenBuildsAPrivateLibraryWithItsManifest) {
  EXPECT_EQ(library_, MachineDir(root_, machine_->sha256) / "liblibrary_test_loader.so");
  const LibraryManifest m = ParseManifest(Read(library_.parent_path() / kManifestFile), "manifest");
  EXPECT_EQ(m.machine, kName);
  EXPECT_EQ(m.source_sha256, machine_->sha256);
  EXPECT_EQ(m.abi, RunningAbiTag());
  EXPECT_EQ(m.library_sha256, core::Sha256Hex(Read(library_)));
  EXPECT_NE(m.compiler.find("-std=c++20 -O2 -fPIC -shared"), std::string::npos) << m.compiler;
  // Exactly one embedded hash and tag: what the loader reads before loading.
  const std::string bytes = Read(library_);
  EXPECT_EQ(EmbeddedStrings(bytes, kSourceSha256Marker),
            std::vector<std::string>{machine_->sha256});
  EXPECT_EQ(EmbeddedStrings(bytes, kAbiTagMarker), std::vector<std::string>{RunningAbiTag()});
  EXPECT_EQ(CheckPrivate(root_, true), "");
  EXPECT_EQ(fs::status(library_.parent_path()).permissions(), fs::perms(0700));
}

TEST_F(MachineLibrary, AbiTagNamesLayoutInterfaceSizeAndToolchain) {
  const std::string tag = RunningAbiTag();
  EXPECT_EQ(tag.rfind(AbiTagPrefix(CompiledInterfaceHeaderText()), 0), 0u) << tag;
  EXPECT_NE(tag.find("/functions=" + std::to_string(sizeof(generated::MachineFunctions)) + "/"),
            std::string::npos)
      << tag;
  EXPECT_TRUE(tag.find("/gcc-") != std::string::npos || tag.find("/clang-") != std::string::npos)
      << tag;
}

TEST_F(MachineLibrary, LoadedLibraryComputesTheDescriptionsKinematics) {
  const LibraryLoad load = Load(root_);
  ASSERT_EQ(load.status, LibraryCheck::Status::kValid) << load.reason;
  const generated::MachineFunctions& f = *load.functions;
  EXPECT_STREQ(f.name, kName);
  EXPECT_STREQ(f.source_sha256, machine_->sha256.c_str());
  // Eq. (1)–(2) and the cylinder geometry against the interpreted reference model, at random
  // joint positions inside the limits.
  const model::InterpretedModel reference(*machine_);
  std::mt19937_64 rng(39);
  for (int i = 0; i < 200; ++i) {
    std::vector<double> q(f.num_joints);
    for (int j = 0; j < f.num_joints; ++j) {
      q[j] = std::uniform_real_distribution<double>(f.joint_min[j], f.joint_max[j])(rng);
    }
    const std::vector<double> params(f.nominal_params, f.nominal_params + f.num_params);
    const std::vector<double> angles = reference.AnglesFromJoints(q.data(), params.data());
    double pose[4], expected[4];
    f.forward_kinematics(angles.data(), params.data(), pose);
    reference.ForwardKinematics(angles.data(), params.data(), expected);
    for (int r = 0; r < 4; ++r) ASSERT_NEAR(pose[r], expected[r], 1e-9) << r;
    for (int a = 0; a < f.num_actuators; ++a) {
      ASSERT_NEAR(f.cylinder_length(a, q.data()), reference.CylinderLength(a, q.data()), 1e-9);
    }
  }
  // Loading again gives the same functions (the library is loaded once per process).
  EXPECT_EQ(Load(root_).functions, load.functions);
}

TEST_F(MachineLibrary, EveryLibraryLoadedIsItself) {
  // Libraries are loaded by descriptor (/proc/self/fd/N): a second, different file must not be
  // taken for the first even when the process loads both.
  const LibraryLoad first = Load(root_);
  const LibraryLoad second = Load(CopyOfCache("second"));
  ASSERT_EQ(first.status, LibraryCheck::Status::kValid) << first.reason;
  ASSERT_EQ(second.status, LibraryCheck::Status::kValid) << second.reason;
  EXPECT_NE(second.functions, first.functions);
  EXPECT_NE(second.library, first.library);
  const double q[2] = {0.1, 0.2};
  EXPECT_EQ(second.functions->cylinder_length(0, q), first.functions->cylinder_length(0, q));
}

TEST_F(MachineLibrary, ResolverUsesTheLibraryForAMachineNotCompiledIn) {
  ASSERT_EQ(generated::FindMachine(kName), nullptr);
  ResolveOptions options;
  options.cache_root = root_;
  const MachineCode code = ResolveMachineCode(*machine_, options);
  EXPECT_EQ(code.source, CodeSource::kLibrary);
  EXPECT_EQ(code.where, library_.string());
  EXPECT_EQ(code.functions, Load(root_).functions);
}

TEST_F(MachineLibrary, ResolverKeepsCompiledInMachines) {
  const model::MachineDescription shipped =
      LoadDescription(kSource + "/models/loaders/xcmg_968ev.yaml");
  ResolveOptions options;
  options.cache_root = work_ / "empty_cache";
  const MachineCode code = ResolveMachineCode(shipped, options);
  EXPECT_EQ(code.source, CodeSource::kCompiledIn);
  EXPECT_EQ(code.functions, generated::FindMachine("xcmg_968ev"));
}

TEST_F(MachineLibrary, EditedDescriptionIsStaleAndSaysToRunGen) {
  const fs::path edited = work_ / "edited" / (std::string(kName) + ".yaml");
  fs::create_directories(edited.parent_path());
  Write(edited, Read(description_path_) + "# edited after gen\n");
  const model::MachineDescription changed = LoadDescription(edited);
  ASSERT_NE(changed.sha256, machine_->sha256);
  ResolveOptions options;
  options.cache_root = root_;
  options.compiler_present = true;
  try {
    ResolveMachineCode(changed, options);
    FAIL() << "an edited description ran on the old library";
  } catch (const MachineCodeError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("stale"), std::string::npos) << what;
    EXPECT_NE(what.find("autoshovel gen " + edited.string()), std::string::npos) << what;
  }
}

TEST_F(MachineLibrary, NoCompilerFallsBackToTheInterpretedModelAndSaysSo) {
  const fs::path other = work_ / "interpreted" / (std::string(kName) + ".yaml");
  fs::create_directories(other.parent_path());
  Write(other, Read(description_path_) + "# a version never compiled\n");
  const model::MachineDescription m = LoadDescription(other);
  ResolveOptions options;
  options.cache_root = root_;
  options.compiler_present = false;
  std::ostringstream notes;
  options.notes = &notes;
  const MachineCode code = ResolveMachineCode(m, options);
  EXPECT_EQ(code.source, CodeSource::kInterpreted);
  EXPECT_NE(notes.str().find("using the interpreted model: no C++ compiler found"),
            std::string::npos)
      << notes.str();
  EXPECT_NE(notes.str().find("slower"), std::string::npos);
  // Same machine, same numbers as the compiled library (the edit was a comment).
  const generated::MachineFunctions& lib = *Load(root_).functions;
  const generated::MachineFunctions& f = *code.functions;
  EXPECT_STREQ(f.source_sha256, m.sha256.c_str());
  const std::vector<double> q = {0.2, -0.4};
  for (int a = 0; a < f.num_actuators; ++a) {
    EXPECT_NEAR(f.cylinder_length(a, q.data()), lib.cylinder_length(a, q.data()), 1e-12);
    EXPECT_NEAR(f.lever_arm(a, q.data()), lib.lever_arm(a, q.data()), 1e-9);
  }
  // Said once: a second resolve is quiet.
  notes.str("");
  ResolveMachineCode(m, options);
  EXPECT_EQ(notes.str(), "");
}

TEST_F(MachineLibrary, MissingLibraryWithACompilerIsAnErrorNamingGen) {
  ResolveOptions options;
  options.cache_root = work_ / "nothing_here";
  options.compiler_present = true;
  try {
    ResolveMachineCode(*machine_, options);
    FAIL();
  } catch (const MachineCodeError& e) {
    EXPECT_NE(std::string(e.what()).find("has no compiled code"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("run: autoshovel gen"), std::string::npos) << e.what();
  }
}

TEST_F(MachineLibrary, TamperedLibraryBytesAreRefused) {
  const fs::path root = CopyOfCache("tampered");
  const fs::path lib = MachineDir(root, machine_->sha256) / library_.filename();
  std::ofstream(lib, std::ios::binary | std::ios::app) << '\0';  // one byte appended
  const LibraryLoad load = Load(root);
  EXPECT_EQ(load.status, LibraryCheck::Status::kRefused);
  EXPECT_NE(load.reason.find("tampered"), std::string::npos) << load.reason;
  EXPECT_NE(load.reason.find("the manifest recorded"), std::string::npos) << load.reason;
  // And the resolver says so, with the remedy.
  ResolveOptions options;
  options.cache_root = root;
  try {
    ResolveMachineCode(*machine_, options);
    FAIL();
  } catch (const MachineCodeError& e) {
    EXPECT_NE(std::string(e.what()).find("refused: tampered"), std::string::npos) << e.what();
  }
}

TEST_F(MachineLibrary, EditedManifestIsRefused) {
  const fs::path root = CopyOfCache("manifest");
  const fs::path manifest = MachineDir(root, machine_->sha256) / kManifestFile;
  const std::string text = Read(manifest);
  // A manifest rewritten to the hash of other bytes.
  const std::string sha = core::Sha256Hex(Read(library_));
  Write(manifest, Replace(text, sha, std::string(64, 'a')));
  EXPECT_NE(Load(root).reason.find("tampered"), std::string::npos) << Load(root).reason;
  // A manifest that no longer parses.
  Write(manifest, text + "extra: 1\n");
  const LibraryLoad load = Load(root);
  EXPECT_EQ(load.status, LibraryCheck::Status::kRefused);
  EXPECT_NE(load.reason.find("bad manifest"), std::string::npos) << load.reason;
  EXPECT_NE(load.reason.find(":12:1: extra: unknown key"), std::string::npos) << load.reason;
}

TEST_F(MachineLibrary, LibraryOfAnotherDescriptionIsStale) {
  // The folder of description B holding A's library with a manifest claiming B: the hash
  // embedded in the library gives it away.
  const std::string other_sha = core::Sha256Hex("another description");
  const fs::path root = CopyOfCache("stale");
  fs::rename(MachineDir(root, machine_->sha256), MachineDir(root, other_sha));
  const fs::path manifest = MachineDir(root, other_sha) / kManifestFile;
  Write(manifest, Replace(Read(manifest), machine_->sha256, other_sha));
  const LibraryLoad load = LoadMachineLibrary(kName, other_sha, root);
  EXPECT_EQ(load.status, LibraryCheck::Status::kRefused);
  EXPECT_NE(load.reason.find("stale"), std::string::npos) << load.reason;
  EXPECT_NE(load.reason.find(machine_->sha256), std::string::npos) << load.reason;
}

TEST_F(MachineLibrary, ForeignAbiIsRefused) {
  // A library built for another ABI (as another autoshovel or compiler would): the test hook
  // writes a different tag into its entry source.
  const fs::path root = work_ / "foreign" / "machines";
  codegen::CompileOptions options;
  options.cache_root = root;
  options.abi_tag_override = "v1/interface=0000000000000000/functions=8/gcc-1/libstdc++-1";
  std::ostringstream progress;
  const codegen::CompileOutcome outcome =
      codegen::CompileMachineLibrary(*machine_, work_ / "generated", options, progress);
  ASSERT_EQ(outcome.status, codegen::CompileOutcome::Status::kBuilt) << outcome.message;
  LibraryLoad load = Load(root);
  EXPECT_EQ(load.status, LibraryCheck::Status::kRefused);
  EXPECT_NE(load.reason.find("foreign"), std::string::npos) << load.reason;
  EXPECT_NE(load.reason.find(options.abi_tag_override), std::string::npos) << load.reason;
  // With the manifest edited to claim this binary's ABI, the tag inside the library still
  // refuses it (and the manifest keeps matching the library's bytes).
  const fs::path manifest = MachineDir(root, machine_->sha256) / kManifestFile;
  Write(manifest, Replace(Read(manifest), options.abi_tag_override, RunningAbiTag()));
  load = Load(root);
  EXPECT_EQ(load.status, LibraryCheck::Status::kRefused);
  EXPECT_NE(load.reason.find("foreign"), std::string::npos) << load.reason;
  EXPECT_NE(load.reason.find("was built for ABI " + options.abi_tag_override), std::string::npos)
      << load.reason;
}

TEST_F(MachineLibrary, GroupOrWorldWritableCacheIsRefused) {
  const fs::path root = CopyOfCache("writable");
  const fs::path dir = MachineDir(root, machine_->sha256);
  const fs::path lib = dir / library_.filename();
  struct Case {
    fs::path path;
    fs::perms add;
    const char* expect;
  };
  for (const Case& c :
       {Case{lib, fs::perms::group_write, "group-writable"},
        Case{lib, fs::perms::others_write, "world-writable"},
        Case{dir / kManifestFile, fs::perms::group_write, "group-writable"},
        Case{dir / kSourceFolder / "entry.cc", fs::perms::group_write, "group-writable"},
        Case{dir, fs::perms::group_write, "group-writable"},
        Case{root, fs::perms::others_write, "world-writable"},
        Case{root.parent_path(), fs::perms::group_write, "writable by others"}}) {
    const fs::perms before = fs::status(c.path).permissions();
    fs::permissions(c.path, c.add, fs::perm_options::add);
    const LibraryLoad load = Load(root);
    EXPECT_EQ(load.status, LibraryCheck::Status::kRefused) << c.path;
    EXPECT_NE(load.reason.find("unsafe cache"), std::string::npos) << load.reason;
    EXPECT_NE(load.reason.find(c.expect), std::string::npos) << load.reason;
    EXPECT_NE(load.reason.find(c.path.string()), std::string::npos) << load.reason;
    fs::permissions(c.path, before);
  }
  EXPECT_EQ(Load(root).status, LibraryCheck::Status::kValid) << Load(root).reason;
}

TEST_F(MachineLibrary, FileOfAnotherOwnerIsRefused) {
  if (geteuid() != 0) GTEST_SKIP() << "changing a file's owner needs root";
  const fs::path root = CopyOfCache("owner");
  const fs::path lib = MachineDir(root, machine_->sha256) / library_.filename();
  ASSERT_EQ(chown(lib.c_str(), 65534, 65534), 0);
  const LibraryLoad load = Load(root);
  EXPECT_EQ(load.status, LibraryCheck::Status::kRefused);
  EXPECT_NE(load.reason.find("belongs to uid 65534"), std::string::npos) << load.reason;
}

TEST_F(MachineLibrary, SymbolicLinkIsRefused) {
  const fs::path root = CopyOfCache("link");
  const fs::path lib = MachineDir(root, machine_->sha256) / library_.filename();
  fs::rename(lib, work_ / "elsewhere.so");
  fs::create_symlink(work_ / "elsewhere.so", lib);
  const LibraryLoad load = Load(root);
  EXPECT_EQ(load.status, LibraryCheck::Status::kRefused);
  EXPECT_NE(load.reason.find("symbolic link"), std::string::npos) << load.reason;
}

TEST_F(MachineLibrary, CompilerErrorsAreShown) {
  // A "compiler" that fails like one: its output must reach the user.
  const fs::path fake = work_ / "failing-c++";
  Write(fake, "#!/bin/sh\necho 'entry.cc:1:1: error: something is wrong' >&2\nexit 1\n",
        fs::perms(0700));
  const char* old = std::getenv("CXX");
  const std::string saved = old ? old : "";
  setenv("CXX", fake.c_str(), 1);
  codegen::CompileOptions options;
  options.cache_root = work_ / "failing" / "machines";
  std::ostringstream progress;
  const codegen::CompileOutcome outcome =
      codegen::CompileMachineLibrary(*machine_, work_ / "generated", options, progress);
  // And none at all: not a failure, said as such.
  setenv("CXX", (work_ / "no-such-compiler").c_str(), 1);
  const codegen::CompileOutcome none =
      codegen::CompileMachineLibrary(*machine_, work_ / "generated", options, progress);
  if (old) {
    setenv("CXX", saved.c_str(), 1);
  } else {
    unsetenv("CXX");
  }
  EXPECT_EQ(outcome.status, codegen::CompileOutcome::Status::kFailed);
  EXPECT_NE(outcome.message.find("error: something is wrong"), std::string::npos)
      << outcome.message;
  EXPECT_NE(outcome.message.find("-std=c++20 -O2 -fPIC -shared"), std::string::npos)
      << outcome.message;
  EXPECT_FALSE(fs::exists(MachineDir(options.cache_root, machine_->sha256)));
  EXPECT_EQ(none.status, codegen::CompileOutcome::Status::kNoCompiler);
  EXPECT_NE(none.message.find("no-such-compiler"), std::string::npos) << none.message;
}

// ---------------------------------------------------------------------------------------------
// The manifest reader: every malformed manifest refused with file:line and the key.

struct BadManifest {
  const char* name;
  std::string text;
  const char* expected;  // in the first diagnostic
};

std::string GoodManifest() {
  LibraryManifest m;
  m.machine = "my_loader";
  m.source_file = "/models/my_loader.yaml";
  m.source_sha256 = std::string(64, 'a');
  m.abi = "v1/interface=0123456789abcdef/functions=192/gcc-12/libstdc++-12";
  m.library = "libmy_loader.so";
  m.library_sha256 = std::string(64, 'b');
  m.compiler = "/usr/bin/c++ -std=c++20 -O2 -fPIC -shared";
  m.compiler_version = "c++ 12.2.0";
  return FormatManifest(m);
}

class ManifestReader : public ::testing::TestWithParam<BadManifest> {};

TEST(ManifestReaderRoundTrip, FormatThenParseGivesTheSameManifest) {
  const LibraryManifest m = ParseManifest(GoodManifest(), "manifest");
  EXPECT_EQ(FormatManifest(m), GoodManifest());
  EXPECT_EQ(m.library, "libmy_loader.so");
  EXPECT_EQ(m.compiler_version, "c++ 12.2.0");
}

TEST_P(ManifestReader, RefusesWithLocation) {
  try {
    ParseManifest(GetParam().text, "cache/manifest");
    FAIL() << "accepted " << GetParam().name;
  } catch (const core::InputError& e) {
    ASSERT_FALSE(e.diagnostics().empty());
    const std::string first = e.diagnostics()[0].ToString();
    EXPECT_NE(first.find(GetParam().expected), std::string::npos) << first;
    EXPECT_EQ(first.rfind("cache/manifest:", 0), 0u) << first;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Malformed, ManifestReader,
    ::testing::Values(
        BadManifest{"unknown_key", GoodManifest() + "colour: red\n", ":12:1: colour: unknown key"},
        BadManifest{"repeated_key", GoodManifest() + "machine: other\n",
                    ":12:1: machine: given twice (first on line 4)"},
        BadManifest{"missing_key", Replace(GoodManifest(), "abi: ", "# abi: "), "abi: missing"},
        BadManifest{"short_hash", Replace(GoodManifest(), std::string(64, 'b'), "bbbb"),
                    ":9:17: library_sha256: expected 64 lower-case hex digits, got 'bbbb'"},
        BadManifest{"upper_case_hash",
                    Replace(GoodManifest(), std::string(64, 'a'), std::string(64, 'A')),
                    "source_sha256: expected 64 lower-case hex digits"},
        BadManifest{"library_elsewhere",
                    Replace(GoodManifest(), "library: libmy_loader.so", "library: ../../evil.so"),
                    "library: expected 'libmy_loader.so'"},
        BadManifest{"no_colon", GoodManifest() + "just words\n",
                    ":12:1: expected `key: value`, got 'just words'"},
        BadManifest{"format", Replace(GoodManifest(), "format: 1", "format: 2"),
                    ":3:9: format: unsupported format '2'"},
        BadManifest{"binary", std::string("format: 1\n\0\n", 12), "not a text file"},
        BadManifest{"empty", "", "format: missing"}),
    [](const ::testing::TestParamInfo<BadManifest>& param) { return param.param.name; });

}  // namespace
}  // namespace autoshovel::machines
