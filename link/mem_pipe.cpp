#include "link/mem_pipe.hpp"

#include <deque>

#include "link/endpoint.hpp"

namespace hil::link {
namespace {

class MemPipe final : public BytePipe, public std::enable_shared_from_this<MemPipe> {
 public:
  MemPipe(Executor& executor, std::string name) : executor_(executor), name_(std::move(name)) {}

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
    if (!open_ || bytes.empty()) return;
    auto peer = peer_.lock();
    if (!peer) return;
    in_flight_ += bytes.size();
    executor_.post([self = shared_from_this(), peer, data = Bytes(bytes.begin(), bytes.end())] {
      self->in_flight_ -= data.size();
      peer->receive(data);
    });
  }

  void close(CloseMode mode) override {
    if (!open_) return;
    open_ = false;
    if (auto peer = peer_.lock()) {
      if (mode == CloseMode::reset) peer->discard_ = true;  // data in flight is lost, as with RST
      const auto ec = mode == CloseMode::reset ? std::make_error_code(std::errc::connection_reset)
                                               : end_of_stream();
      executor_.post([peer, ec] { peer->remote_closed(ec); });
    }
    executor_.post([self = shared_from_this()] { self->notify_close(closed_here()); });
  }

  bool is_open() const override { return open_; }
  std::size_t queued_bytes() const override { return in_flight_; }
  std::string describe() const override { return "mem " + name_; }

 private:
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
  bool open_ = true;
  bool started_ = false;
  bool discard_ = false;
  bool closed_notified_ = false;
};

}  // namespace

std::pair<BytePipePtr, BytePipePtr> make_mem_pipe(Executor& executor, const std::string& name) {
  auto a = std::make_shared<MemPipe>(executor, name + " (client end)");
  auto b = std::make_shared<MemPipe>(executor, name + " (server end)");
  a->connect_to(b);
  b->connect_to(a);
  return {a, b};
}

struct MemNetwork::Entry {
  std::function<void(BytePipePtr)> on_accept;
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
  std::string address() const override { return "mem://" + name_; }

 private:
  MemNetwork& network_;
  std::string name_;
  std::shared_ptr<MemNetwork::Entry> entry_;
};

std::unique_ptr<Listener> MemNetwork::listen(const std::string& name) {
  if (listeners_.count(name) != 0) throw EndpointError("mem://" + name + " is already listened on");
  auto entry = std::make_shared<Entry>();
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
  auto [client, server] = make_mem_pipe(executor_, name);
  // The server learns of the connection first, as with a TCP accept.
  executor_.post([entry = it->second, server = server] {
    if (entry->open && entry->on_accept) entry->on_accept(server);
  });
  executor_.post([handler = std::move(handler), client = client] { handler({}, client); });
}

}  // namespace hil::link
