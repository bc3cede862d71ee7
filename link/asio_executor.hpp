#pragma once
// The real-time driver's executor: tasks and timers on an asio::io_context,
// time from std::chrono::steady_clock since the executor was made.

#include <map>
#include <memory>
#include <optional>
#include <utility>

#include <asio/io_context.hpp>
#include <asio/steady_timer.hpp>

#include "link/executor.hpp"

namespace hil::link {

/// An Executor over an asio::io_context. Tasks run on the thread that runs
/// the io_context; call_at() and cancel() must be called from that thread
/// (or before it starts running).
///
/// Ordering: tasks run in order of due time, and tasks due at the same time
/// run in the order they were scheduled, exactly as under VirtualExecutor.
/// All tasks share one steady_timer armed for the earliest due task, so the
/// order never depends on how Asio orders timers that expire together.
class AsioExecutor final : public Executor {
 public:
  explicit AsioExecutor(asio::io_context& io);
  ~AsioExecutor() override;
  AsioExecutor(const AsioExecutor&) = delete;
  AsioExecutor& operator=(const AsioExecutor&) = delete;

  Time now() const override { return clock_.now(); }
  TimerId call_at(Time at, Task task) override;
  bool cancel(TimerId id) override;

  asio::io_context& io() { return io_; }
  /// Tasks scheduled and not yet run.
  std::size_t pending() const { return queue_.size(); }
  /// The steady_clock instant of a time on this executor's clock.
  std::chrono::steady_clock::time_point time_point(Time at) const { return clock_.start() + at; }

 private:
  void arm();
  void run_due();

  asio::io_context& io_;
  SteadyClock clock_;
  asio::steady_timer timer_;
  // Key: (due time, id); ids grow, so equal times keep scheduling order.
  std::map<std::pair<Time, TimerId>, Task> queue_;
  std::map<TimerId, Time> due_;  // for cancel
  TimerId next_id_ = 1;
  std::optional<Time> armed_for_;  // due time the timer waits for
  // Timer handlers that complete after this executor is gone must not touch
  // it; they hold a weak reference to this token.
  std::shared_ptr<int> alive_ = std::make_shared<int>(0);
};

}  // namespace hil::link
