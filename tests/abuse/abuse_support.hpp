#pragma once
// What the abuse tests share: hil (or a client program) run as a real
// process whose pid, liveness and resident memory the test can see, and
// raw client/car ends (TCP sockets, pty ends) written and read with bounded
// waits.

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <optional>
#include <random>
#include <regex>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace hil::test {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

/// HIL_ABUSE_FULL=1 selects the full sizes (256 MiB, 10,000 cycles, a
/// whole frame at one byte a second); otherwise the short CI form.
inline bool full_form() {
  const char* v = std::getenv("HIL_ABUSE_FULL");
  return v != nullptr && std::string(v) == "1";
}

// __has_feature is clang's; GCC says __SANITIZE_ADDRESS__/__SANITIZE_THREAD__.
#if defined(__has_feature)
#define HIL_TEST_HAS_FEATURE(feature) __has_feature(feature)
#else
#define HIL_TEST_HAS_FEATURE(feature) 0
#endif

/// True in an AddressSanitizer build: freed blocks wait in ASan's quarantine
/// (256 MiB by default) instead of going back to the allocator, so resident
/// memory after an abuse says nothing about leaks or unbounded queues there
/// (ASan's own leak check does, at exit).
#if defined(__SANITIZE_ADDRESS__) || HIL_TEST_HAS_FEATURE(address_sanitizer)
inline constexpr bool kAddressSanitizerBuild = true;
#else
inline constexpr bool kAddressSanitizerBuild = false;
#endif

/// True in a ThreadSanitizer build.
#if defined(__SANITIZE_THREAD__) || HIL_TEST_HAS_FEATURE(thread_sanitizer)
inline constexpr bool kThreadSanitizerBuild = true;
#else
inline constexpr bool kThreadSanitizerBuild = false;
#endif

/// True in an AddressSanitizer or ThreadSanitizer build. The short form
/// sends less there (the same properties are asserted): every process is
/// 2-15x slower under a sanitizer and CI runs the suite under both.
inline constexpr bool kSanitizerBuild = kAddressSanitizerBuild || kThreadSanitizerBuild;

/// Raises this process's open-file soft limit to the hard limit (for a
/// thousand sockets at once); processes started earlier keep theirs.
inline void raise_file_limit() {
  rlimit r{};
  if (::getrlimit(RLIMIT_NOFILE, &r) == 0 && r.rlim_cur < r.rlim_max) {
    r.rlim_cur = r.rlim_max;
    ::setrlimit(RLIMIT_NOFILE, &r);
  }
}

/// A program running in the background, stdout and stderr read through a
/// pipe; killed when the object goes.
class Process {
 public:
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
    std::vector<std::string> words{program};
    words.insert(words.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& w : words)
      argv.push_back(w.data());
    argv.push_back(nullptr);
    if (posix_spawn(&pid_, program.c_str(), &actions, nullptr, argv.data(), environ) != 0)
      pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
    ::close(out[1]);
    ::close(in[0]);
    in_fd_ = in[1];
    out_fd_ = out[0];
    // Read all the time: a process whose stdout pipe fills up blocks, and
    // that would be the test's doing, not the process's.
    reader_ = std::thread([this] {
      std::array<char, 16384> buf{};
      for (;;) {
        const ssize_t n = ::read(out_fd_, buf.data(), buf.size());
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        const std::lock_guard lock(mutex_);
        pending_.append(buf.data(), static_cast<std::size_t>(n));
        more_.notify_all();
      }
    });
  }
  ~Process() {
    if (pid_ > 0 && !exit_status_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    // The pipe ends once the process (and every child holding it) is gone.
    if (reader_.joinable()) reader_.join();
    if (out_fd_ >= 0) ::close(out_fd_);
    if (in_fd_ >= 0) ::close(in_fd_);
  }
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

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

  /// Waits up to `limit` for a new line containing `text`.
  std::optional<std::string> wait_for_line(const std::string& text,
                                           std::chrono::milliseconds limit = 10s) {
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

  /// Reads what the process has written so far, without waiting.
  const std::string& output() {
    while (read_some(Clock::now())) {
    }
    return output_;
  }

  bool write_stdin(const std::string& text) {
    return in_fd_ >= 0 &&
           ::write(in_fd_, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  }
  void close_stdin() {
    if (in_fd_ >= 0) ::close(in_fd_);
    in_fd_ = -1;
  }

  /// SIGINT, then the exit status within `limit`.
  std::optional<int> interrupt(std::chrono::milliseconds limit = 10s) {
    if (pid_ <= 0) return std::nullopt;
    if (exit_status_) return exit_status_;
    ::kill(pid_, SIGINT);
    return wait_exit(limit);
  }

  std::optional<int> wait_exit(std::chrono::milliseconds limit = 10s) {
    const auto deadline = Clock::now() + limit;
    while (Clock::now() < deadline) {
      if (!alive()) {
        output();
        return exit_status_;
      }
      read_some(Clock::now() + 20ms);
    }
    return std::nullopt;
  }

 private:
  // Takes what the reader thread collected, waiting until `deadline` for
  // something; false when nothing came.
  bool read_some(Clock::time_point deadline) {
    std::unique_lock lock(mutex_);
    more_.wait_until(lock, deadline, [this] { return !pending_.empty(); });
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
  std::mutex mutex_;
  std::condition_variable more_;
  std::string pending_;  // read by the thread, not yet in output_
  std::optional<int> exit_status_;
};

/// One end of a connection (socket or pty), owned.
class Conn {
 public:
  Conn() = default;
  explicit Conn(int fd) : fd_(fd) {}
  ~Conn() { reset(); }
  Conn(Conn&& o) noexcept : received(std::move(o.received)), fd_(o.fd_) { o.fd_ = -1; }
  Conn& operator=(Conn&& o) noexcept {
    if (this != &o) {
      reset();
      fd_ = o.fd_;
      o.fd_ = -1;
      received = std::move(o.received);
    }
    return *this;
  }
  bool ok() const { return fd_ >= 0; }
  int fd() const { return fd_; }
  void reset() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }
  /// Closes a socket with a reset (SO_LINGER 0): the peer gets RST, no FIN.
  void abort() {
    linger l{1, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_LINGER, &l, sizeof l);
    reset();
  }

  /// Writes everything within `limit`, reading (and keeping up to 1 MiB of)
  /// what arrives meanwhile so neither side can block the other. False
  /// when the peer closed or the time ran out.
  bool send(const std::string& bytes, std::chrono::milliseconds limit = 10s) {
    return send(bytes.data(), bytes.size(), limit);
  }
  bool send(const void* data, std::size_t size, std::chrono::milliseconds limit = 10s) {
    const auto* p = static_cast<const char*>(data);
    const auto deadline = Clock::now() + limit;
    std::size_t done = 0;
    while (done < size) {
      const short revents = poll_until(POLLOUT | POLLIN, deadline);
      if (revents == 0) return false;
      if ((revents & POLLIN) != 0) drain();
      if ((revents & (POLLERR | POLLNVAL)) != 0) return false;
      if ((revents & POLLOUT) != 0) {
        const ssize_t n = send_or_write(p + done, size - done);
        if (n < 0 && errno != EAGAIN && errno != EINTR) return false;
        if (n > 0) done += static_cast<std::size_t>(n);
      } else if ((revents & POLLHUP) != 0) {
        return false;
      }
    }
    return true;
  }

  /// Reads until `text` has arrived (true), the time ran out or the peer
  /// closed (false).
  bool read_until(const std::string& text, std::chrono::milliseconds limit = 10s) {
    const auto deadline = Clock::now() + limit;
    while (received.find(text) == std::string::npos) {
      if (poll_until(POLLIN, deadline) == 0 || !read_once()) return false;
    }
    return true;
  }

  /// Reads until the peer closes (true) or `limit` passes (false).
  bool read_to_end(std::chrono::milliseconds limit = 10s) {
    const auto deadline = Clock::now() + limit;
    for (;;) {
      if (poll_until(POLLIN, deadline) == 0) return false;
      if (!read_once()) return true;
    }
  }

  std::string received;

 private:
  // Waits for `events` until `deadline`: the events that came, or 0 when
  // the time ran out first.
  short poll_until(short events, Clock::time_point deadline) const {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    if (left.count() <= 0) return 0;
    pollfd p{fd_, events, 0};
    if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) return 0;
    return p.revents;
  }
  ssize_t send_or_write(const char* p, std::size_t n) {
    const ssize_t sent = ::send(fd_, p, n, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (sent < 0 && errno == ENOTSOCK) return ::write(fd_, p, n);
    return sent;
  }
  bool read_once() {
    std::array<char, 65536> buf{};
    const ssize_t n = ::read(fd_, buf.data(), buf.size());
    if (n <= 0) return n < 0 && errno == EAGAIN;
    if (received.size() < (1u << 20)) received.append(buf.data(), static_cast<std::size_t>(n));
    return true;
  }
  void drain() {
    for (int i = 0; i < 64; ++i) {
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, 0) <= 0 || (p.revents & POLLIN) == 0) return;
      if (!read_once()) return;
    }
  }

  int fd_ = -1;
};

/// Connects to 127.0.0.1:port; non-blocking afterwards. Not ok() on failure.
inline Conn tcp_connect(int port, int receive_buffer_bytes = 0) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return Conn();
  if (receive_buffer_bytes > 0)
    ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &receive_buffer_bytes, sizeof receive_buffer_bytes);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd);
    return Conn();
  }
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK);
  return Conn(fd);
}

/// Opens a pty slave (or its symlink) as a serial client does; non-blocking.
inline Conn pty_open(const std::string& path) {
  return Conn(::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC));
}

inline int port_in(const std::string& line) {
  std::smatch m;
  if (!std::regex_search(line, m, std::regex(R"(tcp://127\.0\.0\.1:(\d+))"))) return -1;
  return std::stoi(m[1]);
}

/// `n` bytes from a seeded generator (printed by the caller for replay).
inline std::string random_bytes(std::mt19937_64& rng, std::size_t n) {
  std::string out(n, '\0');
  for (std::size_t i = 0; i < n; i += 8) {
    const std::uint64_t v = rng();
    for (std::size_t k = 0; k < 8 && i + k < n; ++k)
      out[i + k] = static_cast<char>((v >> (8 * k)) & 0xFF);
  }
  return out;
}

}  // namespace hil::test
