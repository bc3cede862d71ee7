#pragma once
// A serial line's time per byte, in the executor's time: what paces a pty
// under the real-time driver and a mem:// line under the virtual-time one.

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>

#include "link/byte_pipe.hpp"
#include "link/executor.hpp"

namespace hil::link {

/// Releases bytes at a serial line's rate: 8N1 framing, 10 bits per byte, so
/// byte k of a burst is complete at start + (k + 1) * 10 / baud seconds
/// (9600 baud: 1.0417 ms per byte). Bytes are handed to the sink in the
/// chunks that are due when a timer fires; a timer fires at most once per
/// `min_tick`, so high rates do not cost one timer per byte.
class SerialPacer {
 public:
  using Sink = std::function<void(ByteView)>;

  SerialPacer(Executor& executor, unsigned baud, Sink sink, Duration min_tick = milliseconds(1));
  ~SerialPacer();
  SerialPacer(const SerialPacer&) = delete;
  SerialPacer& operator=(const SerialPacer&) = delete;

  void push(ByteView bytes);
  /// Drops what has not been released yet.
  void clear();
  std::size_t queued() const { return queue_.size(); }
  /// Runs `done` once everything pushed so far has been released (at once
  /// if nothing is queued).
  void when_drained(std::function<void()> done);

  /// Time on the line of one byte at `baud` (8N1), rounded down to 1 ns.
  static Duration byte_time(unsigned baud);

 private:
  Time completion(std::uint64_t k) const;
  void schedule();
  void release();

  Executor& executor_;
  unsigned baud_;
  Sink sink_;
  Duration min_tick_;
  std::deque<std::uint8_t> queue_;
  Time burst_start_{0};
  std::uint64_t released_ = 0;  // bytes of this burst already released
  Executor::TimerId timer_ = 0;
  std::optional<Time> last_release_;  // none yet: the first tick may come at once
  std::function<void()> on_drained_;
  std::shared_ptr<int> alive_ = std::make_shared<int>(0);
};

}  // namespace hil::link
