#pragma once
// Runs the hil binary with arguments and captures its output and exit status.

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

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

}  // namespace hil::test
