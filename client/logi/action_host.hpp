#pragma once
// What a program that runs LOGI operator actions keeps between them: the
// runs under way (each on an OperatorRunner of its own, several at once if
// the program wants, so an emergency stop need not wait), the request a
// later `confirm` may resend, and whether the car may be moving, so a
// program knows when an emergency stop is owed at its end.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include "client/logi/core.hpp"
#include "client/logi/operator.hpp"
#include "client/logi/session.hpp"
#include "link/executor.hpp"

namespace hil::client::logi {

/// Whether the car may be moving, as far as the client can tell: after the
/// car accepted a move or a run (or left one unanswered) until a stop was
/// accepted, the link went down, or a STAT that had shown it moving shows
/// it at rest; and whenever the last STAT shows RUN 1 or a manual
/// direction. A move the car refused does not count, though the direction
/// stays held in the client.
class MotionTracker {
 public:
  /// Every session event, in order.
  void on_event(const Event& event);
  bool may_be_moving(const LogiClientCore& core) const;

 private:
  bool commanded_ = false;
  bool seen_moving_ = false;
};

/// Runs operator actions on one LogiSession. Feed it every event of the
/// session's sink through on_event(). A run is a list of steps on a runner
/// of its own; runs may overlap. A run's `done` comes on a later executor
/// turn than its last result, so the program may start the next run (or
/// tear down) from it.
class ActionHost {
 public:
  using ResultSink = OperatorRunner::ResultSink;
  /// The run's summary and every action's result, in order.
  using DoneSink =
      std::function<void(const RunSummary& summary, const std::vector<ActionResult>& results)>;

  /// `session` and `executor` (the session's) must outlive the host.
  ActionHost(LogiSession& session, link::Executor& executor);
  ~ActionHost();
  ActionHost(const ActionHost&) = delete;
  ActionHost& operator=(const ActionHost&) = delete;

  /// Starts `steps` on a runner of their own. A `confirm` among them may
  /// resend the uncertain request an earlier run saw (`options.confirmable`
  /// is filled in).
  void run(std::vector<OperatorStep> steps, OperatorRunnerOptions options, ResultSink on_result,
           DoneSink on_done);
  /// Every event of the session, in order.
  void on_event(Time now, const Event& event);
  /// Ends every run under way: the action of each fails as "cancelled"
  /// (through its ResultSink); their DoneSinks are not called.
  void cancel();

  /// Runs started whose `done` has not come yet (and were not cancelled).
  std::size_t runs() const { return running_.size() + ending_; }
  /// See MotionTracker.
  bool may_be_moving() const { return motion_.may_be_moving(session_.core()); }

 private:
  void ended(std::uint64_t id, const RunSummary& summary, DoneSink on_done);

  LogiSession& session_;
  link::Executor& executor_;
  std::map<std::uint64_t, std::unique_ptr<OperatorRunner>> running_;
  /// Runners that ended, kept until their callbacks have left the stack.
  std::vector<std::unique_ptr<OperatorRunner>> retired_;
  std::size_t ending_ = 0;  // runs ended whose `done` is still to come
  std::uint64_t next_id_ = 0;
  std::optional<RequestId> confirmable_;
  MotionTracker motion_;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace hil::client::logi
