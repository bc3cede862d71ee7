#include "apps/common/stdin_lines.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <asio/post.hpp>
#include <cerrno>
#include <utility>

namespace hil::apps {

StdinLines::StdinLines(asio::io_context& io, Handlers handlers)
    : io_(io), handlers_(std::move(handlers)) {}

StdinLines::~StdinLines() {
  stop();
}

void StdinLines::start() {
  struct stat st {};
  const bool pollable = ::fstat(STDIN_FILENO, &st) == 0 &&
                        (S_ISFIFO(st.st_mode) || S_ISSOCK(st.st_mode) || ::isatty(STDIN_FILENO));
  if (!pollable) {
    // A regular file or /dev/null cannot be waited on; it never blocks.
    asio::post(io_, [this] { read_all(); });
    return;
  }
  stdin_flags_ = ::fcntl(STDIN_FILENO, F_GETFL);
  const int fd = ::dup(STDIN_FILENO);
  std::error_code ec;
  input_ = std::make_unique<asio::posix::stream_descriptor>(io_);
  if (fd >= 0) input_->assign(fd, ec);
  if (fd < 0 || ec) {
    if (fd >= 0) ::close(fd);
    input_.reset();
    asio::post(io_, [this] { ended(); });
    return;
  }
  read_some();
}

void StdinLines::stop() {
  if (!input_) return;
  std::error_code ec;
  input_->close(ec);
  input_.reset();
  // Asio made the shared file description non-blocking; the shell that
  // gets the terminal back expects it as it was.
  if (stdin_flags_ != -1) ::fcntl(STDIN_FILENO, F_SETFL, stdin_flags_);
}

void StdinLines::read_all() {
  std::array<char, 4096> buf{};
  while (more()) {
    const ssize_t n = ::read(STDIN_FILENO, buf.data(), buf.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    take(std::string_view(buf.data(), static_cast<std::size_t>(n)));
  }
  ended();
}

void StdinLines::read_some() {
  input_->async_read_some(asio::buffer(buf_), [this](std::error_code ec, std::size_t n) {
    if (!input_) return;  // stopped
    if (n > 0) take(std::string_view(buf_.data(), n));
    if (ec) {
      ended();
      return;
    }
    if (input_ && more()) read_some();
  });
}

void StdinLines::take(std::string_view bytes) {
  partial_.append(bytes);
  for (std::size_t nl = partial_.find('\n'); nl != std::string::npos; nl = partial_.find('\n')) {
    if (!more()) return;
    std::string line = partial_.substr(0, nl);
    partial_.erase(0, nl + 1);
    handlers_.line(std::move(line));
  }
}

void StdinLines::ended() {
  if (ended_) return;
  ended_ = true;
  // Lines nobody wants any more are not a last line either.
  std::string rest = more() ? std::exchange(partial_, {}) : std::string();
  if (handlers_.end) handlers_.end(std::move(rest));
}

}  // namespace hil::apps
