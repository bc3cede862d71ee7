#pragma once
// Runs the hil binary (or another of hil's programs) with arguments and
// captures its output and exit status.

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

extern char** environ;

namespace hil::test {

struct CommandResult {
  int exit_code = -1;
  std::string output;  ///< stdout and stderr together
};

/// A TCP connection to 127.0.0.1:`port`, not inherited by programs the
/// test starts; -1 when refused.
inline int connect_loopback(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

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

/// hil running in the background (a long-running command such as `hil
/// mock`), its stdout and stderr read through a pipe. Every wait is bounded.
class HilProcess {
 public:
  /// `args` are passed as they are (no shell); runs in the source tree.
  explicit HilProcess(const std::vector<std::string>& args) : HilProcess(HIL_BINARY, args) {}

  /// Runs `program` (a path, e.g. a reference client's binary) instead of hil.
  HilProcess(const std::string& program, const std::vector<std::string>& args) {
    int fds[2];
    int in[2];
    if (::pipe(fds) != 0 || ::pipe(in) != 0) return;
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&actions, fds[1], STDERR_FILENO);
    posix_spawn_file_actions_adddup2(&actions, in[0], STDIN_FILENO);
    posix_spawn_file_actions_addclose(&actions, fds[0]);
    posix_spawn_file_actions_addclose(&actions, in[1]);
    posix_spawn_file_actions_addchdir_np(&actions, HIL_SOURCE_DIR);
    std::vector<std::string> argv_strings{program};
    argv_strings.insert(argv_strings.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : argv_strings)
      argv.push_back(a.data());
    argv.push_back(nullptr);
    if (posix_spawn(&pid_, program.c_str(), &actions, nullptr, argv.data(), environ) != 0)
      pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
    ::close(fds[1]);
    ::close(in[0]);
    in_fd_ = in[1];
    out_fd_ = fds[0];
    ::fcntl(out_fd_, F_SETFL, ::fcntl(out_fd_, F_GETFL) | O_NONBLOCK);
  }
  ~HilProcess() {
    if (pid_ > 0 && !exit_code_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    if (out_fd_ >= 0) ::close(out_fd_);
    if (in_fd_ >= 0) ::close(in_fd_);
  }
  HilProcess(const HilProcess&) = delete;
  HilProcess& operator=(const HilProcess&) = delete;

  bool started() const { return pid_ > 0; }

  /// Writes to the process's stdin (a pipe).
  bool write_stdin(const std::string& text) {
    return in_fd_ >= 0 &&
           ::write(in_fd_, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  }

  /// Waits up to `limit` for a line containing `text`; returns the line.
  std::optional<std::string> wait_for_line(
      const std::string& text, std::chrono::milliseconds limit = std::chrono::seconds(10)) {
    const auto deadline = std::chrono::steady_clock::now() + limit;
    for (;;) {
      std::size_t start = 0;
      for (std::size_t nl = output_.find('\n'); nl != std::string::npos;
           nl = output_.find('\n', start)) {
        const std::string line = output_.substr(start, nl - start);
        if (lines_seen_ <= start && line.find(text) != std::string::npos) {
          lines_seen_ = nl + 1;
          return line;
        }
        start = nl + 1;
      }
      if (!read_some(deadline)) return std::nullopt;
    }
  }

  /// Closes the process's stdin, as Ctrl-D at a terminal does.
  void close_stdin() {
    if (in_fd_ >= 0) ::close(in_fd_);
    in_fd_ = -1;
  }

  /// Waits up to `limit` for the process to exit by itself; its exit status
  /// (128 + signal if a signal ended it), or nullopt if it is still running.
  std::optional<int> wait_exit(std::chrono::milliseconds limit = std::chrono::seconds(10)) {
    if (exit_code_) return exit_code_;
    if (pid_ <= 0) return std::nullopt;
    const auto deadline = std::chrono::steady_clock::now() + limit;
    while (std::chrono::steady_clock::now() < deadline) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        while (read_some(std::chrono::steady_clock::now() + std::chrono::milliseconds(200))) {
        }
        return exit_code_;
      }
      read_some(std::chrono::steady_clock::now() + std::chrono::milliseconds(20));
    }
    return std::nullopt;
  }

  /// Sends SIGINT (Ctrl-C) and waits up to `limit` for the exit status.
  std::optional<int> interrupt(std::chrono::milliseconds limit = std::chrono::seconds(10)) {
    if (pid_ <= 0) return std::nullopt;
    ::kill(pid_, SIGINT);
    const auto deadline = std::chrono::steady_clock::now() + limit;
    while (std::chrono::steady_clock::now() < deadline) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        read_some(std::chrono::steady_clock::now() + std::chrono::milliseconds(200));
        return exit_code_;
      }
      read_some(std::chrono::steady_clock::now() + std::chrono::milliseconds(20));
    }
    return std::nullopt;
  }

  /// Everything the process wrote so far.
  const std::string& output() const { return output_; }

 private:
  // Reads what is available, waiting until `deadline`; false on timeout or EOF.
  bool read_some(std::chrono::steady_clock::time_point deadline) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    pollfd p{out_fd_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) return false;
    std::array<char, 4096> buf{};
    const ssize_t n = ::read(out_fd_, buf.data(), buf.size());
    if (n <= 0) return false;
    output_.append(buf.data(), static_cast<std::size_t>(n));
    return true;
  }

  pid_t pid_ = -1;
  int out_fd_ = -1;
  int in_fd_ = -1;
  std::string output_;
  std::size_t lines_seen_ = 0;
  std::optional<int> exit_code_;
};

}  // namespace hil::test
