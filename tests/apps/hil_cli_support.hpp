#pragma once
// Runs the hil binary (or another of hil's programs) with arguments,
// captures its output and exit status and checks them against what a test
// expects; runs hil in the background and finds the port it listens on.

#include <sys/wait.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tests/support/process.hpp"

namespace hil::test {

struct CommandResult {
  int exit_code = -1;
  std::string output;  ///< stdout and stderr together
};

/// `args` is appended to the hil binary path as shell words (quote them).
/// Runs in the source tree, so paths like scenarios/... work as in the docs.
inline CommandResult run_hil(const std::string& args) {
  const std::string command =
      std::string("cd '") + HIL_SOURCE_DIR + "' && '" + HIL_BINARY + "' " + args + " 2>&1";
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buf{};
  std::size_t n = 0;
  while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0)
    result.output.append(buf.data(), n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

inline constexpr int kAnyExit = -1000;  ///< the exit code is not checked
inline constexpr int kFailure = -1001;  ///< any exit code but 0

/// One hil command line and what it must give.
struct CliRun {
  std::string args;                   ///< after `hil`, as shell words
  int exit_code = kAnyExit;           ///< or kAnyExit, kFailure
  std::optional<std::string> output;  ///< the whole output, when given
  std::vector<std::string> contains;  ///< parts the output holds
  std::vector<std::string> lacks;     ///< parts it does not hold
};

/// `hil ARGS` exits with `exit_code` and prints exactly `output`.
inline CliRun prints(std::string args, int exit_code, std::string output) {
  return {.args = std::move(args), .exit_code = exit_code, .output = std::move(output)};
}

/// `hil ARGS` exits with `exit_code`, its output holding each of `parts`.
inline CliRun says(std::string args, int exit_code, std::vector<std::string> parts) {
  return {.args = std::move(args), .exit_code = exit_code, .contains = std::move(parts)};
}

/// Runs `hil run.args` and checks what `run` says it gives.
inline void expect_run(const CliRun& run) {
  SCOPED_TRACE("hil " + run.args);
  const auto r = run_hil(run.args);
  if (run.exit_code == kFailure) {
    EXPECT_NE(r.exit_code, 0) << r.output;
  } else if (run.exit_code != kAnyExit) {
    EXPECT_EQ(r.exit_code, run.exit_code) << r.output;
  }
  if (run.output) EXPECT_EQ(r.output, *run.output);
  for (const auto& part : run.contains)
    EXPECT_THAT(r.output, ::testing::HasSubstr(part));
  for (const auto& part : run.lacks)
    EXPECT_THAT(r.output, ::testing::Not(::testing::HasSubstr(part)));
}

/// hil running in the background (a long-running command such as `hil
/// mock`), or another program when given its path.
class HilProcess : public Process {
 public:
  using Process::Process;
  /// `args` are passed as they are (no shell); runs in the source tree.
  explicit HilProcess(const std::vector<std::string>& args) : Process(HIL_BINARY, args) {}
};

/// Waits for `process` (hil mock or hil proxy) to print its line
/// containing `text` (where it listens: tcp://127.0.0.1:PORT); that port in
/// `port`. A fatal failure when the line or its port does not come.
inline void wait_for_port(HilProcess& process, int& port,
                          const std::string& text = "connect to tcp://") {
  const auto line = process.wait_for_line(text);
  ASSERT_TRUE(line) << process.output();
  port = port_in(*line);
  ASSERT_GT(port, 0) << *line;
}

}  // namespace hil::test
