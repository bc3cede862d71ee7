#pragma once
// One end of a connection a test holds (a TCP socket or a pty), written
// and read with bounded waits.

#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstddef>
#include <string>
#include <utility>

#include "tests/support/process.hpp"

namespace hil::test {

/// One end of a connection (socket or pty), owned.
class Conn {
 public:
  using Clock = std::chrono::steady_clock;

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
  bool send(const std::string& bytes, std::chrono::milliseconds limit = std::chrono::seconds(10)) {
    return send(bytes.data(), bytes.size(), limit);
  }
  bool send(const void* data, std::size_t size,
            std::chrono::milliseconds limit = std::chrono::seconds(10)) {
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
  bool read_until(const std::string& text,
                  std::chrono::milliseconds limit = std::chrono::seconds(10)) {
    const auto deadline = Clock::now() + limit;
    while (received.find(text) == std::string::npos) {
      if (poll_until(POLLIN, deadline) == 0 || !read_once()) return false;
    }
    return true;
  }

  /// Reads until the peer closes (true) or `limit` passes (false).
  bool read_to_end(std::chrono::milliseconds limit = std::chrono::seconds(10)) {
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
  const int fd = connect_loopback(port, receive_buffer_bytes);
  if (fd < 0) return Conn();
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK);
  return Conn(fd);
}

/// Opens a pty slave (or its symlink) as a serial client does; non-blocking.
inline Conn pty_open(const std::string& path) {
  return Conn(::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC));
}

}  // namespace hil::test
