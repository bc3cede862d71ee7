#include "harness/sim_observer.hpp"

#include <chrono>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>

#include "sim/geometry.hpp"

namespace hil::harness {
namespace {

// How often the simulation is looked at for stations, collisions and
// rest; samples go out at the sample period on top of it.
constexpr Duration kSimTick = std::chrono::milliseconds(10);
// The chassis counts as moving at 5 mm/s or 0.02 rad/s (about 1 degree/s)
// and as at rest again below half of each, so the noise of a car standing
// on its wheels does not flood the timeline with transitions.
constexpr double kMovingMps = 0.005;
constexpr double kMovingRadps = 0.02;

}  // namespace

SimObserver::SimObserver(link::Executor& executor, mocks::MockCar& car, RunTimeline& timeline,
                         Duration sample_period, std::function<void()> poll_client)
    : executor_(executor),
      car_(car),
      timeline_(timeline),
      sample_period_(sample_period),
      poll_client_(std::move(poll_client)),
      recorder_(sample_period) {}

SimObserver::~SimObserver() {
  *alive_ = false;
}

void SimObserver::start() {
  tick();
}

void SimObserver::stop() {
  stopped_ = true;
  if (timer_ != 0) executor_.cancel(timer_);
  timer_ = 0;
}

void SimObserver::tick() {
  timer_ = 0;
  if (stopped_) return;
  const Time now = executor_.now();
  car_.world().advance_to(now);
  note_collisions();
  note_station();
  const sim::Twist v = car_.vehicle().velocity();
  const double speed = std::hypot(v.vx_mps, v.vy_mps);
  note_motion(speed, std::abs(v.wz_radps));
  note_fault_state();
  poll_client_();
  if (now >= next_sample_) {
    sample(speed);
    while (next_sample_ <= now)
      next_sample_ += sample_period_;
  }
  const Time next = std::min(now + kSimTick, next_sample_);
  timer_ = executor_.call_at(next, [alive = std::weak_ptr<bool>(alive_), this] {
    if (const auto a = alive.lock(); a && *a) tick();
  });
}

SimObserver::Motion SimObserver::motion() {
  car_.world().advance_to(executor_.now());
  const sim::Twist v = car_.vehicle().velocity();
  const sim::Twist wheels = car_.vehicle().chassis().wheel_twist();
  const bool driven = std::hypot(wheels.vx_mps, wheels.vy_mps) >= kMovingMps / 2 ||
                      std::abs(wheels.wz_radps) >= kMovingRadps / 2;
  return Motion{moving_, std::hypot(v.vx_mps, v.vy_mps), driven};
}

void SimObserver::note_collisions() {
  const std::size_t vehicle = car_.vehicle().index();
  for (const auto& c : recorder_.observe(car_.world())) {
    if (c.vehicle != vehicle || c.phase != sim::ContactEvent::Phase::begin) continue;
    static constexpr const char* kWith[] = {"wall", "obstacle", "vehicle"};
    const std::string with =
        c.other_name.empty() ? std::string(kWith[static_cast<int>(c.with)]) : c.other_name;
    timeline_.add(SimKind::collision, {{"with", with}});
  }
}

void SimObserver::note_station() {
  const sim::Vehicle& vehicle = car_.vehicle();
  if (vehicle.rfid_reads() == rfid_reads_) return;
  rfid_reads_ = vehicle.rfid_reads();
  const auto tag = vehicle.rfid();
  if (!tag) return;
  nlohmann::json data{{"tag", *tag}};
  // "002" is station 2, so `station: 2` matches; other tags by name.
  if (!tag->empty() && tag->find_first_not_of("0123456789") == std::string::npos)
    data["station"] = std::stoi(*tag);
  else
    data["station"] = *tag;
  timeline_.add(SimKind::station, std::move(data));
}

void SimObserver::note_motion(double speed_mps, double turn_radps) {
  if (!moving_ && (speed_mps >= kMovingMps || turn_radps >= kMovingRadps)) {
    moving_ = true;
    timeline_.add(SimKind::moving);
  } else if (moving_ && speed_mps < kMovingMps / 2 && turn_radps < kMovingRadps / 2) {
    moving_ = false;
    timeline_.add(SimKind::at_rest);
  }
}

void SimObserver::note_fault_state() {
  if (car_.firmware().in_fault() == in_fault_) return;
  in_fault_ = car_.firmware().in_fault();
  timeline_.add(CarEventKind::fault_state, {{"on", in_fault_}});
}

void SimObserver::sample(double speed_mps) {
  const sim::Pose pose = car_.vehicle().pose();
  timeline_.add(SimKind::sample,
                {{"x_m", sim::round_to(pose.x_m, 1e-4)},
                 {"y_m", sim::round_to(pose.y_m, 1e-4)},
                 {"heading_deg", sim::round_to(pose.heading_rad * 180 / std::numbers::pi, 0.01)},
                 {"speed_mps", sim::round_to(speed_mps, 1e-4)}});
}

}  // namespace hil::harness
