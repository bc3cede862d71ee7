#pragma once
// Binds the WR8 client core to a hil transport (tcp://, pty:// or mem://)
// under either driver: performs its actions, feeds it bytes and closes, and
// keeps one executor timer for its next wakeup.

#include <cstdint>
#include <memory>
#include <vector>

#include "client/common/connecting_session.hpp"
#include "client/wr8/core.hpp"

namespace hil::client::wr8 {

class Wr8Session
    : public ConnectingSession<Wr8ClientCore, Event, OpenConnection, SendBytes, CloseConnection> {
 public:
  /// `context` must outlive the session. Events go to `sink` on the executor.
  Wr8Session(link::TransportContext& context, link::Endpoint endpoint, ClientConfig config = {},
             EventSink sink = {}, std::shared_ptr<CommLog> log = std::make_shared<CommLog>())
      : ConnectingSession(context, std::move(endpoint), std::move(sink),
                          Wr8ClientCore(std::move(config), std::move(log))) {}
  /// The same on `core`, which may be of a class derived from Wr8ClientCore
  /// (a test's, with a rule broken on purpose); must not be null.
  Wr8Session(link::TransportContext& context, std::unique_ptr<Wr8ClientCore> core,
             link::Endpoint endpoint, EventSink sink = {})
      : ConnectingSession(context, std::move(endpoint), std::move(sink), std::move(core)) {}

  SubmitResult task(proto::TaskCode code, std::vector<proto::Word> params = {}) {
    return feed([&](Time t) { return mutable_core().task(t, code, std::move(params)); });
  }
  SubmitResult drive(std::int32_t distance_cm) {
    return feed([&](Time t) { return mutable_core().drive(t, distance_cm); });
  }
  SubmitResult turn(std::int32_t angle_deg) {
    return feed([&](Time t) { return mutable_core().turn(t, angle_deg); });
  }
  SubmitResult get_settings() {
    return feed([&](Time t) { return mutable_core().get_settings(t); });
  }
  SubmitResult set_settings(std::vector<proto::Setting> settings) {
    return feed([&](Time t) { return mutable_core().set_settings(t, std::move(settings)); });
  }
};

}  // namespace hil::client::wr8
