#pragma once
// Binds the WR8 client core to a hil transport (tcp://, pty:// or mem://)
// under either driver: performs its actions, feeds it bytes and closes, and
// keeps one executor timer for its next wakeup.

#include <functional>
#include <memory>
#include <optional>

#include "client/wr8/core.hpp"
#include "link/endpoint.hpp"
#include "link/transport.hpp"

namespace hil::client::wr8 {

class Wr8Session {
 public:
  using EventSink = std::function<void(Time now, const Event& event)>;

  /// `context` must outlive the session. Events go to `sink` on the executor.
  Wr8Session(link::TransportContext& context, link::Endpoint endpoint, ClientConfig config = {},
             EventSink sink = {}, std::shared_ptr<CommLog> log = std::make_shared<CommLog>());
  ~Wr8Session();
  Wr8Session(const Wr8Session&) = delete;
  Wr8Session& operator=(const Wr8Session&) = delete;

  void connect();
  void disconnect();
  SubmitResult task(proto::TaskCode code, std::vector<proto::Word> params = {});
  SubmitResult drive(std::int32_t distance_cm);
  SubmitResult turn(std::int32_t angle_deg);
  SubmitResult get_settings();
  SubmitResult set_settings(std::vector<proto::Setting> settings);

  const Wr8ClientCore& core() const { return core_; }
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
  Wr8ClientCore core_;
  link::BytePipePtr pipe_;
  std::uint64_t generation_ = 0;  // tells a current connection's callbacks from a closed one's
  link::Executor::TimerId timer_ = 0;
  std::optional<Time> timer_due_;
  bool flushing_ = false;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace hil::client::wr8
