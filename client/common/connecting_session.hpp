#pragma once
// The session shape shared by the TCP clients (LOGI, WR8): a core that asks
// to open, write and close a connection, bound to a hil transport under
// either driver, its events handed to one sink on the executor.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <system_error>
#include <type_traits>
#include <utility>
#include <variant>

#include "client/common/pipe_binding.hpp"
#include "link/endpoint.hpp"
#include "link/time.hpp"
#include "link/transport.hpp"

namespace hil::client {

/// `Core` has connect/disconnect/on_connected/on_connect_failed/on_bytes/
/// on_closed/on_timer(now), take_actions(), take_events(), next_wakeup() and log();
/// its actions are a variant of `Open`, `Send` (bytes in `.bytes` or text in
/// `.text`) and `Close`.
template <class Core, class Event, class Open, class Send, class Close>
class ConnectingSession {
 public:
  using EventSink = std::function<void(link::Time now, const Event& event)>;

  /// `context` must outlive the session. Events go to `sink` on the executor.
  ConnectingSession(link::TransportContext& context, link::Endpoint endpoint, EventSink sink,
                    Core core)
      : ConnectingSession(context, std::move(endpoint), std::move(sink),
                          std::make_unique<Core>(std::move(core))) {}
  /// The same on a core of a class derived from `Core` (a test's, with a
  /// rule broken on purpose). `core` must not be null.
  ConnectingSession(link::TransportContext& context, link::Endpoint endpoint, EventSink sink,
                    std::unique_ptr<Core> core)
      : sink_(std::move(sink)),
        core_(std::move(core)),
        binding_(context, std::move(endpoint),
                 core_handlers(
                     *core_, [this] { return now(); }, [this] { flush(); })) {}
  ConnectingSession(const ConnectingSession&) = delete;
  ConnectingSession& operator=(const ConnectingSession&) = delete;

  void connect() {
    feed([&](link::Time t) { core_->connect(t); });
  }
  void disconnect() {
    feed([&](link::Time t) { core_->disconnect(t); });
  }

  const Core& core() const { return *core_; }
  /// The core's communication log.
  const auto& log() const { return core_->log(); }

 protected:
  link::Time now() const { return binding_.now(); }

  /// Runs `f(now)` on the core, performs what it caused, returns f's result.
  template <class F>
  auto feed(F&& f) {
    if constexpr (std::is_void_v<std::invoke_result_t<F&, link::Time>>) {
      f(now());
      flush();
    } else {
      auto result = f(now());
      flush();
      return result;
    }
  }

  Core& mutable_core() { return *core_; }

 private:
  void flush() {
    drain_core(*core_, flushing_, [this](auto& actions, auto& events) {
      for (const auto& action : actions) {
        if (std::holds_alternative<Open>(action)) {
          binding_.open();
        } else if (const auto* send = std::get_if<Send>(&action)) {
          if constexpr (requires { send->text; }) {
            binding_.write(protocol::ByteView(
                reinterpret_cast<const std::uint8_t*>(send->text.data()), send->text.size()));
          } else {
            binding_.write(send->bytes);
          }
        } else if (std::holds_alternative<Close>(action)) {
          binding_.close();  // what the old connection still reports is not news
        }
      }
      if (sink_) {
        for (const auto& event : events)
          sink_(now(), event);
      }
    });
    binding_.schedule(core_->next_wakeup());
  }

  EventSink sink_;
  std::unique_ptr<Core> core_;
  bool flushing_ = false;
  PipeBinding binding_;  // last: its callbacks use the members above
};

}  // namespace hil::client
