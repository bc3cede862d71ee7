#pragma once
// Watches the simulated world of a scenario run and writes what a scenario
// can wait for or expect to the timeline: station tags read (`sim station`),
// collisions (`sim collision`), the chassis starting and stopping (`sim
// moving`, `sim at_rest`), the car's fault state (`car fault_state`), and a
// pose sample every sample period (`sim sample`). It also keeps the
// trajectories for the report's picture.

#include <functional>
#include <memory>
#include <vector>

#include "harness/timeline_recorder.hpp"
#include "link/executor.hpp"
#include "mocks/car.hpp"
#include "sim/recorder.hpp"

namespace hil::harness {

class SimObserver {
 public:
  /// `poll_client` runs on every look, after the world's records and before
  /// the sample (state that shows only by looking, such as a port opened).
  /// `executor`, `car` and `timeline` must outlive the observer.
  SimObserver(link::Executor& executor, mocks::MockCar& car, RunTimeline& timeline,
              Duration sample_period, std::function<void()> poll_client);
  ~SimObserver();
  SimObserver(const SimObserver&) = delete;
  SimObserver& operator=(const SimObserver&) = delete;

  /// Looks at the world now and then every few milliseconds until stop().
  void start();
  void stop();

  const std::vector<sim::Trajectory>& trajectories() const { return recorder_.trajectories(); }

  /// The car now: `moving` is the observer's own notion (between a `sim
  /// moving` record and the next `sim at_rest`), `driven` that the wheels
  /// are still driven above the at-rest threshold (a car pushing a wall).
  struct Motion {
    bool moving = false;
    double speed_mps = 0;
    bool driven = false;
  };
  Motion motion();

 private:
  void tick();
  void note_collisions();
  void note_station();
  void note_motion(double speed_mps, double turn_radps);
  void note_fault_state();
  void sample(double speed_mps);

  link::Executor& executor_;
  mocks::MockCar& car_;
  RunTimeline& timeline_;
  Duration sample_period_;
  std::function<void()> poll_client_;
  sim::TrajectoryRecorder recorder_;

  link::Executor::TimerId timer_ = 0;
  bool stopped_ = false;
  Time next_sample_{0};
  std::uint64_t rfid_reads_ = 0;
  bool moving_ = false;
  bool in_fault_ = false;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace hil::harness
