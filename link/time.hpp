#pragma once
// Time in hil: a duration since the start of a run. Virtual time and real
// time use the same type, so every box is written once for both drivers.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

namespace hil::link {

using Duration = std::chrono::nanoseconds;
/// Time since the run started (nanoseconds, exact in virtual time).
using Time = std::chrono::nanoseconds;

using std::chrono::microseconds;
using std::chrono::milliseconds;
using std::chrono::seconds;

/// Milliseconds as a double, for reports and logs.
inline double to_ms(Duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
}

/// "12.345 ms"-style text with three decimals.
std::string format_ms(Duration d);

/// The earliest of the times it is shown, for a box's next wakeup: none
/// until it is shown one.
class Earliest {
 public:
  void consider(Time t) {
    if (!time_ || t < *time_) time_ = t;
  }
  void consider(const std::optional<Time>& t) {
    if (t) consider(*t);
  }
  const std::optional<Time>& time() const { return time_; }

 private:
  std::optional<Time> time_;
};

/// Something that knows what time it is.
class Clock {
 public:
  virtual ~Clock() = default;
  virtual Time now() const = 0;
};

/// Real time: std::chrono::steady_clock since the clock was made.
class SteadyClock final : public Clock {
 public:
  SteadyClock() : start_(std::chrono::steady_clock::now()) {}
  Time now() const override {
    return std::chrono::duration_cast<Duration>(std::chrono::steady_clock::now() - start_);
  }
  std::chrono::steady_clock::time_point start() const { return start_; }

 private:
  std::chrono::steady_clock::time_point start_;
};

/// Wall-clock time for logs: microseconds since the Unix epoch.
std::int64_t wall_time_us();

}  // namespace hil::link
