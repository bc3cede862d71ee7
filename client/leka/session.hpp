#pragma once
// Binds the Leka client core to hil's transports under either driver (a
// serial pty, or mem:// in virtual time): writes the core's paced frames,
// feeds it the robot's lines, keeps one timer for its wakeup, logs both ways.

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "client/common/pipe_binding.hpp"
#include "client/common/request_callbacks.hpp"
#include "client/leka/comm_log.hpp"
#include "client/leka/core.hpp"
#include "link/endpoint.hpp"
#include "link/executor.hpp"
#include "link/transport.hpp"

namespace hil::client::leka {

class LekaSession {
 public:
  using InfoCallback = RequestCallbacks<RequestId, InfoResult>::Callback;
  /// Wall-clock microseconds since the Unix epoch, for the log.
  using WallClock = std::function<std::int64_t()>;

  /// `context` must outlive the session. Nothing happens until open().
  LekaSession(link::TransportContext& context, link::Endpoint endpoint, ClientConfig config = {});
  LekaSession(const LekaSession&) = delete;
  LekaSession& operator=(const LekaSession&) = delete;

  void open();
  void close();
  bool is_open() const { return core_.connected(); }
  ConnectionState state() const { return core_.state(); }

  BuildResult send(const GroupBuilder& builder);
  RequestId info(InfoCallback done = {});

  /// Why the last open() failed (the system's message), empty if it did not.
  const std::string& open_error() const { return open_error_; }

  void set_wall_clock(WallClock clock) { wall_clock_ = std::move(clock); }
  const LekaClientCore& core() const { return core_; }
  CommLog& log() { return *log_; }

 private:
  link::Time now() const { return binding_.now(); }
  void drain();
  PipeBinding::Handlers handlers();

  LekaClientCore core_;
  std::shared_ptr<CommLog> log_ = std::make_shared<CommLog>();
  RequestCallbacks<RequestId, InfoResult> callbacks_;
  WallClock wall_clock_;
  std::string open_error_;
  bool draining_ = false;
  PipeBinding binding_;  // last: its callbacks use the members above
};

}  // namespace hil::client::leka
