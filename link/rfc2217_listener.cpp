#include "link/rfc2217_listener.hpp"

#include <deque>
#include <optional>
#include <utility>

#include "link/endpoint.hpp"
#include "link/serial_pacer.hpp"

namespace hil::link {
namespace {

/// Client bytes that may wait for pacing before the connection is left
/// unread (as on a pty): 4 s of input at 9600 baud.
constexpr std::size_t kMaxRfc2217InputBytes = 4096;

/// "tcp 127.0.0.1:4000 <- 127.0.0.1:5000" -> "rfc2217 127.0.0.1:4000 <- 127.0.0.1:5000".
std::string rfc2217_description(std::string inner) {
  if (inner.starts_with("tcp ")) inner.erase(0, 4);
  return "rfc2217 " + inner;
}

/// The client's side of a description: what follows "<- ", or all of it.
std::string peer_of(const std::string& description) {
  const std::size_t arrow = description.find("<- ");
  return arrow == std::string::npos ? description : description.substr(arrow + 3);
}

/// A serial line whose rate can change: bytes already queued finish at the
/// rate they were queued at, later bytes go out at the new one after them
/// (a port reconfigured while sending finishes the character in flight).
class PacedLine {
 public:
  using Sink = SerialPacer::Sink;

  PacedLine(Executor& executor, unsigned baud, Sink sink)
      : executor_(executor), sink_(std::move(sink)), baud_(baud), current_(make(baud)) {}

  void push(ByteView bytes) {
    if (draining_) {
      held_.insert(held_.end(), bytes.begin(), bytes.end());
      return;
    }
    current_->push(bytes);
  }

  void set_baud(unsigned baud) {
    if (baud == baud_) return;
    baud_ = baud;
    if (draining_ || current_->queued() == 0) {
      // Nothing of the old rate is in this pacer (a draining one holds it).
      current_ = make(baud);
      return;
    }
    draining_ = std::move(current_);
    current_ = make(baud);
    draining_->when_drained([this, alive = std::weak_ptr<int>(alive_)] {
      // Not from inside the old pacer's own release.
      executor_.post([this, alive] {
        if (alive.expired() || !draining_) return;
        draining_.reset();
        const Bytes held = std::exchange(held_, {});
        current_->push(held);
        if (drained_) maybe_drained();
      });
    });
  }

  void clear() {
    draining_.reset();
    held_.clear();
    current_->clear();
    drained_ = nullptr;
  }

  std::size_t queued() const {
    return current_->queued() + held_.size() + (draining_ ? draining_->queued() : 0);
  }

  /// Runs `done` once everything pushed so far is out (at once if nothing
  /// is queued); a later call replaces a waiting one.
  void when_drained(std::function<void()> done) {
    drained_ = std::move(done);
    maybe_drained();
  }

 private:
  std::unique_ptr<SerialPacer> make(unsigned baud) {
    return std::make_unique<SerialPacer>(executor_, baud, [this](ByteView b) { sink_(b); });
  }

  void maybe_drained() {
    if (draining_) return;  // the new pacer is asked once the old one is done
    current_->when_drained([this] {
      if (auto done = std::exchange(drained_, nullptr)) done();
    });
  }

  Executor& executor_;
  Sink sink_;
  unsigned baud_;
  std::unique_ptr<SerialPacer> current_;
  std::unique_ptr<SerialPacer> draining_;  // the old rate's bytes still going out
  Bytes held_;                             // pushed while draining_ runs
  std::function<void()> drained_;
  std::shared_ptr<int> alive_ = std::make_shared<int>(0);
};

/// One client session: Telnet/RFC 2217 on `inner`, data bytes to the car.
class Rfc2217Pipe final : public BytePipe, public std::enable_shared_from_this<Rfc2217Pipe> {
 public:
  /// Called once when the session is over, with the bytes it lost to
  /// reset_on_open.
  using OnEnd = std::function<void(std::uint64_t lost)>;

  Rfc2217Pipe(Executor& executor, BytePipePtr inner, const Rfc2217Options& options, OnEnd on_end)
      : executor_(executor),
        inner_(std::move(inner)),
        options_(options),
        on_end_(std::move(on_end)),
        description_(describe_inner(*inner_)),
        opened_at_(executor.now()),
        codec_(Rfc2217Server::Config{LineSettings{options.baud}, options.signature}),
        tx_(executor, options.baud, [this](ByteView b) { to_client(b); }),
        rx_(executor, options.baud, [this](ByteView b) { deliver(b); }) {}

  ~Rfc2217Pipe() override {
    if (state_ == State::open || state_ == State::flushing) inner_->close(CloseMode::reset);
    end_session();
  }

  void start(Handlers handlers) override {
    handlers_ = std::move(handlers);
    if (started_ || state_ != State::open) return;
    started_ = true;
    std::weak_ptr<Rfc2217Pipe> weak = weak_from_this();
    inner_->start(Handlers{[weak](ByteView bytes) {
                             if (auto self = weak.lock()) self->from_network(bytes);
                           },
                           [weak](std::error_code ec) {
                             if (auto self = weak.lock()) self->network_closed(ec);
                           }});
    codec_.open();
    flush_to_client();
  }

  void write(ByteView bytes) override {
    if (state_ != State::open || bytes.empty()) return;
    if (send_limit_ != 0 && queued_bytes() + bytes.size() > send_limit_) {
      // The client stopped reading: end its session rather than grow.
      abort(std::make_error_code(std::errc::no_buffer_space));
      return;
    }
    tx_.push(bytes);
  }

  void close(CloseMode mode) override {
    if (state_ != State::open) return;
    rx_.clear();
    if (mode == CloseMode::reset) {
      abort(closed_here());
      return;
    }
    post_close(closed_here());
    state_ = State::flushing;
    suspended_ = false;
    release_held();
    tx_.when_drained([weak = weak_from_this()] {
      auto self = weak.lock();
      if (!self || self->state_ != State::flushing) return;
      self->state_ = State::closed;
      self->inner_->close(CloseMode::graceful);
      self->end_session();
    });
  }

  bool is_open() const override { return state_ == State::open; }
  void set_send_limit(std::size_t bytes) override { send_limit_ = bytes; }
  std::size_t queued_bytes() const override {
    return tx_.queued() + held_.size() + inner_->queued_bytes();
  }
  std::string describe() const override { return description_; }
  std::uint64_t bytes_lost() const { return lost_; }

  /// The port opens again while the last client's bytes are still on the
  /// line to the car: the board resets, so they never arrive. Ends this
  /// session now (on_close with end_of_stream()).
  void cut_short() {
    if (state_ != State::client_gone) return;
    if (rx_.queued() > 0) {
      say("the port opened again with " + std::to_string(rx_.queued()) +
          " byte(s) of this session still on the line; the board's reset loses them");
    }
    rx_.clear();
    state_ = State::closed;
    notify_close(end_of_stream());
  }

  void pause_reading() override {
    paused_ = true;
    inner_->pause_reading();
  }
  void resume_reading() override {
    paused_ = false;
    if (rx_.queued() <= kMaxRfc2217InputBytes) inner_->resume_reading();
  }

  void when_drained_to(std::size_t bytes, std::function<void()> callback) override {
    if (state_ == State::closed || !callback) return;
    drain_level_ = bytes;
    drain_.watch(
        bytes, queued_bytes(),
        [weak = weak_from_this(), callback = std::move(callback)] {
          if (auto self = weak.lock()) self->drain_level_.reset();
          callback();
        },
        [this](std::function<void()> f) { executor_.post(std::move(f)); });
    arm_inner_drain();
  }

 private:
  enum class State : std::uint8_t { open, client_gone, flushing, closed };

  static std::string describe_inner(const BytePipe& inner) {
    return rfc2217_description(inner.describe());
  }

  void say(const std::string& line) const {
    if (options_.log) options_.log(description_ + ": " + line);
  }

  void from_network(ByteView bytes) {
    if (state_ != State::open && state_ != State::flushing) return;
    codec_.receive(bytes);
    for (const auto& e : codec_.take_events())
      on_event(e);
    const Bytes data = codec_.take_to_device();
    if (!data.empty() && state_ == State::open) received(data);
    flush_to_client();
  }

  void received(ByteView bytes) {
    if (executor_.now() - opened_at_ < options_.reset_on_open) {
      // The board is still in its bootloader: these bytes go nowhere.
      lost_ += bytes.size();
      say(std::to_string(bytes.size()) + " byte(s) lost to reset_on_open (" +
          std::to_string(lost_) + " so far)");
      return;
    }
    rx_.push(bytes);
    if (rx_.queued() > kMaxRfc2217InputBytes && !held_back_) {
      // A serial line takes at most its rate: leave the socket unread (the
      // client's sends slow down) until the backlog is paced in.
      held_back_ = true;
      inner_->pause_reading();
      rx_.when_drained([weak = weak_from_this()] {
        auto self = weak.lock();
        if (!self) return;
        self->held_back_ = false;
        if (!self->paused_) self->inner_->resume_reading();
      });
    }
  }

  void on_event(const Rfc2217Event& e) {
    using Kind = Rfc2217Event::Kind;
    switch (e.kind) {
      case Kind::problem:
        say(e.text);
        break;
      case Kind::line_changed:
        apply_line();
        break;
      case Kind::purge:
        // 1: what the device sent and the client has not got; 2: what the
        // client sent and the device has not read.
        if ((e.value & 1U) != 0) {
          tx_.clear();
          held_.clear();
        }
        if ((e.value & 2U) != 0) rx_.clear();
        break;
      case Kind::suspend:
        suspended_ = true;
        break;
      case Kind::resume:
        suspended_ = false;
        release_held();
        break;
      case Kind::break_state:
        if (e.value != 0) say("BREAK on: hil's line does not model a break; ignored");
        break;
      case Kind::flow_control:
        if (e.value == 2 || e.value == 3 || e.value == 15 || e.value == 16) {
          say(std::string(e.value == 2 || e.value == 15 ? "XON/XOFF" : "RTS/CTS") +
              " flow control accepted; the car reads at the line's rate, so hil's line never "
              "needs it (XON/XOFF bytes pass as data)");
        }
        break;
      default:
        break;
    }
  }

  /// The client's rate and framing pace the line from now on.
  void apply_line() {
    const LineSettings& line = codec_.settings();
    if (options_.baud == 0) return;  // unpaced whatever the client sets
    const unsigned rate = line.baud * 20U / line.half_bits_per_char();
    tx_.set_baud(rate);
    rx_.set_baud(rate);
    const LineSettings car{options_.baud};
    if (line != car) {
      mismatched_ = true;
      say("the client set " + line.describe() + " but the car's line runs at " + car.describe() +
          " (a real board would garble every byte); hil paces the line at " + line.describe() +
          " and passes the bytes intact, as a pty does whatever its client sets");
    } else if (mismatched_) {
      mismatched_ = false;
      say("the client's line matches the car's again (" + car.describe() + ")");
    }
  }

  void to_client(ByteView bytes) {
    if (state_ != State::open && state_ != State::flushing) return;
    if (suspended_) {
      held_.insert(held_.end(), bytes.begin(), bytes.end());
      return;
    }
    codec_.send_data(bytes);
    flush_to_client();
  }

  void release_held() {
    if (held_.empty()) return;
    const Bytes held = std::exchange(held_, {});
    codec_.send_data(held);
    flush_to_client();
  }

  void flush_to_client() {
    const Bytes out = codec_.take_to_client();
    if (!out.empty() && (state_ == State::open || state_ == State::flushing)) inner_->write(out);
    drain_.update(queued_bytes());
    arm_inner_drain();
  }

  void arm_inner_drain() {
    if (!drain_level_) return;
    const std::size_t own = tx_.queued() + held_.size();
    if (own > *drain_level_) return;  // asked again as the line releases bytes
    inner_->when_drained_to(*drain_level_ - own, [weak = weak_from_this()] {
      if (auto self = weak.lock()) self->drain_.update(self->queued_bytes());
    });
  }

  void deliver(ByteView bytes) {
    if ((state_ == State::open || state_ == State::client_gone) && handlers_.on_data)
      handlers_.on_data(bytes);
  }

  void network_closed(std::error_code ec) {
    if (state_ == State::closed || state_ == State::client_gone) return;
    if (state_ == State::flushing) {
      state_ = State::closed;
      end_session();
      return;
    }
    state_ = State::client_gone;
    tx_.clear();
    held_.clear();
    end_session();
    // What the client wrote before closing still reaches the device.
    rx_.when_drained([weak = weak_from_this(), ec] {
      auto self = weak.lock();
      if (!self) return;
      self->state_ = State::closed;
      self->notify_close(ec);
    });
  }

  void abort(std::error_code ec) {
    state_ = State::closed;
    tx_.clear();
    rx_.clear();
    held_.clear();
    drain_.cancel();
    inner_->close(CloseMode::reset);
    post_close(ec);
    end_session();
  }

  void end_session() {
    if (auto end = std::exchange(on_end_, nullptr)) end(lost_);
  }

  void post_close(std::error_code ec) {
    executor_.post([self = shared_from_this(), ec] { self->notify_close(ec); });
  }

  void notify_close(std::error_code ec) {
    if (close_notified_) return;
    close_notified_ = true;
    drain_.cancel();
    // Handlers often capture the pipe; dropping them breaks that cycle.
    auto on_close = std::move(handlers_.on_close);
    handlers_ = {};
    if (on_close) on_close(ec);
  }

  Executor& executor_;
  BytePipePtr inner_;
  Rfc2217Options options_;
  OnEnd on_end_;
  std::string description_;
  Time opened_at_;
  Rfc2217Server codec_;
  Handlers handlers_;
  State state_ = State::open;
  bool started_ = false;
  bool close_notified_ = false;
  bool paused_ = false;     // pause_reading() by the owner
  bool held_back_ = false;  // too much input waits for the line
  bool suspended_ = false;  // FLOWCONTROL-SUSPEND from the client
  bool mismatched_ = false;
  std::uint64_t lost_ = 0;
  Bytes held_;  // paced bytes for the client while it suspended the flow
  std::size_t send_limit_ = 0;
  DrainWatch drain_;
  std::optional<std::size_t> drain_level_;
  PacedLine tx_;  // car -> client
  PacedLine rx_;  // client -> car
};

}  // namespace

struct Rfc2217Listener::State : std::enable_shared_from_this<Rfc2217Listener::State> {
  State(Executor& exec, std::unique_ptr<Listener> in, Rfc2217Options opts)
      : executor(exec), inner(std::move(in)), options(std::move(opts)) {}

  void say(const std::string& line) const {
    if (options.log) options.log(line);
  }

  void accepted(BytePipePtr client) {
    if (closed) {
      client->close(CloseMode::reset);
      return;
    }
    if (in_session) {
      ++refused;
      const auto current = session.lock();
      say(rfc2217_description(client->describe()) + ": refused: the port is in use by " +
          (current ? peer_of(current->describe()) : std::string("another client")) +
          " (one client at a time, as on a serial port)");
      client->close(CloseMode::graceful);
      return;
    }
    if (auto last = previous.lock()) last->cut_short();
    previous.reset();
    in_session = true;
    auto pipe = std::make_shared<Rfc2217Pipe>(executor, std::move(client), options,
                                              [weak = weak_from_this()](std::uint64_t lost) {
                                                if (auto self = weak.lock()) {
                                                  self->in_session = false;
                                                  self->lost_in_past_sessions += lost;
                                                  self->previous = self->session;
                                                  self->session.reset();
                                                }
                                              });
    session = pipe;
    if (on_accept) {
      on_accept(pipe);
    } else {
      pipe->close(CloseMode::reset);
    }
  }

  std::string address() const {
    const std::string inner_address = inner->address();
    if (!inner_address.starts_with("tcp://")) return inner_address;
    const auto tcp = std::get<TcpEndpoint>(parse_endpoint(inner_address));
    return to_uri(
        Endpoint{Rfc2217Endpoint{tcp.host, tcp.port, options.baud, options.reset_on_open}});
  }

  Executor& executor;
  std::unique_ptr<Listener> inner;
  Rfc2217Options options;
  std::function<void(BytePipePtr)> on_accept;
  std::weak_ptr<Rfc2217Pipe> session;
  // The last session, while its client's bytes may still be on the line.
  std::weak_ptr<Rfc2217Pipe> previous;
  bool in_session = false;
  bool closed = false;
  std::uint64_t lost_in_past_sessions = 0;
  std::uint64_t refused = 0;
};

Rfc2217Listener::Rfc2217Listener(Executor& executor, std::unique_ptr<Listener> inner,
                                 Rfc2217Options options)
    : state_(std::make_shared<State>(executor, std::move(inner), std::move(options))) {}

Rfc2217Listener::~Rfc2217Listener() {
  close();
}

void Rfc2217Listener::start(std::function<void(BytePipePtr)> on_accept) {
  state_->on_accept = std::move(on_accept);
  state_->inner->start([weak = std::weak_ptr<State>(state_)](BytePipePtr client) {
    if (auto self = weak.lock()) self->accepted(std::move(client));
  });
}

void Rfc2217Listener::close() {
  if (state_->closed) return;
  state_->closed = true;
  state_->on_accept = nullptr;
  state_->inner->close();
}

std::string Rfc2217Listener::address() const {
  return state_->address();
}

std::uint64_t Rfc2217Listener::bytes_lost_to_reset() const {
  std::uint64_t lost = state_->lost_in_past_sessions;
  if (auto pipe = state_->session.lock()) lost += pipe->bytes_lost();
  return lost;
}

std::uint64_t Rfc2217Listener::connections_refused() const {
  return state_->refused;
}

}  // namespace hil::link
