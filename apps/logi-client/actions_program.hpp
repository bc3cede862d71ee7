#pragma once
// What logi-client's batch and --stdin-actions modes share: the loop, the
// session and its action host, the lines printed for events, the stop
// signals (the first stops the run, a second one leaves at once) and the
// way out: an emergency stop when the car may be moving, a disconnect, and
// the communication log.

#include <functional>
#include <iosfwd>
#include <memory>
#include <string>

#include "apps/common/program.hpp"
#include "apps/logi-client/batch.hpp"
#include "client/logi/action_host.hpp"
#include "client/logi/session.hpp"

namespace hil::apps::logi_client {

/// The way out of a run: with `stop_car` and the car connected, an
/// emergency stop (MV:STOP, and ST:STOP unless the car is in MAN) and a
/// line saying so, then up to 3 s for the car's answers; then `done`.
/// Timing from the executor only.
void stop_car_then(logi::LogiSession& session, link::Executor& executor, bool stop_car,
                   const std::function<void(const std::string&)>& print,
                   std::function<void()> done);

/// One run of a mode without a screen, against tcp://host:port. A mode
/// says how the run begins and what its shutdown drops first.
class ActionsProgram {
 public:
  ActionsProgram(const BatchOptions& options, std::ostream& out, std::ostream& err);
  virtual ~ActionsProgram();
  ActionsProgram(const ActionsProgram&) = delete;
  ActionsProgram& operator=(const ActionsProgram&) = delete;

  /// Runs until the run ends; writes the log; returns the exit status.
  int run();

 protected:
  /// The mode's first work, before the loop starts.
  virtual void begin() = 0;
  /// What shut_down() drops before the car is stopped: the actions under
  /// way, each reported cancelled.
  virtual void abandon() { actions_->cancel(); }
  /// More lines for an event, after the one BatchReporter prints.
  virtual void event_lines(const logi::Event&) {}
  /// After the loop ended, before the log is written.
  virtual void after_loop() {}

  /// Ends the run, once: the exit status `code`, abandon(), an emergency
  /// stop if `stop_car` and the car may be moving, then a disconnect.
  void shut_down(int code, bool stop_car);
  bool stopping() const { return stopping_; }

  /// A line of output, flushed at once: a program on the other end of a
  /// pipe (hil) waits for it.
  void print(const std::string& line);
  logi::Time time_now() { return program_.executor().now(); }

  const BatchOptions& options_;
  ProgramLoop program_;
  std::unique_ptr<logi::LogiSession> session_;
  std::unique_ptr<logi::ActionHost> actions_;

 private:
  void on_event(logi::Time now, const logi::Event& event);
  void on_signal(int signal);

  std::ostream& out_;
  std::ostream& err_;
  BatchReporter reporter_;
  bool stopping_ = false;
};

}  // namespace hil::apps::logi_client
