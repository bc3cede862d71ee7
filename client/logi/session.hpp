#pragma once
// Binds the LOGI client core to a hil transport (tcp://, pty:// or mem://)
// under either driver: performs its actions, feeds it bytes and closes, and
// keeps one executor timer for its next wakeup.

#include <memory>

#include "client/common/connecting_session.hpp"
#include "client/logi/core.hpp"

namespace hil::client::logi {

class LogiSession
    : public ConnectingSession<LogiClientCore, Event, OpenConnection, SendBytes, CloseConnection> {
 public:
  /// `context` must outlive the session. Events go to `sink` on the executor.
  LogiSession(link::TransportContext& context, link::Endpoint endpoint, ClientConfig config = {},
              EventSink sink = {}, std::shared_ptr<CommLog> log = std::make_shared<CommLog>())
      : ConnectingSession(context, std::move(endpoint), std::move(sink),
                          LogiClientCore(std::move(config), std::move(log))) {}
  /// The same on `core`, which may be of a class derived from LogiClientCore
  /// (a test's, with a rule broken on purpose); must not be null.
  LogiSession(link::TransportContext& context, std::unique_ptr<LogiClientCore> core,
              link::Endpoint endpoint, EventSink sink = {})
      : ConnectingSession(context, std::move(endpoint), std::move(sink), std::move(core)) {}

  SubmitResult submit(const proto::Message& command) {
    return feed([&](Time t) { return mutable_core().submit(t, command); });
  }
  SubmitResult press(proto::Direction direction) {
    return feed([&](Time t) { return mutable_core().press(t, direction); });
  }
  SubmitResult release() {
    return feed([&](Time t) { return mutable_core().release(t); });
  }
  SubmitResult emergency_stop() {
    return feed([&](Time t) { return mutable_core().emergency_stop(t); });
  }
  SubmitResult confirm_resend(RequestId request) {
    return feed([&](Time t) { return mutable_core().confirm_resend(t, request); });
  }
};

}  // namespace hil::client::logi
