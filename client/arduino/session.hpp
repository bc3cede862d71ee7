#pragma once
// Binds the Arduino client core to hil's transports under either driver:
// opens the endpoint (pty://, tcp://, mem://), writes the core's frames,
// feeds it what arrives, keeps one timer for its wakeup, and logs every frame.

#include <functional>
#include <memory>
#include <optional>
#include <string_view>

#include "client/arduino/comm_log.hpp"
#include "client/arduino/core.hpp"
#include "client/common/pipe_binding.hpp"
#include "client/common/request_callbacks.hpp"
#include "link/endpoint.hpp"
#include "link/transport.hpp"

namespace hil::client::arduino {

class ArduinoSession {
 public:
  using Callback = RequestCallbacks<RequestId, Result>::Callback;
  using EventHandler = std::function<void(const Event&)>;
  /// Wall-clock microseconds since the Unix epoch, for the log's timestamps.
  using WallClock = std::function<std::int64_t()>;

  /// `context` must outlive the session. Nothing happens until open().
  ArduinoSession(link::TransportContext& context, link::Endpoint endpoint,
                 ClientConfig config = {});
  /// The same on `core`, which may be of a class derived from
  /// ArduinoClientCore (a test's, with a rule broken on purpose); null throws
  /// std::invalid_argument.
  ArduinoSession(link::TransportContext& context, link::Endpoint endpoint,
                 std::unique_ptr<ArduinoClientCore> core);
  ArduinoSession(const ArduinoSession&) = delete;
  ArduinoSession& operator=(const ArduinoSession&) = delete;

  void open();
  void close();

  /// Every event of the core (request results, link changes, frames in).
  void set_event_handler(EventHandler handler) { on_event_ = std::move(handler); }
  /// Replaces the wall clock used for log timestamps (tests pin it).
  void set_wall_clock(WallClock clock) { wall_clock_ = std::move(clock); }

  /// Queues a request; `done` runs on the executor with its result.
  RequestId request(protocol::arduino::Body body, Callback done = {});
  RequestId raw(std::string_view token, Callback done = {});
  RequestId ping(Callback done = {}) { return request(protocol::arduino::Ping{}, std::move(done)); }
  RequestId status(Callback done = {}) {
    return request(protocol::arduino::StatusRequest{}, std::move(done));
  }
  RequestId set_v(int pwm, Callback done = {}) {
    return request(protocol::arduino::SetSpeed{pwm}, std::move(done));
  }
  RequestId move_cm(int cm, Callback done = {}) {
    return request(protocol::arduino::Move{cm}, std::move(done));
  }
  RequestId rotate_deg(int deg, Callback done = {}) {
    return request(protocol::arduino::Rotate{deg}, std::move(done));
  }
  RequestId stop(Callback done = {}) { return request(protocol::arduino::Stop{}, std::move(done)); }
  RequestId sonar(Callback done = {}) {
    return request(protocol::arduino::SonarRead{}, std::move(done));
  }
  RequestId ir(Callback done = {}) { return request(protocol::arduino::IrRead{}, std::move(done)); }
  RequestId help(Callback done = {}) { return request(protocol::arduino::Help{}, std::move(done)); }

  ConnectionState state() const { return core_->state(); }
  const ArduinoClientCore& core() const { return *core_; }
  CommLog& log() { return *log_; }
  std::shared_ptr<CommLog> shared_log() const { return log_; }

 private:
  link::Time now() const { return binding_.now(); }
  void drain();
  void perform(Action& action);
  void dispatch(Event& event);

  std::unique_ptr<ArduinoClientCore> core_;
  std::shared_ptr<CommLog> log_ = std::make_shared<CommLog>();
  RequestCallbacks<RequestId, Result> callbacks_;
  EventHandler on_event_;
  WallClock wall_clock_;
  bool draining_ = false;
  PipeBinding binding_;  // last: its callbacks use the members above
};

}  // namespace hil::client::arduino
