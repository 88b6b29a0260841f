// core::WriteFileAtomically, CreateFolders and ProgressLine: a write that fails is an error that
// names the path and leaves the old file untouched; progress off a terminal is whole lines.
#include "runtime/core/file_output.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "runtime/core/progress_line.h"

namespace autoshovel::core {
namespace {

namespace fs = std::filesystem;

// A fresh folder per test, removed afterwards.
class FileOutput : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("autoshovel_file_output_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static std::string Read(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
  }
  // Everything in the folder but `keep`: a failed write must leave no temporary file behind.
  std::size_t OtherFiles(const fs::path& keep) const {
    std::size_t n = 0;
    for (const auto& entry : fs::directory_iterator(dir_)) n += entry.path() != keep;
    return n;
  }

  fs::path dir_;
};

TEST_F(FileOutput, WritesAndReplacesWholeFiles) {
  const fs::path path = dir_ / "a.txt";
  WriteFileAtomically(path, "first version\n");
  EXPECT_EQ(Read(path), "first version\n");
  WriteFileAtomically(path, std::string("bytes\0with a nul", 16));
  EXPECT_EQ(Read(path), std::string("bytes\0with a nul", 16));
  EXPECT_EQ(OtherFiles(path), 0u);
}

TEST_F(FileOutput, AFullDeviceIsAnErrorNamingThePath) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full here";
  try {
    WriteFileAtomically("/dev/full", "anything");
    FAIL() << "a write to /dev/full reported success";
  } catch (const OutputError& e) {
    EXPECT_EQ(std::string(e.what()), "/dev/full: cannot write: No space left on device");
  }
  // The device node itself must still be a device: never renamed over.
  EXPECT_TRUE(fs::is_character_file("/dev/full"));
}

TEST_F(FileOutput, AMissingFolderOrAFolderAsTargetIsRefused) {
  EXPECT_THROW(WriteFileAtomically(dir_ / "no_such" / "a.txt", "x"), OutputError);
  EXPECT_THROW(WriteFileAtomically(dir_, "x"), OutputError);
  std::ofstream(dir_ / "plain") << "x";
  try {
    WriteFileAtomically(dir_ / "plain" / "a.txt", "x");
    FAIL() << "a path under a regular file was written";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find((dir_ / "plain").string()), std::string::npos) << e.what();
  }
}

// A write that fails half way (here: the file size limit, as a full disk would) keeps the old
// file byte for byte and leaves no temporary file.
TEST_F(FileOutput, AFailedWriteKeepsTheOldFile) {
  const fs::path path = dir_ / "results.csv";
  WriteFileAtomically(path, "old contents\n");
  rlimit old_limit{};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old_limit), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);  // EFBIG instead of a signal
  rlimit small = old_limit;
  small.rlim_cur = 4096;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  bool threw = false;
  std::string message;
  try {
    WriteFileAtomically(path, std::string(100000, 'x'));
  } catch (const OutputError& e) {
    threw = true;
    message = e.what();
  }
  ::setrlimit(RLIMIT_FSIZE, &old_limit);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_TRUE(threw) << "a write past the size limit reported success";
  EXPECT_NE(message.find("results.csv: cannot write: File too large"), std::string::npos)
      << message;
  EXPECT_EQ(Read(path), "old contents\n");
  EXPECT_EQ(OtherFiles(path), 0u);
}

TEST_F(FileOutput, CreateFoldersSaysWhyNotWhatStdFilesystemSays) {
  CreateFolders(dir_ / "a" / "b");
  EXPECT_TRUE(fs::is_directory(dir_ / "a" / "b"));
  std::ofstream(dir_ / "plain") << "x";
  try {
    CreateFolders(dir_ / "plain" / "sub");
    FAIL() << "a folder under a regular file was created";
  } catch (const OutputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find("filesystem error"), std::string::npos) << what;
    EXPECT_NE(what.find("cannot create the folder: Not a directory"), std::string::npos) << what;
  }
  EXPECT_THROW(CreateFolders(dir_ / "plain"), OutputError);
}

TEST(ProgressLine, OffATerminalEveryUpdateIsAWholeLine) {
  std::ostringstream log;
  ProgressLine progress(log);
  EXPECT_FALSE(progress.terminal());  // a string stream is not a terminal
  progress.Update("[1/3 cycles]");
  progress.Update("[1/3 cycles]", false);  // no news within the heartbeat: nothing written
  progress.Update("[2/3 cycles]");
  progress.Finish("[3/3 cycles]");
  EXPECT_EQ(log.str(), "[1/3 cycles]\n[2/3 cycles]\n[3/3 cycles]\n");
  EXPECT_EQ(log.str().find('\r'), std::string::npos);
}

TEST(ProgressLine, OnATerminalTheLineIsRewrittenInPlace) {
  std::ostringstream screen;
  ProgressLine progress(screen, true);
  progress.Update("[10/300 cycles] long");
  progress.Update("[11/300]");
  progress.Finish("[300/300]");
  EXPECT_EQ(screen.str(), "\r[10/300 cycles] long\r[11/300]            \r[300/300]\n");
}

}  // namespace
}  // namespace autoshovel::core
