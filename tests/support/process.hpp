#pragma once
// A program run as a real process by a test: started with posix_spawn in
// the source tree, its stdout and stderr read through one pipe all the time
// (a process whose pipe fills up blocks, and that would be the test's
// doing), its stdin a pipe the test writes. Every wait is bounded.

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <fstream>
#include <mutex>
#include <optional>
#include <regex>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace hil::test {

/// A program path and its arguments as the NULL-ended argv that
/// posix_spawn and execv take; the strings live as long as the object.
class ArgvList {
 public:
  ArgvList(const std::string& program, const std::vector<std::string>& args) : words_{program} {
    words_.insert(words_.end(), args.begin(), args.end());
    for (auto& w : words_)
      argv_.push_back(w.data());
    argv_.push_back(nullptr);
  }
  ArgvList(const ArgvList&) = delete;
  ArgvList& operator=(const ArgvList&) = delete;

  char* const* data() { return argv_.data(); }

 private:
  std::vector<std::string> words_;
  std::vector<char*> argv_;
};

/// A TCP connection to 127.0.0.1:`port`, blocking, not inherited by
/// programs the test starts, with SO_RCVBUF set first when
/// `receive_buffer_bytes` is positive; -1 when refused.
inline int connect_loopback(int port, int receive_buffer_bytes = 0) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  if (receive_buffer_bytes > 0)
    ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &receive_buffer_bytes, sizeof receive_buffer_bytes);
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

/// The port of the first `tcp://127.0.0.1:PORT` in a line hil printed; -1
/// when there is none.
inline int port_in(const std::string& line) {
  std::smatch m;
  if (!std::regex_search(line, m, std::regex(R"(tcp://127\.0\.0\.1:(\d+))"))) return -1;
  return std::stoi(m[1]);
}

/// A program running in the background; killed when the object goes.
class Process {
 public:
  using Clock = std::chrono::steady_clock;

  /// Runs `program` (a path) with `args`, passed as they are (no shell),
  /// in the source tree, so paths like scenarios/... work as in the docs.
  Process(const std::string& program, const std::vector<std::string>& args) {
    int out[2];
    int in[2];
    if (::pipe(out) != 0 || ::pipe(in) != 0) return;
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&actions, out[1], STDERR_FILENO);
    posix_spawn_file_actions_adddup2(&actions, in[0], STDIN_FILENO);
    posix_spawn_file_actions_addclose(&actions, out[0]);
    posix_spawn_file_actions_addclose(&actions, in[1]);
    posix_spawn_file_actions_addchdir_np(&actions, HIL_SOURCE_DIR);
    ArgvList argv(program, args);
    if (posix_spawn(&pid_, program.c_str(), &actions, nullptr, argv.data(), environ) != 0)
      pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
    ::close(out[1]);
    ::close(in[0]);
    in_fd_ = in[1];
    out_fd_ = out[0];
    reader_ = std::thread([this] { read_pipe(); });
  }
  ~Process() {
    if (pid_ > 0 && !exit_status_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    // A child of the process may still hold the pipe: the reader stops
    // without waiting for its end.
    stopping_ = true;
    if (reader_.joinable()) reader_.join();
    if (out_fd_ >= 0) ::close(out_fd_);
    if (in_fd_ >= 0) ::close(in_fd_);
  }
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

  bool started() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }

  /// Still running (not exited, not killed by a signal).
  bool alive() {
    if (pid_ <= 0 || exit_status_) return false;
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      exit_status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      return false;
    }
    return true;
  }

  /// VmRSS from /proc/PID/status, in KiB (0 when it cannot be read).
  long rss_kib() const {
    std::ifstream in("/proc/" + std::to_string(pid_) + "/status");
    std::string line;
    while (std::getline(in, line)) {
      if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
    }
    return 0;
  }

  /// Waits up to `limit` for a line after the last one this returned that
  /// contains `text`; returns the line.
  std::optional<std::string> wait_for_line(
      const std::string& text, std::chrono::milliseconds limit = std::chrono::seconds(10)) {
    const auto deadline = Clock::now() + limit;
    for (;;) {
      std::size_t start = seen_;
      for (std::size_t nl = output_.find('\n', start); nl != std::string::npos;
           nl = output_.find('\n', start)) {
        const std::string line = output_.substr(start, nl - start);
        start = nl + 1;
        if (line.find(text) != std::string::npos) {
          seen_ = start;
          return line;
        }
      }
      if (!read_some(deadline)) return std::nullopt;
    }
  }

  /// Everything the process has written so far, without waiting.
  const std::string& output() {
    while (read_some(Clock::now())) {
    }
    return output_;
  }

  /// Writes to the process's stdin (a pipe).
  bool write_stdin(const std::string& text) {
    return in_fd_ >= 0 &&
           ::write(in_fd_, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  }
  /// Closes the process's stdin, as Ctrl-D at a terminal does.
  void close_stdin() {
    if (in_fd_ >= 0) ::close(in_fd_);
    in_fd_ = -1;
  }

  /// Sends SIGINT (Ctrl-C) and waits up to `limit` for the exit status.
  std::optional<int> interrupt(std::chrono::milliseconds limit = std::chrono::seconds(10)) {
    if (pid_ <= 0) return std::nullopt;
    if (exit_status_) return exit_status_;
    ::kill(pid_, SIGINT);
    return wait_exit(limit);
  }

  /// Waits up to `limit` for the process to exit by itself; its exit status
  /// (128 + signal if a signal ended it), or nullopt if it is still running.
  /// What it wrote before it ended is in output() afterwards.
  std::optional<int> wait_exit(std::chrono::milliseconds limit = std::chrono::seconds(10)) {
    if (pid_ <= 0) return std::nullopt;
    const auto deadline = Clock::now() + limit;
    for (;;) {
      if (!alive()) {
        // Until the pipe ends, or 200 ms pass with nothing new (a child of
        // the process may hold it open).
        while (read_some(Clock::now() + std::chrono::milliseconds(200))) {
        }
        return exit_status_;
      }
      if (Clock::now() >= deadline) return std::nullopt;
      const auto step = std::min(deadline, Clock::now() + std::chrono::milliseconds(20));
      if (!read_some(step)) std::this_thread::sleep_until(step);
    }
  }

 private:
  // The reader thread: moves what the pipe brings into pending_ until the
  // pipe ends or the object goes.
  void read_pipe() {
    std::array<char, 16384> buf{};
    while (!stopping_) {
      pollfd p{out_fd_, POLLIN, 0};
      const int ready = ::poll(&p, 1, 50);
      if (ready < 0 && errno != EINTR) break;
      if (ready <= 0) continue;
      const ssize_t n = ::read(out_fd_, buf.data(), buf.size());
      if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
      if (n <= 0) break;
      const std::lock_guard lock(mutex_);
      pending_.append(buf.data(), static_cast<std::size_t>(n));
      more_.notify_all();
    }
    const std::lock_guard lock(mutex_);
    pipe_ended_ = true;
    more_.notify_all();
  }

  // Takes what the reader thread collected, waiting until `deadline` for
  // something; false when nothing came (at once once the pipe has ended).
  bool read_some(Clock::time_point deadline) {
    std::unique_lock lock(mutex_);
    more_.wait_until(lock, deadline, [this] { return !pending_.empty() || pipe_ended_; });
    if (pending_.empty()) return false;
    output_ += pending_;
    pending_.clear();
    return true;
  }

  pid_t pid_ = -1;
  int out_fd_ = -1;
  int in_fd_ = -1;
  std::string output_;
  std::size_t seen_ = 0;
  std::thread reader_;
  std::atomic<bool> stopping_{false};
  std::mutex mutex_;
  std::condition_variable more_;
  std::string pending_;  // read by the thread, not yet in output_
  bool pipe_ended_ = false;
  std::optional<int> exit_status_;
};

}  // namespace hil::test
