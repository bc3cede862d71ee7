#include "harness/run_driver.hpp"

#include <chrono>
#include <thread>

#include <asio/io_context.hpp>

#include "base/duration.hpp"
#include "link/asio_executor.hpp"

namespace hil::harness {
namespace {

// A guard against a run that makes no progress in time.
constexpr std::uint64_t kMaxTasks = 50'000'000;
// Under the real-time driver, the longest the loop waits for the next
// handler before looking at `done` again.
constexpr auto kRealTimeSlice = std::chrono::milliseconds(20);

// The executors are bases of their drivers, built before RunDriver's
// transport context that refers to them and destroyed after it.
struct VirtualClock {
  link::VirtualExecutor virtual_executor;
};

struct RealTimeClock {
  asio::io_context io;
  link::AsioExecutor asio_executor{io};
};

// The virtual-time driver: runs the executor task by task; time jumps to
// the next task.
class VirtualDriver final : private VirtualClock, public RunDriver {
 public:
  VirtualDriver() : RunDriver(link::TransportContext{virtual_executor}) {}

  std::optional<std::string> drive(const std::function<bool()>& done, Time deadline) override {
    while (!done()) {
      const auto next = virtual_executor.next_due();
      if (!next || *next > deadline) {
        virtual_executor.run_until(deadline);
        return std::nullopt;
      }
      virtual_executor.run_one();
      // Something that reschedules itself at the same instant forever would
      // hang the run; no scenario needs this many tasks.
      if (++tasks_run_ > kMaxTasks)
        return "the run stopped making progress at " + link::format_ms(virtual_executor.now()) +
               " (more than " + std::to_string(kMaxTasks) + " tasks)";
    }
    return std::nullopt;
  }

 private:
  std::uint64_t tasks_run_ = 0;
};

// The real-time driver: an io_context with real sockets and ptys; the
// clock is the steady clock.
class RealTimeDriver final : private RealTimeClock, public RunDriver {
 public:
  RealTimeDriver() : RunDriver(link::TransportContext{asio_executor, &io}) {}

  std::optional<std::string> drive(const std::function<bool()>& done, Time deadline) override {
    while (!done()) {
      const Time now = asio_executor.now();
      if (now >= deadline) return std::nullopt;
      const auto slice = std::min<Duration>(deadline - now, kRealTimeSlice);
      if (io.run_one_for(slice) == 0) {
        // Nothing to wait on at all: the io_context stopped; let the time pass.
        if (io.stopped()) io.restart();
        if (asio_executor.pending() == 0) std::this_thread::sleep_for(slice);
      }
    }
    return std::nullopt;
  }
};

}  // namespace

std::unique_ptr<RunDriver> make_run_driver(bool real_time) {
  if (real_time) return std::make_unique<RealTimeDriver>();
  return std::make_unique<VirtualDriver>();
}

std::string run_seconds_text(Duration d) {
  return hil::seconds_text(d, d % std::chrono::seconds(1) == Duration(0) ? 0 : 3);
}

}  // namespace hil::harness
