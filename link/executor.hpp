#pragma once
// Where boxes schedule work. The virtual-time driver and the real-time
// driver are both Executors; code that only uses this interface runs
// unchanged under either.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "link/time.hpp"

namespace hil::link {

class Executor : public Clock {
 public:
  using Task = std::function<void()>;
  using TimerId = std::uint64_t;

  /// Runs `task` at time `at` (or now, if `at` has passed). Tasks due at the
  /// same time run in the order they were scheduled.
  virtual TimerId call_at(Time at, Task task) = 0;
  /// Cancels a task that has not run yet; returns whether it was pending.
  virtual bool cancel(TimerId id) = 0;

  TimerId call_after(Duration delay, Task task) { return call_at(now() + delay, std::move(task)); }
  /// Runs `task` as soon as possible, after the task that is running now.
  TimerId post(Task task) { return call_at(now(), std::move(task)); }
};

/// One task kept due at a time that moves, such as a box's next wakeup:
/// schedule() re-arms the executor only when the time changed, and the
/// task never runs once the timer is gone.
class WakeupTimer {
 public:
  /// `executor` must outlive the timer.
  WakeupTimer(Executor& executor, Executor::Task fire);
  ~WakeupTimer();
  WakeupTimer(const WakeupTimer&) = delete;
  WakeupTimer& operator=(const WakeupTimer&) = delete;

  /// Runs the task at `due` instead of when it was due; nullopt: never.
  /// Cheap to call after every input.
  void schedule(std::optional<Time> due);

 private:
  Executor& executor_;
  Executor::Task fire_;
  Executor::TimerId id_ = 0;
  std::optional<Time> due_;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

/// The virtual-time driver's clock and event queue: time moves only when
/// the queue is run, jumping from one due task to the next. Deterministic:
/// the same tasks scheduled in the same order run in the same order.
class VirtualExecutor final : public Executor {
 public:
  Time now() const override { return now_; }
  TimerId call_at(Time at, Task task) override;
  bool cancel(TimerId id) override;

  /// Runs every task due at or before `until` (including tasks those tasks
  /// schedule), then leaves the clock at `until`. Returns the tasks run.
  std::size_t run_until(Time until);
  std::size_t run_for(Duration d) { return run_until(now_ + d); }
  /// Runs the earliest pending task, moving the clock to its time.
  bool run_one();
  /// Runs until nothing is pending or `max_tasks` have run (a guard against
  /// a box that reschedules itself forever). Returns the tasks run.
  std::size_t run_until_idle(std::size_t max_tasks = 10'000'000);

  std::optional<Time> next_due() const;
  std::size_t pending() const { return live_; }

 private:
  // A binary min-heap of (time, sequence) entries, so equal times keep
  // scheduling order, over a table of task slots reused through a free
  // list: scheduling and running a task allocate nothing of their own
  // (the Task may). A TimerId is the slot and its generation; cancelling
  // empties the slot at once and leaves the heap entry to be skipped when
  // it comes up, or dropped when such stale entries outnumber live ones.
  struct Entry {
    Time at;
    std::uint64_t seq;
    std::uint32_t slot;
    std::uint32_t generation;
  };
  struct Slot {
    Task task;
    std::uint32_t generation = 1;
    bool pending = false;
  };
  static bool later(const Entry& a, const Entry& b) {
    return a.at != b.at ? a.at > b.at : a.seq > b.seq;
  }
  bool stale(const Entry& e) const {
    const Slot& s = slots_[e.slot];
    return !s.pending || s.generation != e.generation;
  }
  void drop_stale_top() const;
  void release(std::uint32_t slot);

  mutable std::vector<Entry> heap_;
  std::vector<Slot> slots_;
  std::vector<std::uint32_t> free_;
  std::size_t live_ = 0;
  Time now_{0};
  std::uint64_t next_seq_ = 0;
};

}  // namespace hil::link
