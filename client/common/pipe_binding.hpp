#pragma once
// The I/O half of every client session: opens an endpoint, owns the byte
// pipe, drops what an abandoned pipe still reports, and keeps one executor
// timer, so each session only moves bytes and times between its core and it.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <system_error>

#include "link/byte_pipe.hpp"
#include "link/endpoint.hpp"
#include "link/executor.hpp"
#include "link/time.hpp"
#include "link/transport.hpp"
#include "protocol/common/bytes.hpp"

namespace hil::client {

class PipeBinding {
 public:
  /// What the binding reports; each runs on the executor, never after the
  /// binding is gone, and never for a pipe that open() or close() replaced.
  struct Handlers {
    std::function<void()> connected;
    std::function<void(std::error_code)> connect_failed;
    std::function<void(protocol::ByteView)> bytes;
    std::function<void()> closed;  ///< the peer or the transport ended the pipe
    std::function<void()> timer;   ///< the time given to schedule() came
  };

  /// `context` must outlive the binding.
  PipeBinding(link::TransportContext& context, link::Endpoint endpoint, Handlers handlers);
  ~PipeBinding();
  PipeBinding(const PipeBinding&) = delete;
  PipeBinding& operator=(const PipeBinding&) = delete;

  /// Starts connecting; a pipe still open is closed first.
  void open();
  /// Closes the pipe (if any); nothing more is reported about it.
  void close();
  /// Writes to the open pipe; false (and nothing written) when there is none.
  bool write(protocol::ByteView bytes);
  bool has_pipe() const { return pipe_ != nullptr; }

  /// Keeps one timer due at `due` (none when nullopt); cheap to call after
  /// every input, as it only re-arms when the time changed.
  void schedule(std::optional<link::Time> due) { timer_.schedule(due); }

  link::Time now() const { return context_.executor.now(); }
  const link::Endpoint& endpoint() const { return endpoint_; }

 private:
  link::TransportContext& context_;
  link::Endpoint endpoint_;
  Handlers handlers_;
  link::BytePipePtr pipe_;
  std::uint64_t generation_ = 0;  // callbacks from an older pipe are ignored
  link::WakeupTimer timer_;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

/// Handlers that give `core` what the binding reports, stamped with `now()`,
/// then call `after()` (the session's drain): on_connected, on_bytes,
/// on_closed, on_timer, and on_connect_failed (with the system's message
/// when the core takes one; nothing when the core has none).
template <class Core, class Now, class After>
PipeBinding::Handlers core_handlers(Core& core, Now now, After after) {
  PipeBinding::Handlers h;
  h.connected = [&core, now, after] {
    core.on_connected(now());
    after();
  };
  if constexpr (requires { core.on_connect_failed(now(), std::string()); }) {
    h.connect_failed = [&core, now, after](std::error_code ec) {
      core.on_connect_failed(now(), ec.message());
      after();
    };
  } else if constexpr (requires { core.on_connect_failed(now()); }) {
    h.connect_failed = [&core, now, after](std::error_code) {
      core.on_connect_failed(now());
      after();
    };
  } else {
    h.connect_failed = [after](std::error_code) { after(); };
  }
  h.bytes = [&core, now, after](protocol::ByteView bytes) {
    core.on_bytes(now(), bytes);
    after();
  };
  h.closed = [&core, now, after] {
    core.on_closed(now());
    after();
  };
  h.timer = [&core, now, after] {
    core.on_timer(now());
    after();
  };
  return h;
}

/// Hands `step` the core's pending actions and events until it has none
/// left (a step may cause more). A call made from inside a step returns at
/// once, so a driver that completes an action synchronously cannot re-enter.
template <class Core, class Step>
void drain_core(Core& core, bool& draining, Step&& step) {
  if (draining) return;
  struct Reset {
    bool& flag;
    ~Reset() { flag = false; }
  } reset{draining};
  draining = true;
  for (;;) {
    auto actions = core.take_actions();
    auto events = core.take_events();
    if (actions.empty() && events.empty()) break;
    step(actions, events);
  }
}

}  // namespace hil::client
