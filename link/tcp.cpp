#include "link/tcp.hpp"

#include <array>
#include <chrono>
#include <deque>
#include <functional>
#include <system_error>
#include <utility>
#include <vector>

#include <asio/connect.hpp>
#include <asio/error.hpp>
#include <asio/ip/tcp.hpp>
#include <asio/post.hpp>
#include <asio/steady_timer.hpp>
#include <asio/write.hpp>

namespace hil::link {
namespace {

using asio::ip::tcp;

/// How long a graceful close may take to flush the queue and see the peer's
/// FIN before the socket is closed anyway.
constexpr auto close_deadline = std::chrono::seconds(5);
/// Pause before accepting again after an accept error (e.g. EMFILE), so a
/// persistent error cannot spin the io_context.
constexpr auto accept_retry = std::chrono::milliseconds(100);
/// At most this many queued writes go into one gathered async_write.
constexpr std::size_t max_gather = 64;

std::string text_of(const tcp::endpoint& e) {
  const auto a = e.address();
  return (a.is_v6() ? "[" + a.to_string() + "]" : a.to_string()) + ":" + std::to_string(e.port());
}

class TcpPipe final : public BytePipe, public std::enable_shared_from_this<TcpPipe> {
 public:
  TcpPipe(tcp::socket socket, std::string description)
      : socket_(std::move(socket)),
        deadline_(socket_.get_executor()),
        description_(std::move(description)) {
    std::error_code ignored;
    // Frames are small and latency matters more than packet count.
    socket_.set_option(tcp::no_delay(true), ignored);
    // read() reads only once the socket is readable, and must never block.
    socket_.non_blocking(true, ignored);
  }

  void start(Handlers handlers) override {
    handlers_ = std::move(handlers);
    if (!reading_ && !peer_done_ && state_ != State::closed) read();
  }

  void write(ByteView bytes) override {
    if (state_ != State::open || send_ended_ || bytes.empty()) return;
    if (send_limit_ != 0 && queued_ + bytes.size() > send_limit_) {
      // The peer stopped reading: dropping it bounds what it can cost.
      abort(true);
      asio::post(socket_.get_executor(), [self = shared_from_this()] {
        self->notify_close(std::make_error_code(std::errc::no_buffer_space));
      });
      return;
    }
    queue_.emplace_back(bytes.begin(), bytes.end());
    queued_ += bytes.size();
    if (!writing_) write_queued();
  }

  void close(CloseMode mode) override {
    if (state_ != State::open) return;
    asio::post(socket_.get_executor(),
               [self = shared_from_this()] { self->notify_close(closed_here()); });
    if (mode == CloseMode::reset) {
      abort(true);
    } else {
      close_gracefully();
    }
  }

  void shutdown_send() override {
    if (state_ != State::open || send_ended_) return;
    send_ended_ = true;
    if (!writing_) send_fin();
  }

  bool is_open() const override { return state_ == State::open; }
  void set_send_limit(std::size_t bytes) override { send_limit_ = bytes; }
  std::size_t queued_bytes() const override { return queued_; }
  std::string describe() const override { return description_; }

  void pause_reading() override { paused_ = true; }
  void resume_reading() override {
    if (!paused_) return;
    paused_ = false;
    if (state_ == State::open && !reading_ && !peer_done_) read();
  }
  void when_drained_to(std::size_t bytes, std::function<void()> callback) override {
    if (state_ == State::closed || !callback) return;
    drain_.watch(bytes, queued_, std::move(callback), [this](std::function<void()> f) {
      asio::post(socket_.get_executor(), std::move(f));
    });
  }

 private:
  enum class State : std::uint8_t {
    open,
    flushing,   // close(graceful) called: the queue drains, input is discarded
    lingering,  // our FIN is sent: waiting for the peer's
    closed,
  };

  /// Sends what is queued, then FIN, then waits for the peer's FIN, all
  /// bounded by close_deadline.
  void close_gracefully() {
    state_ = State::flushing;
    deadline_.expires_after(close_deadline);
    deadline_.async_wait([self = shared_from_this()](std::error_code ec) {
      if (!ec) self->abort(false);
    });
    // Keep reading so the peer's FIN is seen and unread input cannot turn
    // our close into a reset that would destroy data the peer has not read.
    if (!reading_ && !peer_done_) read();
    if (!writing_) shut_down_send();
  }

  /// Waits until the socket is readable and only then reads, into one
  /// buffer per thread: an idle connection holds no read buffer, so a
  /// thousand open connections cost a few hundred KiB, not 64 MiB.
  void read() {
    reading_ = true;
    socket_.async_wait(tcp::socket::wait_read, [self = shared_from_this()](std::error_code ec) {
      if (ec) {
        self->on_read(ec, 0);
        return;
      }
      if (self->paused_ && self->state_ == State::open) {
        // Readable, but the relay is holding this peer back: leave the
        // bytes in the kernel until resume_reading().
        self->reading_ = false;
        return;
      }
      std::error_code read_ec;
      const std::size_t n = self->socket_.read_some(asio::buffer(read_buffer()), read_ec);
      if (read_ec == asio::error::would_block || read_ec == asio::error::try_again) {
        self->reading_ = false;
        if (self->state_ != State::closed) self->read();
        return;
      }
      self->on_read(read_ec, n);
    });
  }

  /// Handlers never run nested inside another pipe's read, so one buffer
  /// per thread is never in use twice.
  static std::array<std::uint8_t, 64 * 1024>& read_buffer() {
    static thread_local std::array<std::uint8_t, 64 * 1024> buffer{};
    return buffer;
  }

  void on_read(std::error_code ec, std::size_t n) {
    reading_ = false;
    if (state_ == State::closed) return;
    if (state_ != State::open) {
      // Closing: input is discarded; the peer's FIN (or an error) ends it.
      if (!ec) {
        read();
      } else {
        peer_done_ = true;
        if (state_ == State::lingering || ec != asio::error::eof) abort(false);
      }
      return;
    }
    if (n > 0 && handlers_.on_data) handlers_.on_data(ByteView(read_buffer().data(), n));
    if (state_ != State::open) {
      // on_data closed the pipe; close() keeps the drain going if needed.
      return;
    }
    if (!ec) {
      read();
    } else if (ec == asio::error::eof) {
      peer_done_ = true;
      if (handlers_.on_end) {
        // A half-close: the peer may still read, so this end stays open
        // for writing until shutdown_send() or close().
        auto on_end = handlers_.on_end;  // the handler may close the pipe
        on_end();
        if (state_ == State::open && fin_sent_) {
          abort(false);
          notify_close(ec);
        }
        return;
      }
      // The peer will send nothing more. What we queued still goes out
      // (it may be reading until our FIN), then we close.
      close_gracefully();
      notify_close(ec);
    } else {
      abort(false);
      notify_close(ec);
    }
  }

  void write_queued() {
    writing_ = true;
    std::vector<asio::const_buffer> buffers;
    for (std::size_t i = 0; i < queue_.size() && i < max_gather; ++i)
      buffers.push_back(asio::buffer(queue_[i]));
    in_flight_ = buffers.size();
    asio::async_write(
        socket_, buffers,
        [self = shared_from_this()](std::error_code ec, std::size_t) { self->on_written(ec); });
  }

  void on_written(std::error_code ec) {
    writing_ = false;
    if (state_ == State::closed) return;
    if (ec) {
      const bool was_open = state_ == State::open;
      abort(false);
      if (was_open) notify_close(ec);
      return;
    }
    for (; in_flight_ > 0; --in_flight_) {
      queued_ -= queue_.front().size();
      queue_.pop_front();
    }
    drain_.update(queued_);
    if (state_ == State::closed) return;
    if (!queue_.empty()) {
      write_queued();
    } else if (state_ == State::flushing) {
      shut_down_send();
    } else if (send_ended_ && !fin_sent_) {
      send_fin();
    }
  }

  /// shutdown_send()'s FIN, once the queue is out; the pipe stays open
  /// for reading. If the peer has ended too, both directions are over.
  void send_fin() {
    std::error_code ignored;
    socket_.shutdown(tcp::socket::shutdown_send, ignored);
    fin_sent_ = true;
    if (!peer_done_) return;
    abort(false);
    asio::post(socket_.get_executor(),
               [self = shared_from_this()] { self->notify_close(end_of_stream()); });
  }

  void shut_down_send() {
    std::error_code ignored;
    socket_.shutdown(tcp::socket::shutdown_send, ignored);
    state_ = State::lingering;
    if (peer_done_) abort(false);
  }

  /// Closes the socket now; with `reset`, the peer sees a connection reset.
  void abort(bool reset) {
    std::error_code ignored;
    if (reset) socket_.set_option(asio::socket_base::linger(true, 0), ignored);
    socket_.close(ignored);
    deadline_.cancel();
    state_ = State::closed;
    queue_.clear();
    queued_ = 0;
    drain_.cancel();
  }

  void notify_close(std::error_code ec) {
    ec = portable_error(ec);
    if (close_notified_) return;
    close_notified_ = true;
    // Handlers often capture the pipe; dropping them breaks that cycle.
    auto on_close = std::move(handlers_.on_close);
    handlers_ = {};
    if (on_close) on_close(ec);
  }

  tcp::socket socket_;
  asio::steady_timer deadline_;
  std::string description_;
  Handlers handlers_;
  State state_ = State::open;
  bool reading_ = false;
  bool writing_ = false;
  bool peer_done_ = false;
  bool send_ended_ = false;  // shutdown_send() called: writes are ignored
  bool fin_sent_ = false;    // shutdown_send()'s FIN is out
  bool close_notified_ = false;
  bool paused_ = false;  // pause_reading(): readable input stays in the kernel
  // A deque keeps each queued buffer in place while an async_write uses it.
  std::deque<Bytes> queue_;
  std::size_t in_flight_ = 0;  // queue_ entries the current async_write covers
  std::size_t queued_ = 0;
  std::size_t send_limit_ = 0;  // 0: no cap
  DrainWatch drain_;            // when_drained_to()
};

tcp::endpoint resolve_for_listen(asio::io_context& io, const TcpEndpoint& endpoint,
                                 const std::string& uri) {
  const std::string host = endpoint.host.empty() ? "127.0.0.1" : endpoint.host;
  std::error_code ec;
  const auto address = asio::ip::make_address(host, ec);
  if (!ec) return {address, endpoint.port};
  tcp::resolver resolver(io);
  const auto results = resolver.resolve(host, std::to_string(endpoint.port), ec);
  if (ec || results.empty()) {
    throw std::system_error(portable_error(ec ? ec : asio::error::host_not_found),
                            uri + ": cannot resolve '" + host + "'");
  }
  return results.begin()->endpoint();
}

}  // namespace

struct TcpListener::State : std::enable_shared_from_this<TcpListener::State> {
  explicit State(asio::io_context& io) : acceptor(io), retry(io) {}

  void accept() {
    acceptor.async_accept([self = shared_from_this()](std::error_code ec, tcp::socket socket) {
      if (ec == asio::error::operation_aborted || !self->acceptor.is_open()) return;
      if (ec) {
        self->retry.expires_after(accept_retry);
        self->retry.async_wait([self](std::error_code wait_ec) {
          if (!wait_ec && self->acceptor.is_open()) self->accept();
        });
        return;
      }
      std::error_code peer_ec;
      const auto peer = socket.remote_endpoint(peer_ec);
      auto pipe = std::make_shared<TcpPipe>(
          std::move(socket), "tcp " + self->local + " <- " + (peer_ec ? "?" : text_of(peer)));
      self->accept();
      if (self->on_accept) self->on_accept(std::move(pipe));
    });
  }

  tcp::acceptor acceptor;
  asio::steady_timer retry;
  std::function<void(BytePipePtr)> on_accept;
  std::string local;  // host:port actually bound
};

TcpListener::TcpListener(asio::io_context& io, const TcpEndpoint& endpoint)
    : state_(std::make_shared<State>(io)) {
  const std::string uri = to_uri(Endpoint{endpoint});
  const tcp::endpoint bind_to = resolve_for_listen(io, endpoint, uri);
  auto& acceptor = state_->acceptor;
  std::error_code ec;
  acceptor.open(bind_to.protocol(), ec);
  if (!ec) acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
  if (!ec) acceptor.bind(bind_to, ec);
  if (!ec) acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) throw std::system_error(portable_error(ec), uri + ": cannot listen");
  state_->local = text_of(acceptor.local_endpoint());
}

TcpListener::~TcpListener() {
  close();
}

void TcpListener::start(std::function<void(BytePipePtr)> on_accept) {
  state_->on_accept = std::move(on_accept);
  if (state_->acceptor.is_open()) state_->accept();
}

void TcpListener::close() {
  std::error_code ignored;
  state_->acceptor.close(ignored);
  state_->retry.cancel();
  state_->on_accept = nullptr;
}

std::string TcpListener::address() const {
  return "tcp://" + state_->local;
}

std::uint16_t TcpListener::port() const {
  std::error_code ec;
  const auto e = state_->acceptor.local_endpoint(ec);
  return ec ? 0 : e.port();
}

void tcp_connect(asio::io_context& io, const TcpEndpoint& endpoint, ConnectHandler handler) {
  struct Op {
    Op(asio::io_context& context, ConnectHandler h)
        : resolver(context), socket(context), handler(std::move(h)) {}
    tcp::resolver resolver;
    tcp::socket socket;
    ConnectHandler handler;
  };
  auto op = std::make_shared<Op>(io, std::move(handler));
  const std::string host = endpoint.host.empty() ? "127.0.0.1" : endpoint.host;
  op->resolver.async_resolve(
      host, std::to_string(endpoint.port),
      [op](std::error_code ec, const tcp::resolver::results_type& results) {
        if (ec) {
          op->handler(portable_error(ec), nullptr);
          return;
        }
        asio::async_connect(
            op->socket, results, [op](std::error_code connect_ec, const tcp::endpoint& remote) {
              if (connect_ec) {
                op->handler(portable_error(connect_ec), nullptr);
                return;
              }
              std::error_code local_ec;
              const auto local = op->socket.local_endpoint(local_ec);
              auto description = "tcp " + (local_ec ? std::string("?") : text_of(local)) + " -> " +
                                 text_of(remote);
              op->handler({},
                          std::make_shared<TcpPipe>(std::move(op->socket), std::move(description)));
            });
      });
}

}  // namespace hil::link
