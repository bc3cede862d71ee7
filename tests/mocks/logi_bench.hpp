#pragma once
// The bench the LOGI firmware tests share: the car on mem:// with a client
// connected that decodes its feedback and STAT frames, the small arenas the
// motion tests drive in, and checks of the answers to a run of commands.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "mocks/logi.hpp"
#include "protocol/logi/codec.hpp"
#include "sim/presets.hpp"
#include "tests/mocks/mock_test_support.hpp"

namespace hil::mocks::test {

namespace logi = protocol::logi;

/// 4 m x 3 m with walls and nothing else; the car starts in the middle facing +x.
inline sim::Arena open_floor() {
  sim::Arena a;
  a.name = "open";
  a.start = {2.0, 1.5, 0.0};
  return a;
}

/// 6 m x 1 m: a straight tape along y = 0.5, a parcel on it at x = 2.0
/// (front face at 1.95), station 001 at x = 3.0 beyond it.
inline sim::Arena corridor() {
  sim::Arena a;
  a.name = "corridor";
  a.width_m = 6.0;
  a.height_m = 1.0;
  a.tapes.push_back(sim::Tape{"line", {{0.2, 0.5}, {5.8, 0.5}}});
  a.obstacles.push_back(sim::BoxObstacle{"parcel", {2.0, 0.5}, 0.1, 0.3, 0});
  a.tags.push_back(sim::RfidTag{"001", {3.0, 0.5}});
  a.start = {0.5, 0.5, 0.0};
  return a;
}

/// A tape that ends at x = 1.5, with station 001 out of reach beyond it.
inline sim::Arena short_tape() {
  sim::Arena a;
  a.name = "short";
  a.tapes.push_back(sim::Tape{"line", {{0.3, 1.5}, {1.5, 1.5}}});
  a.tags.push_back(sim::RfidTag{"001", {3.5, 1.5}});
  a.start = {0.5, 1.5, 0.0};
  return a;
}

/// A connected client in front of the firmware on mem://, decoding what the car sends.
class LogiBench {
 public:
  explicit LogiBench(LogiConfig config = {}, sim::Arena arena = sim::default_warehouse_arena(),
                     sim::VehicleDef vehicle = sim::logi_car())
      : car_(
            std::move(vehicle),
            [config](sim::World& w, sim::Vehicle& v) {
              return std::make_unique<LogiFirmware>(w, v, config);
            },
            {}, sim::WorldDef{std::move(arena)}) {
    client_ = car_.connect();
  }

  /// Sends one well-formed frame now and lets the car handle it at this instant.
  void send(std::string_view payload) { send_raw(logi::frame_text(payload)); }
  void send_raw(std::string_view bytes) {
    client_->write(bytes);
    car_.run_for(link::Duration::zero());
  }
  /// Sends a command and returns the car's answers (payload text, one per
  /// frame, space-separated; empty when there was none).
  std::string ask(std::string_view payload) {
    send(payload);
    return answers();
  }
  std::string ask_raw(std::string_view bytes) {
    send_raw(bytes);
    return answers();
  }
  /// Feedback received since the last look, as payload text.
  std::string answers() {
    take();
    std::string out;
    for (const auto& f : feedback_) {
      if (!out.empty()) out += ' ';
      out += logi::payload_of(f);
    }
    feedback_.clear();
    return out;
  }
  /// STAT frames received since the last look, with their arrival times.
  std::vector<std::pair<link::Time, logi::Status>> stats() {
    take();
    return std::exchange(stats_, {});
  }
  /// Runs the clock to `t`, collecting frames with the time they arrived.
  void run_until(link::Time t) {
    while (car_.now() < t) {
      const auto next = car_.executor().next_due();
      car_.run_until(next && *next <= t ? *next : t);
      take();
    }
  }
  void run_for(link::Duration d) { run_until(car_.now() + d); }
  /// Runs in 10 ms slices until `done()` holds or `limit` passes; returns whether it held.
  bool run_until(const std::function<bool()>& done, link::Duration limit) {
    const link::Time end = car_.now() + limit;
    while (!done()) {
      if (car_.now() >= end) return false;
      run_for(link::milliseconds(10));
    }
    return true;
  }

  /// Runs until the car is not running (as run_until(done, limit)).
  bool run_until_stopped(link::Duration limit) {
    return run_until([this] { return !state().running; }, limit);
  }
  /// Sets the target station and starts the run, whatever the answers.
  void start_run(std::string_view station) {
    ask("GS:" + std::string(station));
    ask("ST:RUN");
  }

  link::Time now() const { return car_.now(); }
  LogiFirmware& fw() { return car_.firmware(); }
  const LogiState& state() { return car_.firmware().state(); }
  sim::Vehicle& vehicle() { return car_.vehicle(); }
  sim::Pose pose() { return car_.vehicle().pose(); }
  ClientEnd& client() { return *client_; }
  VirtualCar<LogiFirmware>& car() { return car_; }
  std::uint64_t decode_errors() const { return decode_errors_; }

 private:
  void take() {
    const auto bytes = client_->take();
    items_.clear();
    decoder_.feed(bytes, items_);
    for (auto& item : items_) {
      if (auto* f = std::get_if<protocol::Frame<logi::Message>>(&item)) {
        if (auto* fb = std::get_if<logi::Feedback>(&f->message)) feedback_.push_back(*fb);
        if (auto* st = std::get_if<logi::Status>(&f->message)) stats_.emplace_back(now(), *st);
      } else {
        ++decode_errors_;
      }
    }
  }

  VirtualCar<LogiFirmware> car_;
  std::shared_ptr<ClientEnd> client_;
  logi::Decoder decoder_;
  std::vector<logi::Item> items_;
  std::vector<logi::Feedback> feedback_;
  std::vector<std::pair<link::Time, logi::Status>> stats_;
  std::uint64_t decode_errors_ = 0;
};

/// The bench on the open floor with the car switched to manual mode.
class ManualLogiBench : public LogiBench {
 public:
  explicit ManualLogiBench(LogiConfig config = {}) : LogiBench(std::move(config), open_floor()) {
    ask("MD:MAN");
  }
};

/// Sends each command in turn and expects its answer.
inline void expect_answers(
    LogiBench& b, std::initializer_list<std::pair<std::string_view, std::string_view>> asked) {
  for (const auto& [command, answer] : asked)
    EXPECT_EQ(b.ask(command), answer) << command;
}

inline double speed_of(const sim::Twist& t) {
  return std::hypot(t.vx_mps, t.vy_mps);
}

}  // namespace hil::mocks::test
