#include "link/pty.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <climits>
#include <functional>
#include <system_error>
#include <utility>

#include <asio/error.hpp>
#include <asio/posix/stream_descriptor.hpp>
#include <asio/post.hpp>
#include <asio/steady_timer.hpp>
#include <asio/write.hpp>

namespace hil::link {

// ---------------------------------------------------------------- pty pipe

namespace {

using Descriptor = asio::posix::stream_descriptor;

[[noreturn]] void throw_errno(const std::string& what) {
  throw std::system_error(errno, std::generic_category(), what);
}

void make_raw(int fd, unsigned baud) {
  termios t{};
  if (::tcgetattr(fd, &t) != 0) return;  // not a terminal: nothing to set
  ::cfmakeraw(&t);
  t.c_cflag |= CLOCAL | CREAD;
  t.c_cc[VMIN] = 1;
  t.c_cc[VTIME] = 0;
  speed_t speed = 0;
  switch (baud) {
    case 1200:
      speed = B1200;
      break;
    case 2400:
      speed = B2400;
      break;
    case 4800:
      speed = B4800;
      break;
    case 9600:
      speed = B9600;
      break;
    case 19200:
      speed = B19200;
      break;
    case 38400:
      speed = B38400;
      break;
    case 57600:
      speed = B57600;
      break;
    case 115200:
      speed = B115200;
      break;
    case 230400:
      speed = B230400;
      break;
    case 460800:
      speed = B460800;
      break;
    case 921600:
      speed = B921600;
      break;
    default:
      break;
  }
  if (speed != 0) ::cfsetspeed(&t, speed);
  ::tcsetattr(fd, TCSANOW, &t);
}

/// Client bytes that may wait for pacing before the pty is left unread:
/// 4 s of input at 9600 baud.
constexpr std::size_t kMaxPacedInputBytes = 4096;

/// Reads whatever is waiting without blocking and forgets it.
void discard_input(int fd) {
  std::array<char, 4096> scratch{};
  while (::read(fd, scratch.data(), scratch.size()) > 0) {
  }
}

/// One session over a pty or serial descriptor: paced writes out, paced
/// reads in, the reset_on_open window, and the end of the session.
class PtyPipe final : public BytePipe, public std::enable_shared_from_this<PtyPipe> {
 public:
  /// Called once when the descriptor is no longer used by this session:
  /// `client_gone` says whether the far side closed (true) or this side
  /// did (false).
  using OnEnd = std::function<void(bool client_gone)>;

  PtyPipe(Executor& executor, std::shared_ptr<Descriptor> descriptor, const PtyOptions& options,
          std::string description, OnEnd on_end)
      : executor_(executor),
        descriptor_(std::move(descriptor)),
        options_(options),
        description_(std::move(description)),
        on_end_(std::move(on_end)),
        opened_at_(executor.now()),
        tx_(executor, options.baud, [this](ByteView b) { to_os(b); }),
        rx_(executor, options.baud, [this](ByteView b) { deliver(b); }) {}

  // A session dropped before start() must still give the pty back.
  ~PtyPipe() override {
    if (on_end_) on_end_(false);
  }

  void start(Handlers handlers) override {
    handlers_ = std::move(handlers);
    if (state_ == State::open && !reading_) read();
  }

  void write(ByteView bytes) override {
    if (state_ != State::open || bytes.empty()) return;
    if (send_limit_ != 0 && tx_.queued() + os_queued_ + bytes.size() > send_limit_) {
      // The client stopped reading: end its session rather than grow.
      post_close(std::make_error_code(std::errc::no_buffer_space));
      state_ = State::closed;
      rx_.clear();
      end_session(false);
      return;
    }
    tx_.push(bytes);
  }

  void close(CloseMode mode) override {
    if (state_ != State::open) return;
    post_close(closed_here());
    rx_.clear();
    if (mode == CloseMode::reset) {
      state_ = State::closed;
      end_session(false);
      return;
    }
    // Reading goes on while flushing, to notice the client hanging up.
    state_ = State::flushing;
    if (!reading_) read();
    tx_.when_drained([self = shared_from_this()] { self->finish_flush(); });
  }

  bool is_open() const override { return state_ == State::open; }
  void set_send_limit(std::size_t bytes) override { send_limit_ = bytes; }
  std::size_t queued_bytes() const override { return tx_.queued() + os_queued_; }
  std::string describe() const override { return description_; }

  void pause_reading() override { paused_ = true; }
  void resume_reading() override {
    if (!paused_) return;
    paused_ = false;
    if (state_ == State::open && !reading_) read_when_room();
  }
  void when_drained_to(std::size_t bytes, std::function<void()> callback) override {
    if (state_ == State::closed || !callback) return;
    drain_.watch(bytes, queued_bytes(), std::move(callback),
                 [this](std::function<void()> f) { executor_.post(std::move(f)); });
  }

  std::uint64_t bytes_lost() const { return lost_; }

  /// The owner is going away: end now without waiting for anything.
  void hang_up() {
    if (state_ == State::closed) return;
    post_close(closed_here());
    state_ = State::closed;
    rx_.clear();
    end_session(false);
  }

 private:
  enum class State : std::uint8_t {
    open,
    client_gone,  // far side closed; bytes it sent are still being paced in
    flushing,     // close(graceful): paced bytes still going out
    closed,
  };

  void read() {
    reading_ = true;
    descriptor_->async_read_some(
        asio::buffer(buffer_),
        [self = shared_from_this()](std::error_code ec, std::size_t n) { self->on_read(ec, n); });
  }

  /// A serial line delivers at most `baud` bits a second however fast the
  /// client writes: once a few seconds of input wait to be paced in, the
  /// pty is left unread (the client's writes block, as on a real port)
  /// until they have gone through, so a fast writer cannot grow memory.
  void read_when_room() {
    if (paused_) return;  // resume_reading() reads again
    if (rx_.queued() <= kMaxPacedInputBytes) {
      read();
      return;
    }
    rx_.when_drained([self = shared_from_this()] {
      if (self->state_ == State::open && !self->reading_ && !self->paused_) self->read();
    });
  }

  void on_read(std::error_code ec, std::size_t n) {
    reading_ = false;
    ec = portable_error(ec);
    if (state_ == State::closed || state_ == State::client_gone) return;
    if (n > 0 && state_ == State::open) received(ByteView(buffer_.data(), n));
    if (state_ == State::closed || ec == std::errc::operation_canceled) return;
    if (!ec) {
      if (!reading_) read_when_room();
      return;
    }
    if (state_ == State::flushing) {
      state_ = State::closed;
      end_session(true);
      return;
    }
    // A pty master reads EIO once no process holds the slave open; a slave
    // or serial port reads eof or EIO when its far end goes away.
    const bool gone = ec == asio::error::eof || ec == std::errc::io_error;
    state_ = State::client_gone;
    end_session(true);
    // What the client wrote before closing still reaches the device.
    rx_.when_drained([self = shared_from_this(), code = gone ? asio::error::eof : ec] {
      self->state_ = State::closed;
      self->notify_close(code);
    });
  }

  void received(ByteView bytes) {
    if (executor_.now() - opened_at_ < options_.reset_on_open) {
      // The board is still in its bootloader: these bytes go nowhere.
      lost_ += bytes.size();
      if (options_.log) {
        options_.log(description_ + ": " + std::to_string(bytes.size()) +
                     " byte(s) lost to reset_on_open (" + std::to_string(lost_) + " so far)");
      }
      return;
    }
    rx_.push(bytes);
  }

  void deliver(ByteView bytes) {
    if ((state_ == State::open || state_ == State::client_gone) && handlers_.on_data) {
      handlers_.on_data(bytes);
    }
  }

  void to_os(ByteView bytes) {
    if (state_ != State::open && state_ != State::flushing) return;
    os_queue_.emplace_back(bytes.begin(), bytes.end());
    os_queued_ += bytes.size();
    if (!writing_) write_os();
  }

  void write_os() {
    writing_ = true;
    asio::async_write(
        *descriptor_, asio::buffer(os_queue_.front()),
        [self = shared_from_this()](std::error_code ec, std::size_t) { self->on_written(ec); });
  }

  void on_written(std::error_code ec) {
    writing_ = false;
    ec = portable_error(ec);
    if (state_ != State::open && state_ != State::flushing) return;
    if (ec) {
      if (state_ == State::open) notify_close(ec);
      state_ = State::closed;
      end_session(false);
      return;
    }
    os_queued_ -= os_queue_.front().size();
    os_queue_.pop_front();
    drain_.update(queued_bytes());
    if (state_ != State::open && state_ != State::flushing) return;
    if (!os_queue_.empty()) {
      write_os();
    } else {
      finish_flush();
    }
  }

  void finish_flush() {
    if (state_ != State::flushing || tx_.queued() > 0 || !os_queue_.empty()) return;
    state_ = State::closed;
    end_session(false);
  }

  /// Stops using the descriptor and hands it back to the owner.
  void end_session(bool client_gone) {
    drain_.cancel();
    tx_.clear();
    // Safe while a write is pending: cancel() runs on this thread, so no
    // more of that buffer is written once it returns.
    os_queue_.clear();
    os_queued_ = 0;
    std::error_code ignored;
    descriptor_->cancel(ignored);
    if (on_end_) {
      auto end = std::move(on_end_);
      on_end_ = nullptr;
      end(client_gone);
    }
  }

  void post_close(std::error_code ec) {
    executor_.post([self = shared_from_this(), ec] { self->notify_close(ec); });
  }

  void notify_close(std::error_code ec) {
    if (close_notified_) return;
    close_notified_ = true;
    // Handlers often capture the pipe; dropping them breaks that cycle.
    auto on_close = std::move(handlers_.on_close);
    handlers_ = {};
    if (on_close) on_close(ec);
  }

  Executor& executor_;
  std::shared_ptr<Descriptor> descriptor_;
  PtyOptions options_;
  std::string description_;
  OnEnd on_end_;
  Time opened_at_;
  Handlers handlers_;
  State state_ = State::open;
  bool reading_ = false;
  bool writing_ = false;
  bool close_notified_ = false;
  bool paused_ = false;  // pause_reading(): the pty is left unread
  std::uint64_t lost_ = 0;
  std::array<std::uint8_t, 4096> buffer_{};
  std::deque<Bytes> os_queue_;
  std::size_t os_queued_ = 0;
  std::size_t send_limit_ = 0;  // 0: no cap
  DrainWatch drain_;            // when_drained_to()
  SerialPacer tx_;  // device -> client
  SerialPacer rx_;  // client -> device
};

/// Points `link` at `target`, replacing an old symlink atomically (rename)
/// and refusing to replace anything else.
void place_symlink(const std::string& link, const std::string& target) {
  struct stat st {};
  if (::lstat(link.c_str(), &st) == 0 && !S_ISLNK(st.st_mode)) {
    throw std::system_error(
        std::make_error_code(std::errc::file_exists),
        link + ": exists and is not a symlink; not replacing it with the pty link");
  }
  const std::string temporary = link + ".tmp" + std::to_string(::getpid());
  ::unlink(temporary.c_str());
  if (::symlink(target.c_str(), temporary.c_str()) != 0)
    throw_errno(link + ": cannot create the pty symlink");
  if (::rename(temporary.c_str(), link.c_str()) != 0) {
    const int saved = errno;
    ::unlink(temporary.c_str());
    throw std::system_error(saved, std::generic_category(),
                            link + ": cannot create the pty symlink");
  }
}

/// Removes `link` if it still points at `target` (another process may have
/// taken the path over since).
void remove_symlink(const std::string& link, const std::string& target) {
  std::array<char, PATH_MAX> buffer{};
  const ssize_t n = ::readlink(link.c_str(), buffer.data(), buffer.size() - 1);
  if (n > 0 && std::string(buffer.data(), static_cast<std::size_t>(n)) == target)
    ::unlink(link.c_str());
}

}  // namespace

// ---------------------------------------------------------------- listener

struct PtyListener::State : std::enable_shared_from_this<PtyListener::State> {
  enum class Mode : std::uint8_t { idle, waiting_open, in_session, waiting_hang_up, closed };

  State(asio::io_context& context, Executor& exec, std::string link_path, PtyOptions opts)
      : io(context),
        executor(exec),
        path(std::move(link_path)),
        options(std::move(opts)),
        poll_timer(context) {}

  int fd() { return master->native_handle(); }

  void poll_soon() {
    poll_timer.expires_after(options.poll_period);
    poll_timer.async_wait([self = shared_from_this()](std::error_code ec) {
      if (!ec) self->poll();
    });
  }

  void poll() {
    if (mode != Mode::waiting_open && mode != Mode::waiting_hang_up) return;
    pollfd p{fd(), POLLIN, 0};
    ::poll(&p, 1, 0);
    const bool slave_closed = (p.revents & POLLHUP) != 0;
    if (mode == Mode::waiting_open) {
      if (!slave_closed) {
        open_session();
        return;
      }
      // A client that opened, wrote and closed between two polls: nobody
      // saw that session, so its bytes must not reach the next one.
      if ((p.revents & POLLIN) != 0) forget_buffers();
    } else {
      discard_input(fd());
      if (slave_closed) {
        forget_buffers();
        mode = Mode::waiting_open;
      }
    }
    poll_soon();
  }

  /// Drops every byte still inside the pty, both ways, so the next client
  /// never sees the previous session's bytes. What the device wrote may sit
  /// in the slave's input queue, which only a flush on the slave side
  /// reaches; opening the slave here does not count as a client (the
  /// session is already over and the open is closed at once).
  void forget_buffers() {
    discard_input(fd());
    ::tcflush(fd(), TCIOFLUSH);
    const int s = ::open(slave.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (s >= 0) {
      ::tcflush(s, TCIOFLUSH);
      ::close(s);
    }
  }

  void open_session() {
    mode = Mode::in_session;
    auto pipe =
        std::make_shared<PtyPipe>(executor, master, options, "pty " + path + " (" + slave + ")",
                                  [weak = weak_from_this()](bool client_gone) {
                                    if (auto self = weak.lock()) self->session_ended(client_gone);
                                  });
    session = pipe;
    if (on_accept) {
      on_accept(pipe);
    } else {
      pipe->hang_up();
    }
  }

  void session_ended(bool client_gone) {
    if (mode != Mode::in_session) return;
    if (auto pipe = session.lock()) lost_in_past_sessions += pipe->bytes_lost();
    session.reset();
    if (client_gone) {
      forget_buffers();
      mode = Mode::waiting_open;
    } else {
      // The device side ended the session while the client keeps the port
      // open: swallow its bytes until it closes, then wait for the next.
      mode = Mode::waiting_hang_up;
    }
    poll_soon();
  }

  asio::io_context& io;
  Executor& executor;
  std::string path;
  PtyOptions options;
  std::shared_ptr<Descriptor> master;
  std::string slave;
  asio::steady_timer poll_timer;
  std::function<void(BytePipePtr)> on_accept;
  std::weak_ptr<PtyPipe> session;
  Mode mode = Mode::idle;
  std::uint64_t lost_in_past_sessions = 0;
};

PtyListener::PtyListener(asio::io_context& io, Executor& executor, const std::string& path,
                         PtyOptions options)
    : state_(std::make_shared<State>(io, executor, path, std::move(options))) {
  const int fd = ::posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw_errno(path + ": cannot open a pty (posix_openpt)");
  state_->master = std::make_shared<Descriptor>(io, fd);
  std::array<char, 128> name{};
  if (::grantpt(fd) != 0 || ::unlockpt(fd) != 0 || ::ptsname_r(fd, name.data(), name.size()) != 0) {
    throw_errno(path + ": cannot set up the pty");
  }
  state_->slave = name.data();
  // Raw mode lives in the slave's settings, which outlast this open. The
  // open-and-close also puts the master in the "no slave open" (POLLHUP)
  // state that poll() relies on; a never-opened slave does not show it.
  const int slave = ::open(name.data(), O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (slave < 0) throw_errno(path + ": cannot open the pty slave " + state_->slave);
  make_raw(slave, state_->options.baud);
  ::close(slave);
  place_symlink(path, state_->slave);
}

PtyListener::PtyListener(asio::io_context& io, Executor& executor, const PtyEndpoint& endpoint)
    : PtyListener(io, executor, endpoint.path,
                  PtyOptions{endpoint.baud, endpoint.reset_on_open, milliseconds(10), {}}) {}

PtyListener::~PtyListener() {
  close();
}

void PtyListener::start(std::function<void(BytePipePtr)> on_accept) {
  if (state_->mode != State::Mode::idle) return;
  state_->on_accept = std::move(on_accept);
  state_->mode = State::Mode::waiting_open;
  asio::post(state_->io, [self = state_] { self->poll(); });
}

void PtyListener::close() {
  auto& s = *state_;
  if (s.mode == State::Mode::closed) return;
  const bool had_session = s.mode == State::Mode::in_session;
  s.mode = State::Mode::closed;
  s.poll_timer.cancel();
  if (auto pipe = s.session.lock(); had_session && pipe) {
    s.lost_in_past_sessions += pipe->bytes_lost();
    pipe->hang_up();
  }
  s.session.reset();
  s.on_accept = nullptr;
  // Closing the master hangs up the slave: the client's reads fail, as
  // when a USB serial adapter is unplugged.
  std::error_code ignored;
  s.master->close(ignored);
  remove_symlink(s.path, s.slave);
}

std::string PtyListener::address() const {
  return to_uri(
      Endpoint{PtyEndpoint{state_->path, state_->options.baud, state_->options.reset_on_open}});
}

std::string PtyListener::slave_path() const {
  return state_->slave;
}

std::uint64_t PtyListener::bytes_lost_to_reset() const {
  std::uint64_t lost = state_->lost_in_past_sessions;
  if (auto pipe = state_->session.lock()) lost += pipe->bytes_lost();
  return lost;
}

// ---------------------------------------------------------------- client

void pty_connect(asio::io_context& io, Executor& executor, const PtyEndpoint& endpoint,
                 ConnectHandler handler) {
  const int fd = ::open(endpoint.path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    const std::error_code ec(errno, std::system_category());
    executor.post([handler = std::move(handler), ec] { handler(ec, nullptr); });
    return;
  }
  make_raw(fd, endpoint.baud);
  auto descriptor = std::make_shared<Descriptor>(io, fd);
  PtyOptions unpaced;
  auto pipe = std::make_shared<PtyPipe>(executor, descriptor, unpaced, "pty " + endpoint.path,
                                        [descriptor](bool) {
                                          std::error_code ignored;
                                          descriptor->close(ignored);
                                        });
  executor.post([handler = std::move(handler), pipe] { handler({}, pipe); });
}

}  // namespace hil::link
