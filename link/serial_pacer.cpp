#include "link/serial_pacer.hpp"

#include <utility>

namespace hil::link {

namespace {
constexpr std::uint64_t ns_per_10_s = 10'000'000'000ULL;  // 10 bits per byte, in ns per baud
}

SerialPacer::SerialPacer(Executor& executor, unsigned baud, Sink sink, Duration min_tick)
    : executor_(executor), baud_(baud), sink_(std::move(sink)), min_tick_(min_tick) {}

SerialPacer::~SerialPacer() {
  if (timer_ != 0) executor_.cancel(timer_);
}

Duration SerialPacer::byte_time(unsigned baud) {
  return Duration(static_cast<Duration::rep>(ns_per_10_s / baud));
}

Time SerialPacer::completion(std::uint64_t k) const {
  // Rounded up, so a byte is never released before its last bit is sent.
  const std::uint64_t ns = ((k + 1) * ns_per_10_s + baud_ - 1) / baud_;
  return burst_start_ + Duration(static_cast<Duration::rep>(ns));
}

void SerialPacer::push(ByteView bytes) {
  if (bytes.empty()) return;
  if (baud_ == 0) {
    sink_(bytes);
    return;
  }
  // An empty queue means the line is idle (bytes are released only once
  // their last bit is out), so a new burst starts now.
  if (queue_.empty()) {
    burst_start_ = executor_.now();
    released_ = 0;
  }
  queue_.insert(queue_.end(), bytes.begin(), bytes.end());
  if (timer_ == 0) schedule();
}

void SerialPacer::clear() {
  queue_.clear();
  on_drained_ = nullptr;
  if (timer_ != 0) executor_.cancel(timer_);
  timer_ = 0;
}

void SerialPacer::when_drained(std::function<void()> done) {
  if (queue_.empty()) {
    done();
  } else {
    on_drained_ = std::move(done);
  }
}

void SerialPacer::schedule() {
  Time at = completion(released_);
  if (last_release_ && at < *last_release_ + min_tick_) at = *last_release_ + min_tick_;
  timer_ = executor_.call_at(at, [this, alive = std::weak_ptr<int>(alive_)] {
    if (!alive.expired()) release();
  });
}

void SerialPacer::release() {
  timer_ = 0;
  const Time now = executor_.now();
  // Bytes complete by now: floor(elapsed * baud / 10 s), split so the
  // product cannot overflow however late the timer fired.
  const auto elapsed = static_cast<std::uint64_t>((now - burst_start_).count());
  const std::uint64_t complete =
      elapsed / ns_per_10_s * baud_ + elapsed % ns_per_10_s * baud_ / ns_per_10_s;
  std::uint64_t due = complete > released_ ? complete - released_ : 0;
  if (due > queue_.size()) due = queue_.size();
  Bytes chunk(queue_.begin(), queue_.begin() + static_cast<std::ptrdiff_t>(due));
  queue_.erase(queue_.begin(), queue_.begin() + static_cast<std::ptrdiff_t>(due));
  released_ += due;
  if (due > 0) last_release_ = now;
  // Every `baud` bytes are exactly 10 s of line time: rebase to keep the
  // arithmetic small on endless streams.
  while (released_ >= baud_) {
    released_ -= baud_;
    burst_start_ += Duration(static_cast<Duration::rep>(ns_per_10_s));
  }
  if (!queue_.empty()) schedule();
  std::weak_ptr<int> alive = alive_;
  if (!chunk.empty()) sink_(chunk);
  if (alive.expired()) return;
  if (queue_.empty() && on_drained_) {
    auto done = std::move(on_drained_);
    on_drained_ = nullptr;
    done();
  }
}

}  // namespace hil::link
