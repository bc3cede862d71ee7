#pragma once
// What moves time in a scenario run. Everything in a run (the car, the
// link, the client, the steps) goes through the driver's executor and
// transport context; only the loop that runs their tasks differs: virtual
// time jumps from task to task, real time waits on sockets and ptys.

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "harness/timeline.hpp"
#include "link/executor.hpp"
#include "link/transport.hpp"

namespace hil::harness {

class RunDriver {
 public:
  virtual ~RunDriver() = default;
  RunDriver(const RunDriver&) = delete;
  RunDriver& operator=(const RunDriver&) = delete;

  link::Executor& executor() { return context_.executor; }
  link::TransportContext& context() { return context_; }
  /// Real sockets and ptys on the steady clock (else virtual time, mem://).
  bool real_time() const { return context_.io != nullptr; }

  /// Runs tasks until `done` or until the clock reaches `deadline` (the
  /// clock then stands there). Returns an error when the run stopped
  /// making progress.
  virtual std::optional<std::string> drive(const std::function<bool()>& done, Time deadline) = 0;

 protected:
  explicit RunDriver(link::TransportContext context) : context_(std::move(context)) {}

 private:
  link::TransportContext context_;
};

/// The real-time driver when `real_time`, else the virtual-time one.
std::unique_ptr<RunDriver> make_run_driver(bool real_time);

/// A run's duration as its messages write it: "2 s", "1.500 s".
std::string run_seconds_text(Duration d);

}  // namespace hil::harness
