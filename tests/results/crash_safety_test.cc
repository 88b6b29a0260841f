// Issue 9 item 3: a run killed with SIGKILL loses at most the cycle in flight, and a resumed run
// completes with no duplicate and no missing rows. A forked child writes through ResultsDb and is
// killed; the parent reopens the file (SQLite recovers from the WAL) and checks it.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <iostream>
#include <random>
#include <thread>

#include "runtime/results/results_db.h"
#include "tests/results/test_records.h"

namespace autoshovel::results {
namespace {

using testing::ScratchDir;
using testing::TestRecord;
using testing::TestRun;

int CountRows(const std::filesystem::path& file, const char* sql) {
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  sqlite3_stmt* statement = nullptr;
  EXPECT_EQ(sqlite3_prepare_v2(db, sql, -1, &statement, nullptr), SQLITE_OK) << sql;
  int count = -1;
  if (sqlite3_step(statement) == SQLITE_ROW) count = sqlite3_column_int(statement, 0);
  sqlite3_finalize(statement);
  sqlite3_close(db);
  return count;
}

// Every cycle present is whole: its samples are exactly those written, and no sample belongs to
// a cycle without a row.
void ExpectOnlyWholeCycles(const std::filesystem::path& file, int samples_per_cycle,
                           const std::vector<int>& big_cycles = {}, int big_samples = 0) {
  EXPECT_EQ(CountRows(file,
                      "SELECT count(*) FROM samples s WHERE NOT EXISTS (SELECT 1 FROM cycles c "
                      "WHERE c.run_id = s.run_id AND c.cycle = s.cycle)"),
            0)
      << "orphan samples";
  ResultsDb db(file);
  for (const int c : db.CompletedCycles("run-1")) {
    const bool big = std::find(big_cycles.begin(), big_cycles.end(), c) != big_cycles.end();
    const std::optional<CycleRecord> read = db.Cycle("run-1", c);
    ASSERT_TRUE(read.has_value());
    testing::ExpectSameRecord(*read, TestRecord(c, big ? big_samples : samples_per_cycle));
  }
}

// Child side: never returns; exit code 0 when every planned cycle is written.
[[noreturn]] void WriteMissingCyclesAndExit(const std::filesystem::path& file, int cycles,
                                            int samples_per_cycle, int notify_fd = -1,
                                            int big_cycle = -1, int big_samples = 0) {
  try {
    ResultsDb db(file);
    RunInfo run = TestRun();
    run.cycles_planned = cycles;
    db.BeginRun(run);
    for (const int c : db.MissingCycles("run-1", cycles)) {
      if (c == big_cycle) {
        const char byte = 'B';  // "the big transaction starts now"
        if (notify_fd >= 0 && write(notify_fd, &byte, 1) != 1) _exit(3);
        db.WriteCycle("run-1", TestRecord(c, big_samples));
        const char done = 'D';
        if (notify_fd >= 0 && write(notify_fd, &done, 1) != 1) _exit(3);
      } else {
        db.WriteCycle("run-1", TestRecord(c, samples_per_cycle));
      }
    }
  } catch (...) {
    _exit(2);
  }
  _exit(0);
}

TEST(CrashSafety, KillDuringALargeCycleLosesOnlyThatCycle) {
  const auto file = ScratchDir("") / "results.sqlite";
  constexpr int kCycles = 8, kSamples = 200, kBigCycle = 5, kBigSamples = 400000;
  int pipe_fds[2];
  ASSERT_EQ(pipe(pipe_fds), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    close(pipe_fds[0]);
    WriteMissingCyclesAndExit(file, kCycles, kSamples, pipe_fds[1], kBigCycle, kBigSamples);
  }
  close(pipe_fds[1]);
  char byte = 0;
  ASSERT_EQ(read(pipe_fds[0], &byte, 1), 1);
  ASSERT_EQ(byte, 'B');
  // The 400 000-sample transaction takes far longer than this; its pages (tens of MB, more than
  // the 2 MB page cache) spill into the WAL uncommitted, which recovery must discard.
  std::this_thread::sleep_for(std::chrono::milliseconds(60));
  ASSERT_EQ(kill(child, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "status " << status;
  char after = 0;
  const ssize_t got = read(pipe_fds[0], &after, 1);  // EOF: the child is gone
  close(pipe_fds[0]);
  ASSERT_EQ(got, 0) << "the big cycle committed before the kill: the test did not hit it";

  EXPECT_EQ(CountRows(file, "SELECT count(*) FROM cycles"), kBigCycle);
  EXPECT_EQ(CountRows(file, "SELECT count(*) FROM samples"), kBigCycle * kSamples);
  ExpectOnlyWholeCycles(file, kSamples);
  {
    ResultsDb db(file);
    EXPECT_EQ(db.CompletedCycles("run-1"), (std::vector<int>{0, 1, 2, 3, 4}));
  }

  // Resume (a smaller big cycle this time, to keep the test short) and complete.
  const pid_t resumed = fork();
  ASSERT_GE(resumed, 0);
  if (resumed == 0) WriteMissingCyclesAndExit(file, kCycles, kSamples, -1, kBigCycle, 3000);
  ASSERT_EQ(waitpid(resumed, &status, 0), resumed);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "status " << status;
  ResultsDb db(file);
  EXPECT_EQ(db.CompletedCycles("run-1"), (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(CountRows(file, "SELECT count(*) FROM samples"), (kCycles - 1) * kSamples + 3000);
  ExpectOnlyWholeCycles(file, kSamples, {kBigCycle}, 3000);
}

TEST(CrashSafety, RepeatedKillsAtRandomInstantsThenResumeCompleteTheRun) {
  const auto file = ScratchDir("") / "results.sqlite";
  constexpr int kCycles = 60, kSamples = 1500;
  std::mt19937 rng(20250601);
  std::uniform_int_distribution<int> delay_ms(5, 60);
  int kills = 0, rounds = 0;
  bool finished = false;
  while (!finished && rounds < 40) {
    ++rounds;
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) WriteMissingCyclesAndExit(file, kCycles, kSamples);
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms(rng)));
    kill(child, SIGKILL);  // may find it already exited: then it finished
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    if (WIFSIGNALED(status)) {
      ++kills;
    } else {
      ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "status " << status;
      finished = true;
    }
    // After every kill: whole cycles only, each index at most once (UNIQUE), a prefix so far.
    ExpectOnlyWholeCycles(file, kSamples);
    if (::testing::Test::HasFailure()) return;
  }
  EXPECT_GE(kills, 3) << "the kills never landed: the test proves little";
  if (!finished) {
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) WriteMissingCyclesAndExit(file, kCycles, kSamples);
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  }
  std::vector<int> all(kCycles);
  for (int c = 0; c < kCycles; ++c) all[c] = c;
  ResultsDb db(file);
  EXPECT_EQ(db.CompletedCycles("run-1"), all);
  EXPECT_EQ(CountRows(file, "SELECT count(*) FROM cycles"), kCycles);
  EXPECT_EQ(CountRows(file, "SELECT count(DISTINCT cycle) FROM cycles"), kCycles);
  EXPECT_EQ(CountRows(file, "SELECT count(*) FROM samples"), kCycles * kSamples);
  ExpectOnlyWholeCycles(file, kSamples);
  std::cout << "[          ] " << kills << " kills in " << rounds << " rounds\n";
}

}  // namespace
}  // namespace autoshovel::results
