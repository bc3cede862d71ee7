#pragma once
// Plays a scenario's steps: the main sequence (setup, then steps; the first
// failure skips the rest), the teardown (every step, failed or not), and the
// scheduled steps beside them (at a time, or when a record matches). Each
// step's start and end go to the timeline and its verdict to its
// StepOutcome; operator actions go to the client under test.

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "harness/outcome.hpp"
#include "harness/reference_client.hpp"
#include "harness/scenario.hpp"
#include "harness/timeline_recorder.hpp"
#include "link/executor.hpp"
#include "mocks/car.hpp"
#include "mocks/server.hpp"

namespace hil::harness {

/// What the steps act on; everything must outlive the sequencer.
struct StepTargets {
  link::Executor& executor;
  RunTimeline& timeline;
  mocks::MockCar& car;
  mocks::MockServer& server;
  ScenarioClient& client;
};

class StepSequencer {
 public:
  enum class Sequence : std::uint8_t { main, teardown };

  /// Lists every step of `scenario` in `steps`, not run yet: setup, steps,
  /// teardown, then the schedule. `scenario` and `steps` must outlive it.
  StepSequencer(const Scenario& scenario, std::vector<StepOutcome>& steps, StepTargets targets);
  ~StepSequencer();
  StepSequencer(const StepSequencer&) = delete;
  StepSequencer& operator=(const StepSequencer&) = delete;

  /// Arms each scheduled step whose moment is an event.
  void start_schedule();
  /// The run's origin is known (harness/origin.hpp): arms each scheduled
  /// step whose moment is a run time (`at: 5s`) from it, and from now on
  /// the run times inside faults and car steps (a rule's or a behaviour's
  /// `at`) count from it too. A fault profile in force with such times (the
  /// scenario's own, from the start) is put in force again, moved by it.
  void origin_fixed(Time origin);
  /// Starts the sequence's first step on the next executor turn.
  void start(Sequence which);
  bool done(Sequence which) const;
  /// Ends the sequence now: the steps under way fail with `reason`, the
  /// rest are not run.
  void time_out(Sequence which, const std::string& reason);
  /// No scheduled step starts from now on.
  void stop_schedule();
  /// Ends the run's steps: those still under way fail, scheduled steps
  /// whose moment never came say so; nothing starts or ends afterwards.
  void close();

 private:
  struct Order {
    std::vector<std::size_t> steps;  // indices into steps_
    std::size_t next = 0;
    bool stop_on_failure = true;
    bool done = false;
  };
  struct Running {
    std::function<void(bool ok)> then;
    link::Executor::TimerId timer = 0;
    RunTimeline::ListenerId listener = 0;
  };

  Order& order(Sequence which) { return which == Sequence::main ? main_ : teardown_; }
  std::size_t add(const Step& step, const char* phase);
  void advance(Order& seq);
  void skip_rest(Order& seq, const std::string& reason);
  void begin_step(std::size_t index, std::function<void(bool ok)> then);
  /// `cut_short`: the run ended the step (a timeout), so a step expected to
  /// fail does not pass by it.
  void finish_step(std::size_t index, bool ok, std::string reason, bool cut_short = false);
  void finish_later(std::size_t index, bool ok, std::string reason);
  void end_under_way(const std::string& reason);
  void begin_wait_until(std::size_t index, const WaitUntilStep& wait);
  void begin_obstacle(std::size_t index, const ObstacleStep& step);
  void pump_actions();
  void post(std::function<void()> f);
  /// Starts the scheduled step `index` when called, unless the schedule is over.
  std::function<void()> scheduled_start(std::size_t index);
  std::function<void()> guarded(std::function<void()> f) const;

  const Scenario& scenario_;
  std::vector<StepOutcome>& steps_;
  StepTargets targets_;

  std::vector<const Step*> plan_;  // parallel to steps_
  std::size_t schedule_base_ = 0;  // steps_ index of the first scheduled step
  Order main_;
  Order teardown_;
  std::map<std::size_t, Running> running_;
  std::deque<std::size_t> actions_;
  std::size_t actions_under_way_ = 0;
  std::multimap<std::string, std::size_t> obstacles_;  // name -> arena obstacle index
  /// How far run times in faults and car steps move: the origin, once known.
  Duration origin_shift_{0};
  /// The fault profile in force, as the scenario wrote it.
  link::FaultProfile faults_in_force_;
  bool schedule_stopped_ = false;
  bool closed_ = false;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace hil::harness
