#include "link/mem_pipe.hpp"

#include <deque>

#include "link/endpoint.hpp"
#include "link/serial_pacer.hpp"

namespace hil::link {
namespace {

// Beyond the line time of the queued bytes: the pacer's tick rounding.
constexpr Duration kLineSlack = milliseconds(20);

class MemPipe final : public BytePipe, public std::enable_shared_from_this<MemPipe> {
 public:
  MemPipe(Executor& executor, std::string name, unsigned baud)
      : executor_(executor),
        name_(std::move(name)),
        baud_(baud),
        line_(executor, baud,
              [this](ByteView chunk) { arrive(Bytes(chunk.begin(), chunk.end())); }) {}

  void connect_to(const std::shared_ptr<MemPipe>& peer) { peer_ = peer; }

  void start(Handlers handlers) override {
    handlers_ = std::move(handlers);
    started_ = true;
    // Anything that arrived before start() is delivered now, in order.
    if (!early_.empty() || early_close_) {
      executor_.post([self = shared_from_this()] { self->flush_early(); });
    }
  }

  void write(ByteView bytes) override {
    if (!open_ || send_ended_ || bytes.empty()) return;
    auto peer = peer_.lock();
    if (!peer) return;
    in_flight_ += bytes.size();
    if (baud_ != 0) {
      line_.push(bytes);
      watch_line();
      return;
    }
    executor_.post([self = shared_from_this(), data = Bytes(bytes.begin(), bytes.end())] {
      self->arrive(data);
    });
  }

  void close(CloseMode mode) override {
    if (!open_) return;
    open_ = false;
    if (auto peer = peer_.lock()) {
      if (mode == CloseMode::reset) {
        peer->discard_ = true;  // data in flight is lost, as with RST
        line_.clear();
        in_flight_ = 0;
        watching_line_ = false;
        end_after_line_ = End::none;
        executor_.post(
            [peer] { peer->remote_closed(std::make_error_code(std::errc::connection_reset)); });
      } else if (!send_ended_) {
        send_end(End::close);
      }
    }
    executor_.post([self = shared_from_this()] { self->notify_close(closed_here()); });
  }

  void shutdown_send() override {
    if (!open_ || send_ended_) return;
    auto peer = peer_.lock();
    // An end that cannot take a half-close sees a close, as before.
    if (!peer || !peer->takes_half_close()) {
      close(CloseMode::graceful);
      return;
    }
    send_ended_ = true;
    send_end(End::half);
    if (peer_ended_) close_both_ended();
  }

  bool is_open() const override { return open_; }
  std::size_t queued_bytes() const override { return in_flight_; }
  std::string describe() const override { return "mem " + name_; }

 private:
  /// How this end's stream ends at the peer: a close, or a half-close the
  /// peer may still answer.
  enum class End : std::uint8_t { none, close, half };

  bool takes_half_close() const { return started_ && handlers_.on_end && !closed_notified_; }

  /// The end of this end's stream reaches the peer after the bytes
  /// written before it (after those still on a paced line).
  void send_end(End end) {
    if (watching_line_) {
      end_after_line_ = end;
      return;
    }
    post_end(end);
  }

  void post_end(End end) {
    auto peer = peer_.lock();
    if (!peer || end == End::none) return;
    if (end == End::half) {
      executor_.post([peer] { peer->remote_ended(); });
    } else {
      executor_.post([peer] { peer->remote_closed(end_of_stream()); });
    }
  }

  /// The peer half-closed: on_end, and the pipe stays open for writing
  /// until shutdown_send() or close().
  void remote_ended() {
    if (closed_notified_ || peer_ended_) return;
    if (!handlers_.on_end) {
      remote_closed(end_of_stream());
      return;
    }
    peer_ended_ = true;
    auto on_end = handlers_.on_end;  // the handler may close the pipe
    on_end();
    if (send_ended_) close_both_ended();
  }

  /// Both directions have ended: the pipe is over.
  void close_both_ended() {
    if (!open_) return;
    open_ = false;
    executor_.post([self = shared_from_this()] { self->notify_close(end_of_stream()); });
  }

  /// While bytes are on a paced line, a timer on the executor holds this
  /// end until they are all out (so what was written arrives even if its
  /// owner lets go of it, and nothing is held once the executor is gone);
  /// a graceful close reaches the peer after them.
  void watch_line() {
    auto self = shared_from_this();
    if (keep_timer_ != 0) executor_.cancel(keep_timer_);
    const auto queued = static_cast<Duration::rep>(line_.queued() + 1);
    const Time until = executor_.now() + SerialPacer::byte_time(baud_) * queued + kLineSlack;
    keep_timer_ = executor_.call_at(until, [self] { self->keep_timer_ = 0; });
    if (watching_line_) return;
    watching_line_ = true;
    line_.when_drained([this] {
      watching_line_ = false;
      post_end(std::exchange(end_after_line_, End::none));
    });
  }

  /// Bytes written here reach the peer.
  void arrive(const Bytes& data) {
    in_flight_ -= std::min(in_flight_, data.size());
    if (auto peer = peer_.lock()) peer->receive(data);
  }

  void receive(const Bytes& data) {
    if (discard_ || closed_notified_) return;
    if (!started_) {
      early_.push_back(data);
      return;
    }
    if (handlers_.on_data) handlers_.on_data(data);
  }

  void remote_closed(std::error_code ec) {
    if (!started_) {
      early_close_ = ec;
      return;
    }
    open_ = false;
    notify_close(ec);
  }

  void notify_close(std::error_code ec) {
    if (closed_notified_) return;
    closed_notified_ = true;
    if (handlers_.on_close) handlers_.on_close(ec);
  }

  void flush_early() {
    while (!early_.empty()) {
      const Bytes data = std::move(early_.front());
      early_.pop_front();
      if (handlers_.on_data && !discard_) handlers_.on_data(data);
    }
    if (early_close_) {
      open_ = false;
      notify_close(*early_close_);
    }
  }

  Executor& executor_;
  std::string name_;
  std::weak_ptr<MemPipe> peer_;
  Handlers handlers_;
  std::deque<Bytes> early_;
  std::optional<std::error_code> early_close_;
  std::size_t in_flight_ = 0;
  unsigned baud_;
  SerialPacer line_;  // this end's writes; unused when unpaced
  Executor::TimerId keep_timer_ = 0;
  bool watching_line_ = false;
  End end_after_line_ = End::none;  // the end to send once the line is drained
  bool open_ = true;
  bool send_ended_ = false;  // shutdown_send(): the peer has this end's end
  bool peer_ended_ = false;  // on_end was called
  bool started_ = false;
  bool discard_ = false;
  bool closed_notified_ = false;
};

}  // namespace

std::pair<BytePipePtr, BytePipePtr> make_mem_pipe(Executor& executor, const std::string& name,
                                                  unsigned baud) {
  auto a = std::make_shared<MemPipe>(executor, name + " (client end)", baud);
  auto b = std::make_shared<MemPipe>(executor, name + " (server end)", baud);
  a->connect_to(b);
  b->connect_to(a);
  return {a, b};
}

struct MemNetwork::Entry {
  std::function<void(BytePipePtr)> on_accept;
  unsigned baud = 0;
  bool open = true;
};

class MemListener final : public Listener {
 public:
  MemListener(MemNetwork& network, std::string name, std::shared_ptr<MemNetwork::Entry> entry)
      : network_(network), name_(std::move(name)), entry_(std::move(entry)) {}
  ~MemListener() override { close(); }

  void start(std::function<void(BytePipePtr)> on_accept) override {
    entry_->on_accept = std::move(on_accept);
  }
  void close() override {
    if (!entry_->open) return;
    entry_->open = false;
    network_.listeners_.erase(name_);
  }
  std::string address() const override { return to_uri(MemEndpoint{name_, entry_->baud}); }

 private:
  MemNetwork& network_;
  std::string name_;
  std::shared_ptr<MemNetwork::Entry> entry_;
};

std::unique_ptr<Listener> MemNetwork::listen(const std::string& name, unsigned baud) {
  if (listeners_.count(name) != 0) throw EndpointError("mem://" + name + " is already listened on");
  auto entry = std::make_shared<Entry>();
  entry->baud = baud;
  listeners_.emplace(name, entry);
  return std::make_unique<MemListener>(*this, name, entry);
}

void MemNetwork::connect(const std::string& name, ConnectHandler handler) {
  const auto it = listeners_.find(name);
  if (it == listeners_.end() || !it->second->on_accept) {
    executor_.post([handler = std::move(handler)] {
      handler(std::make_error_code(std::errc::connection_refused), nullptr);
    });
    return;
  }
  auto [client, server] = make_mem_pipe(executor_, name, it->second->baud);
  // The server learns of the connection first, as with a TCP accept.
  executor_.post([entry = it->second, server = server] {
    if (entry->open && entry->on_accept) entry->on_accept(server);
  });
  executor_.post([handler = std::move(handler), client = client] { handler({}, client); });
}

}  // namespace hil::link
