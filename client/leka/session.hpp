#pragma once
// Binds the Leka client core to hil's transports under either driver (a
// serial pty, or mem:// in virtual time): writes the core's paced frames,
// feeds it the robot's lines, keeps one timer for its wakeup, logs both ways.

#include <functional>
#include <map>
#include <memory>
#include <optional>

#include "client/leka/comm_log.hpp"
#include "client/leka/core.hpp"
#include "link/endpoint.hpp"
#include "link/executor.hpp"
#include "link/transport.hpp"

namespace hil::client::leka {

class LekaSession {
 public:
  using InfoCallback = std::function<void(const InfoResult&)>;
  /// Wall-clock microseconds since the Unix epoch, for the log.
  using WallClock = std::function<std::int64_t()>;

  /// `context` must outlive the session. Nothing happens until open().
  LekaSession(link::TransportContext& context, link::Endpoint endpoint, ClientConfig config = {});
  ~LekaSession();
  LekaSession(const LekaSession&) = delete;
  LekaSession& operator=(const LekaSession&) = delete;

  void open();
  void close();
  bool is_open() const { return core_.connected(); }

  BuildResult send(const GroupBuilder& builder);
  RequestId info(InfoCallback done = {});

  void set_wall_clock(WallClock clock) { wall_clock_ = std::move(clock); }
  const LekaClientCore& core() const { return core_; }
  CommLog& log() { return *log_; }

 private:
  link::Time now() const { return context_.executor.now(); }
  void drain();
  void reschedule();
  void drop_pipe();

  link::TransportContext& context_;
  link::Endpoint endpoint_;
  LekaClientCore core_;
  std::shared_ptr<CommLog> log_ = std::make_shared<CommLog>();
  link::BytePipePtr pipe_;
  std::uint64_t generation_ = 0;  // callbacks from an older pipe are ignored
  link::Executor::TimerId timer_ = 0;
  std::optional<link::Time> timer_due_;
  std::map<RequestId, InfoCallback> callbacks_;
  WallClock wall_clock_;
  bool draining_ = false;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace hil::client::leka
