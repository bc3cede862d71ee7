#pragma once
// Binds the LOGI client core to a hil transport (tcp://, pty:// or mem://)
// under either driver: performs its actions, feeds it bytes and closes, and
// keeps one executor timer for its next wakeup.

#include <functional>
#include <memory>
#include <optional>

#include "client/logi/core.hpp"
#include "link/endpoint.hpp"
#include "link/transport.hpp"

namespace hil::client::logi {

class LogiSession {
 public:
  using EventSink = std::function<void(Time now, const Event& event)>;

  /// `context` must outlive the session. Events go to `sink` on the executor.
  LogiSession(link::TransportContext& context, link::Endpoint endpoint, ClientConfig config = {},
              EventSink sink = {}, std::shared_ptr<CommLog> log = std::make_shared<CommLog>());
  ~LogiSession();
  LogiSession(const LogiSession&) = delete;
  LogiSession& operator=(const LogiSession&) = delete;

  void connect();
  void disconnect();
  SubmitResult submit(const proto::Message& command);
  SubmitResult press(proto::Direction direction);
  SubmitResult release();
  SubmitResult emergency_stop();
  SubmitResult confirm_resend(RequestId request);

  const LogiClientCore& core() const { return core_; }
  const std::shared_ptr<CommLog>& log() const { return core_.log(); }

 private:
  Time now() const { return context_.executor.now(); }
  /// Performs the core's actions, hands on its events, re-arms the timer.
  void flush();
  void reschedule();
  void open();

  link::TransportContext& context_;
  link::Endpoint endpoint_;
  EventSink sink_;
  LogiClientCore core_;
  link::BytePipePtr pipe_;
  std::uint64_t generation_ = 0;  // tells a current connection's callbacks from a closed one's
  link::Executor::TimerId timer_ = 0;
  std::optional<Time> timer_due_;
  bool flushing_ = false;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace hil::client::logi
