#pragma once
// Part of the fault injector (fault_injector.hpp): what it has decided to
// deliver and when, in stream order, with the stalls that hold deliveries
// back and the pacing of a bandwidth-limited line.

#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "link/faults/fault_injector.hpp"
#include "link/time.hpp"
#include "protocol/common/bytes.hpp"

namespace hil::link::faults {

class DeliveryQueue {
 public:
  /// The earliest time a write wanted at `desired` can arrive: not before
  /// the last write queued (a stream keeps its order), and not in a stall.
  Time slot(Time desired) const;
  /// Puts `bytes` on the line at `t` or, if it is busy, when it is next
  /// free, at `rate` bytes per second; the time their last byte arrives,
  /// moved past any stall.
  Time pace(Time t, std::size_t bytes, std::uint64_t rate);
  /// Joins `bytes` to the last queued write when that one is joinable, from
  /// the same `push` and due at `due`: untouched frames of one sender write
  /// due at the same time go out as one write, as the sender wrote them.
  bool join(Time due, protocol::ByteView bytes, std::uint64_t push);
  /// Queues one write due at `due` (no earlier than slot() gave).
  void add(Time due, protocol::Bytes bytes, std::uint64_t push, bool joinable);
  /// Queues the link break at `at`.
  void add_break(Time at, bool reset);
  /// Removes every write due after `at` and returns their bytes, in order.
  protocol::Bytes cut_after(Time at);
  /// When the last write queued is due.
  Time last_due() const { return last_due_; }

  /// Nothing is delivered in [begin, end); what falls due then goes out at
  /// `end`. `timed` marks a stall from a rule's `at`.
  void add_stall(Time begin, Time end, bool timed);
  /// Forgets the timed stalls that begin at or after `from`.
  void forget_timed_stalls(Time from);

  /// Appends every output due at or before `now`, in order.
  void pop_due(Time now, std::vector<InjectorOutput>& out);
  /// When the next output is due; nullopt when none is queued.
  std::optional<Time> next_due() const;

 private:
  struct Pending {
    Time due{0};
    std::optional<protocol::Bytes> bytes;  // nullopt: a LinkBreak
    bool reset = false;
    std::uint64_t push = 0;  // the sender write it came from
    bool joinable = false;
  };
  struct Interval {
    Time begin{0};
    Time end{0};
    bool timed = false;
  };

  Time after_stalls(Time t) const;

  std::deque<Pending> queue_;  // due times never decrease: it is a stream
  std::vector<Interval> stalls_;
  Time last_due_{0};
  Time line_free_{0};  // when the bandwidth-limited line is next idle
};

}  // namespace hil::link::faults
