// Reading in a child process (util/child_process.hpp): what the child writes to its standard
// error stays out of the user's terminal and comes back for the caller's message; a child that
// writes much there, or hangs, is still answered.
#include <gtest/gtest.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "cairn/util/child_process.hpp"

namespace cairn {
namespace {

void write_error(const std::string& text) {
  for (std::size_t at = 0; at < text.size();) {
    const ssize_t n = ::write(STDERR_FILENO, text.data() + at, text.size() - at);
    if (n <= 0) return;
    at += static_cast<std::size_t>(n);
  }
}

TEST(ChildProcess, CrashMessageComesBackInsteadOfReachingTheTerminal) {
  testing::internal::CaptureStderr();
  const ChildResult r = run_in_child(
      [](std::string&) {
        write_error("a first line\nfree(): invalid next size (fast)\n");
        std::abort();
        return 0;
      },
      30);
  const std::string terminal = testing::internal::GetCapturedStderr();
  EXPECT_EQ(r.signal, SIGABRT);
  EXPECT_FALSE(r.timed_out);
  if (child_errors_captured()) {
    EXPECT_EQ(terminal.find("invalid next size"), std::string::npos) << terminal;
    EXPECT_EQ(r.errors, "a first line\nfree(): invalid next size (fast)\n");
    EXPECT_EQ(child_said(r), "; it printed \"free(): invalid next size (fast)\"");
    EXPECT_EQ(child_ending(r, 30), "signal 6; it printed \"free(): invalid next size (fast)\"");
  } else {  // a sanitizer build: the child's reports go to the terminal
    EXPECT_NE(terminal.find("invalid next size"), std::string::npos) << terminal;
    EXPECT_EQ(child_said(r), "");
  }
}

TEST(ChildProcess, MuchStandardErrorNeitherBlocksTheChildNorGrowsTheResult) {
  // Four times a pipe's buffer of 64 KiB: a parent that did not read the child's standard error
  // while it waits for the answer would wait for ever.
  testing::internal::CaptureStderr();  // (where the child's standard error is the process's)
  const ChildResult r = run_in_child(
      [](std::string& out) {
        for (int k = 0; k < 4096; ++k) write_error("line " + std::to_string(k) + " of a chatty library's warnings\n");
        write_error("the last\tline\n\n");
        out = "answer";
        return 7;
      },
      30);
  const std::string terminal = testing::internal::GetCapturedStderr();
  EXPECT_FALSE(r.timed_out);
  EXPECT_EQ(r.signal, 0);
  EXPECT_EQ(r.exit_code, 7);
  EXPECT_EQ(r.output, "answer");
  if (child_errors_captured()) {
    EXPECT_LE(r.errors.size(), child_errors_kept);
    EXPECT_GT(r.errors.size(), child_errors_kept / 2);
    EXPECT_EQ(r.errors.substr(r.errors.size() - 15), "the last\tline\n\n");
    EXPECT_EQ(child_said(r), "; it printed \"the last?line\"");  // control characters replaced
    EXPECT_EQ(terminal, "");
  }
}

TEST(ChildProcess, AChildThatHangsIsKilledAtItsTime) {
  testing::internal::CaptureStderr();
  const ChildResult r = run_in_child(
      [](std::string&) {
        write_error("waiting\n");
        ::sleep(60);
        return 0;
      },
      1);
  (void)testing::internal::GetCapturedStderr();
  EXPECT_TRUE(r.timed_out);
  EXPECT_EQ(r.signal, 0);
  if (child_errors_captured()) {
    EXPECT_EQ(child_ending(r, 1), "it did not finish in 1 s; it printed \"waiting\"");
  }
}

TEST(ChildProcess, NothingWrittenAddsNothingToTheMessage) {
  const ChildResult r = run_in_child([](std::string& out) {
    out.assign(1, 'x');  // (GCC 12 warns, wrongly, on a one-character literal here)
    return 3;
  }, 30);
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(r.errors, "");
  EXPECT_EQ(child_ending(r, 30), "exit code 3");
}

}  // namespace
}  // namespace cairn
