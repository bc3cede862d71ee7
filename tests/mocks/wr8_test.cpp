// The WR8 mock firmware under the virtual-time driver: authentication, the
// DATA stream, every task and its answers, settings and the PID drive, the
// servo zero, faults, scripted behaviours and malformed input, with exact
// times.

#include "mocks/wr8.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include "link/protocol_adapter.hpp"
#include "protocol/wr8/codec.hpp"
#include "sim/presets.hpp"
#include "tests/mocks/mock_test_support.hpp"

namespace hil::mocks {
namespace {

namespace wr8 = protocol::wr8;
using link::milliseconds;
using link::seconds;
using protocol::Bytes;

using Car = test::VirtualCar<Wr8Firmware>;
using test::at_ms;
using test::ms_of;

/// One packet the client received, and when.
struct Packet {
  Time at{};
  wr8::Message message;
};

/// A WR8 car on mem:// and a GUI connected to it (at 1 ms) that decodes
/// everything the car sends, with the virtual time it arrived.
class Gui {
 public:
  explicit Gui(Wr8Config config = {}, ServerOptions options = {})
      : config_(config),
        car_(
            sim::wr8_vehicle(),
            [config](sim::World& w, sim::Vehicle& v) {
              return std::make_unique<Wr8Firmware>(w, v, config);
            },
            std::move(options)),
        decoder_(vehicle_side(config)) {
    client_ = car_.connect();
  }

  static wr8::DecoderOptions vehicle_side(const Wr8Config& config) {
    wr8::DecoderOptions options;
    options.profile = config.profile;
    options.sender = wr8::Sender::vehicle;
    return options;
  }

  /// Writes a packet now; what the car answers at once is collected.
  void send(const wr8::Message& m) { send_bytes(wr8::encode(m, config_.profile)); }
  /// Sends what encode() would refuse (wrong parameter counts).
  void send_unchecked(const wr8::Message& m) {
    send_bytes(wr8::encode_unchecked(m, config_.profile));
  }
  void send_bytes(const Bytes& bytes) {
    client_->write(protocol::ByteView(bytes));
    run_until(car_.now());
  }
  void task(std::uint8_t coi, wr8::TaskCode code, std::vector<wr8::Word> params = {}) {
    send(wr8::Task{coi, code, std::move(params)});
  }
  void drive(std::uint8_t coi, std::int32_t cm) {
    task(coi, wr8::TaskCode::drive, {wr8::Word::from_i32(cm)});
  }
  void turn(std::uint8_t coi, std::int32_t deg) {
    task(coi, wr8::TaskCode::turn, {wr8::Word::from_i32(deg)});
  }
  void settings(std::uint8_t coi, std::vector<wr8::Setting> entries) {
    send(wr8::Settings{coi, std::move(entries)});
  }
  void authenticate() {
    send(wr8::Auth{config_.profile.auth_text});
    ASSERT_FALSE(log_.empty());
    ASSERT_TRUE(std::holds_alternative<wr8::AuthReply>(log_.back().message));
  }

  /// Authenticates and forgets the bytes received so far, for a test that
  /// reads the raw bytes (client(), take_hex()).
  void authenticate_raw() {
    authenticate();
    client().take();
  }
  /// The bytes received since the last look, in hex.
  std::string take_hex() { return protocol::to_hex(client().take()); }

  /// Authenticates, runs to `t` and forgets what arrived so far.
  void settle(Time t) {
    authenticate();
    run_until(t);
    take();
  }

  /// Runs every event up to `t`, recording each packet at its exact time.
  void run_until(Time t) {
    car_.run_until_each(t, [this] { collect(); });
  }
  void run_for(Duration d) { run_until(car_.now() + d); }

  /// Packets received so far (and forgets them).
  std::vector<Packet> take() { return std::exchange(log_, {}); }

  Time now() const { return car_.now(); }
  Car& car() { return car_; }
  Wr8Firmware& fw() { return car_.firmware(); }
  const Wr8State& state() { return car_.firmware().state(); }
  sim::Vehicle& vehicle() { return car_.vehicle(); }
  sim::AckermannChassis& chassis() { return *car_.vehicle().ackermann(); }
  test::ClientEnd& client() { return *client_; }
  const Wr8Config& config() const { return config_; }

 private:
  void collect() {
    const Bytes bytes = client_->take();
    test::decode_frames<wr8::Message>(
        decoder_, bytes, "the car sent bytes a GUI cannot decode: ", [this](const auto& frame) {
          log_.push_back(Packet{car_.now(), frame.message});
        });
  }

  Wr8Config config_;
  Car car_;
  std::shared_ptr<test::ClientEnd> client_;
  wr8::Decoder decoder_;
  std::vector<Packet> log_;
};

template <class T>
std::vector<std::pair<Time, T>> select(const std::vector<Packet>& packets) {
  std::vector<std::pair<Time, T>> out;
  for (const Packet& p : packets) {
    if (const auto* m = std::get_if<T>(&p.message)) out.emplace_back(p.at, *m);
  }
  return out;
}

/// The answers to requests, in order, as (time ms, COI, code).
struct Answer {
  std::int64_t at_ms;
  std::uint8_t coi;
  wr8::ResponseCode code;
  friend bool operator==(const Answer&, const Answer&) = default;
};

std::ostream& operator<<(std::ostream& os, const Answer& a) {
  return os << "{" << a.at_ms << " ms, coi " << int{a.coi} << ", " << wr8::to_string(a.code) << "}";
}

std::vector<Answer> answers(const std::vector<Packet>& packets) {
  std::vector<Answer> out;
  for (const auto& [t, r] : select<wr8::Response>(packets))
    out.push_back(Answer{ms_of(t), r.coi, r.code});
  return out;
}

constexpr auto kError = wr8::ResponseCode::error;
constexpr auto kStarted = wr8::ResponseCode::started;
constexpr auto kCompleted = wr8::ResponseCode::completed;

/// A DATA value in the default profile's presentation.
double value(const wr8::Data& data, std::uint8_t code) {
  for (const auto& v : data.values) {
    if (v.code != code) continue;
    switch (code) {
      case wr8::data_code::odometry:
        return v.value.as_i32();
      case wr8::data_code::speed:
      case wr8::data_code::wheel_angle:
        return static_cast<double>(v.value.as_f32());
      default:
        return v.value.bits;
    }
  }
  ADD_FAILURE() << "DATA without parameter " << int{code};
  return 0;
}

wr8::Setting setting(wr8::SettingCode code, float v) {
  return {code, wr8::Word::from_f32(v)};
}
wr8::Setting servo_zero(std::int32_t deg) {
  return {wr8::SettingCode::servo_zero, wr8::Word::from_i32(deg)};
}

// ---------------------------------------------------------------- setup

TEST(Wr8Firmware, NeedsAnAckermannVehicleAndAWorkableConfig) {
  sim::World world({});
  sim::Vehicle& logi = world.add_vehicle(sim::logi_car());
  EXPECT_THROW({ Wr8Firmware f(world, logi); }, std::invalid_argument);
  sim::Vehicle& wr8_car = world.add_vehicle(sim::wr8_vehicle());
  Wr8Firmware fw(world, wr8_car);
  EXPECT_EQ(fw.protocol(), "wr8");
  Wr8Config bad;
  bad.data_period = Duration::zero();
  EXPECT_THROW({ Wr8Firmware f(world, wr8_car, bad); }, std::invalid_argument);
  bad = {};
  bad.p = -1;
  EXPECT_THROW({ Wr8Firmware f(world, wr8_car, bad); }, std::invalid_argument);
  bad = {};
  bad.max_packet_bytes = 8;  // below the decoder's floor
  EXPECT_THROW({ Wr8Firmware f(world, wr8_car, bad); }, std::invalid_argument);
}

// ---------------------------------------------------------------- authentication

TEST(Wr8Auth, TheRightStringIsAnsweredWithDeviceCodeIdAndState) {
  Gui gui;
  EXPECT_EQ(gui.state().session, Wr8Session::unauthenticated);
  gui.send(wr8::Auth{gui.config().profile.auth_text});
  const auto got = gui.take();
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].at, at_ms(1));
  EXPECT_EQ(std::get<wr8::AuthReply>(got[0].message), (wr8::AuthReply{8, 1, wr8::State::stop}));
  EXPECT_EQ(gui.state().session, Wr8Session::authenticated);
  // On the wire, exactly: code 2, device 8, id 1, STOP.
  Gui raw;
  raw.client().take();
  raw.client().write(wr8::encode(wr8::Auth{raw.config().profile.auth_text}));
  raw.car().run_for(milliseconds(0));
  EXPECT_EQ(raw.client().take(), (Bytes{0x02, 0x08, 0x01, 0x02}));
}

TEST(Wr8Auth, DeviceCodeIdAndStringAreConfigurable) {
  Wr8Config config;
  config.device_code = 0x42;
  config.device_id = 7;
  config.profile.auth_text = {'S', 'E', 'C', 'R', 'E', 'T', '-', '0', '0', '9'};
  Gui gui(config);
  gui.send(wr8::Auth{wr8::default_profile().auth_text});  // the default string is wrong here
  EXPECT_TRUE(gui.take().empty());
  EXPECT_EQ(gui.state().session, Wr8Session::refused);

  Gui other(config);
  other.authenticate();
  EXPECT_EQ(std::get<wr8::AuthReply>(other.take().at(0).message),
            (wr8::AuthReply{0x42, 7, wr8::State::stop}));
}

TEST(Wr8Auth, AWrongStringGetsNoAnswerAndTheConnectionClosesExactlyOneSecondLater) {
  Gui gui;
  auto text = gui.config().profile.auth_text;
  text[9] = '2';
  gui.send(wr8::Auth{text});  // at 1 ms
  EXPECT_EQ(gui.state().session, Wr8Session::refused);
  EXPECT_EQ(gui.state().close_at, at_ms(1001));
  // Nothing is answered during the delay, not even the right string or a task.
  gui.run_until(at_ms(500));
  gui.send(wr8::Auth{gui.config().profile.auth_text});
  gui.task(1, wr8::TaskCode::check);
  gui.run_until(at_ms(1000));
  EXPECT_FALSE(gui.client().closed.has_value());
  EXPECT_TRUE(gui.fw().connected());
  gui.run_until(at_ms(1001));
  ASSERT_TRUE(gui.client().closed.has_value());
  EXPECT_EQ(*gui.client().closed, link::end_of_stream());
  EXPECT_FALSE(gui.fw().connected());
  EXPECT_TRUE(gui.take().empty());  // no AUTH-REPLY, no RESPONSE, no DATA
  EXPECT_EQ(gui.state().auth_failures, 1u);
  EXPECT_EQ(gui.state().dropped_unauthenticated, 2u);
}

TEST(Wr8Auth, TheCloseDelayIsConfigurable) {
  Wr8Config config;
  config.wrong_auth_close_delay = milliseconds(250);
  Gui gui(config);
  gui.send(wr8::Auth{});  // ten zero bytes
  gui.run_until(at_ms(250));
  EXPECT_FALSE(gui.client().closed.has_value());
  gui.run_until(at_ms(251));
  EXPECT_TRUE(gui.client().closed.has_value());
}

TEST(Wr8Auth, PacketsBeforeAuthenticationAreDroppedCountedAndUnanswered) {
  Gui gui;
  gui.task(1, wr8::TaskCode::check);
  gui.drive(2, 50);
  gui.settings(3, {setting(wr8::SettingCode::p, 9)});
  gui.send(wr8::Empty{});
  gui.run_until(at_ms(1000));
  EXPECT_TRUE(gui.take().empty());  // no answer and no DATA before AUTH
  EXPECT_EQ(gui.state().dropped_unauthenticated, 4u);
  EXPECT_EQ(gui.fw().stats().frames_in, 4u);
  EXPECT_EQ(gui.state().p, 1.5);    // the SETTINGS had no effect
  EXPECT_FALSE(gui.state().drive);  // nor the drive
  EXPECT_EQ(gui.vehicle().odometry().distance_m, 0.0);
  // After AUTH the same requests are served.
  gui.authenticate();
  gui.task(4, wr8::TaskCode::check);
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1000, 4, kCompleted}}));
}

TEST(Wr8Auth, ASecondRightAuthIsAnsweredAgainWithTheCurrentStateAndChangesNothing) {
  Gui gui;
  gui.authenticate();  // at 1 ms
  gui.run_until(at_ms(1000));
  gui.drive(1, 50);
  gui.run_until(at_ms(1050));
  gui.take();
  gui.send(wr8::Auth{gui.config().profile.auth_text});
  auto got = gui.take();
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(std::get<wr8::AuthReply>(got[0].message).state, wr8::State::run);
  EXPECT_TRUE(gui.state().drive.has_value());  // the drive goes on
  gui.run_until(at_ms(1300));
  // The DATA grid is the same as before: 1100, 1200, 1300.
  const auto data = select<wr8::Data>(gui.take());
  ASSERT_EQ(data.size(), 3u);
  EXPECT_EQ(data[0].first, at_ms(1100));
  EXPECT_EQ(data[2].first, at_ms(1300));
}

TEST(Wr8Auth, AWrongSecondAuthEndsTheSessionSilentlyAndClosesAfterTheDelay) {
  Gui gui;
  gui.authenticate();
  gui.run_until(at_ms(1000));
  gui.drive(1, 100);
  gui.take();
  gui.send(wr8::Auth{});  // at 1000 ms
  gui.run_until(at_ms(1999));
  EXPECT_TRUE(gui.take().empty());  // no DATA, no answer for the drive
  EXPECT_FALSE(gui.client().closed.has_value());
  gui.run_until(at_ms(2000));
  EXPECT_TRUE(gui.client().closed.has_value());
  EXPECT_FALSE(gui.state().drive.has_value());  // the hang-up stopped it
}

// ---------------------------------------------------------------- DATA

TEST(Wr8Data, StreamsAtTenHertzOnAnExactGridAfterAuthentication) {
  Gui gui;
  gui.run_until(at_ms(250));
  EXPECT_TRUE(gui.take().empty());
  gui.authenticate();  // at 250 ms
  gui.take();
  gui.run_until(at_ms(1250));
  const auto data = select<wr8::Data>(gui.take());
  ASSERT_EQ(data.size(), 10u);
  for (std::size_t n = 0; n < data.size(); ++n) {
    const std::int64_t t = 300 + 100 * static_cast<std::int64_t>(n);
    EXPECT_EQ(data[n].first, at_ms(t));
    EXPECT_EQ(data[n].second.timestamp_ms, static_cast<std::uint32_t>(t));  // ms since start
  }
  EXPECT_EQ(gui.state().data_sent, 10u);
}

TEST(Wr8Data, ThePeriodIsConfigurable) {
  Wr8Config config;
  config.data_period = milliseconds(40);  // 25 Hz
  Gui gui(config);
  gui.authenticate();
  gui.run_until(at_ms(1000));
  const auto data = select<wr8::Data>(gui.take());
  ASSERT_EQ(data.size(), 25u);
  EXPECT_EQ(data.front().first, at_ms(40));
  EXPECT_EQ(data.back().first, at_ms(1000));
}

TEST(Wr8Data, AtRestCarriesStopAndTheFourReadingsInTheProfileUnits) {
  Gui gui;
  gui.authenticate_raw();
  gui.car().run_until(at_ms(100));
  // STOP, 100 ms, 17 block bytes: odometry 0 cm, speed 0.0f, angle 0.0f, battery 100 %.
  EXPECT_EQ(gui.take_hex(),
            "06 02 64 00 00 00 11 00 00 00 00 00 01 00 00 00 00 02 00 00 00 00 03 64");
}

TEST(Wr8Data, MutedTelemetryLeavesGapsAndResumesOnTheGrid) {
  Gui gui;
  gui.authenticate();
  gui.fw().arm(Behaviour{"mute", When{at_ms(150), "", 1}, MuteTelemetry{milliseconds(300)}});
  gui.run_until(at_ms(700));
  std::vector<std::int64_t> times;
  for (const auto& [t, d] : select<wr8::Data>(gui.take()))
    times.push_back(ms_of(t));
  EXPECT_EQ(times, (std::vector<std::int64_t>{100, 500, 600, 700}));
}

TEST(Wr8Data, FollowsADriveInRunStateAndItsNumbersAgreeWithEachOther) {
  Gui gui;
  gui.settle(at_ms(1000));
  gui.drive(1, 100);
  gui.run_until(at_ms(6000));
  const auto got = gui.take();
  const auto data = select<wr8::Data>(got);
  const auto done = answers(got).back();
  ASSERT_EQ(done.code, kCompleted);
  double previous_odo = 0;
  double previous_speed = 0;
  double max_speed = 0;
  for (const auto& [t, d] : data) {
    const double odo = value(d, wr8::data_code::odometry);
    const double speed = value(d, wr8::data_code::speed);
    max_speed = std::max(max_speed, speed);
    EXPECT_GE(odo, previous_odo);
    // Odometry follows the reported speeds: the mean speed over 100 ms.
    EXPECT_NEAR(odo - previous_odo, (speed + previous_speed) / 2 * 10, 1.5) << ms_of(t);
    EXPECT_EQ(d.state, ms_of(t) < done.at_ms ? wr8::State::run : wr8::State::stop) << ms_of(t);
    EXPECT_EQ(value(d, wr8::data_code::wheel_angle), 0.0);
    previous_odo = odo;
    previous_speed = speed;
  }
  EXPECT_FLOAT_EQ(static_cast<float>(max_speed), 0.5f);  // cruising at the drive's top speed
  EXPECT_EQ(previous_odo, 100);
  EXPECT_EQ(previous_speed, 0.0);
}

// ---------------------------------------------------------------- tasks

TEST(Wr8Task, CheckCompletesAtOnce) {
  Gui gui;
  gui.settle(at_ms(1000));
  gui.task(7, wr8::TaskCode::check);
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1000, 7, kCompleted}}));
  gui.send_unchecked(wr8::Task{8, wr8::TaskCode::check, {wr8::Word::from_i32(1)}});
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1000, 8, kError}}));
}

TEST(Wr8Task, DriveCompletesOnTheFirstControlTickAfterTheWheelsCovered100Cm) {
  Gui gui;
  gui.settle(at_ms(1000));
  const sim::Pose start = gui.vehicle().pose();
  gui.drive(1, 100);
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1000, 1, kStarted}}));
  EXPECT_EQ(gui.fw().state_code(), wr8::State::run);
  // Watch every control tick: no answer while the wheels have covered less
  // than 100 cm, completed on the tick they reach it.
  std::optional<std::int64_t> completed_ms;
  for (std::int64_t t = 1010; t <= 8000 && !completed_ms; t += 10) {
    gui.run_until(at_ms(t));
    const double covered_m = gui.vehicle().odometry().distance_m;
    const auto got = answers(gui.take());
    if (covered_m < 1.0) {
      EXPECT_TRUE(got.empty()) << t;
    } else {
      EXPECT_EQ(got, (std::vector<Answer>{{t, 1, kCompleted}}));
      completed_ms = t;
    }
  }
  ASSERT_TRUE(completed_ms.has_value());
  // Consistent with the speed: at best 0.5 s to reach 0.5 m/s at 1 m/s^2
  // (12.5 cm), then 87.5 cm at 0.5 m/s, 2.25 s in all; the controller slows
  // down for the last 33 cm, so it takes longer, but not twice as long.
  const std::int64_t took_ms = *completed_ms - 1000;
  EXPECT_GE(took_ms, 2250);
  EXPECT_LE(took_ms, 4500);
  EXPECT_EQ(gui.fw().state_code(), wr8::State::stop);
  // The car stops cleanly: less than 1 cm past the distance, straight ahead.
  gui.run_until(at_ms(*completed_ms + 500));
  EXPECT_EQ(gui.chassis().speed_mps(), 0.0);
  EXPECT_GE(gui.vehicle().odometry().distance_m, 1.0);
  EXPECT_LT(gui.vehicle().odometry().distance_m, 1.01);
  const sim::Pose end = gui.vehicle().pose();
  EXPECT_NEAR(end.x_m - start.x_m, 1.0, 0.01);
  EXPECT_NEAR(end.y_m, start.y_m, 0.001);
  EXPECT_EQ(gui.state().tasks_completed, 1u);
}

TEST(Wr8Task, DriveRefusesDistancesItCannotDrive) {
  Gui gui;
  gui.settle(at_ms(1000));
  gui.drive(1, 0);
  gui.drive(2, -10);
  gui.drive(3, 1001);  // past max_drive_cm
  gui.send_unchecked(
      wr8::Task{4, wr8::TaskCode::drive, {wr8::Word::from_i32(10), wr8::Word::from_i32(10)}});
  EXPECT_EQ(answers(gui.take()),
            (std::vector<Answer>{
                {1000, 1, kError}, {1000, 2, kError}, {1000, 3, kError}, {1000, 4, kError}}));
  gui.run_until(at_ms(1500));
  EXPECT_EQ(gui.vehicle().odometry().distance_m, 0.0);
  EXPECT_EQ(gui.state().tasks_failed, 4u);
}

TEST(Wr8Task, ANewMotionTaskWhileOneRunsIsAnErrorAndTheRunningOneGoesOn) {
  Gui gui;
  gui.settle(at_ms(1000));
  gui.drive(1, 50);
  gui.run_until(at_ms(1200));
  gui.drive(2, 50);
  gui.turn(3, 10);
  gui.task(4, wr8::TaskCode::check);  // not a motion task
  gui.task(5, wr8::TaskCode::blink);  // nor this
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1000, 1, kStarted},
                                                      {1200, 2, kError},
                                                      {1200, 3, kError},
                                                      {1200, 4, kCompleted},
                                                      {1200, 5, kStarted}}));
  gui.run_until(at_ms(5000));
  auto done = answers(gui.take());
  std::sort(done.begin(), done.end(),
            [](const Answer& a, const Answer& b) { return a.coi < b.coi; });
  ASSERT_EQ(done.size(), 2u);
  EXPECT_EQ(done[0].coi, 1);
  EXPECT_EQ(done[0].code, kCompleted);
  EXPECT_EQ(done[1], (Answer{3200, 5, kCompleted}));
  EXPECT_NEAR(gui.vehicle().odometry().distance_m, 0.50, 0.01);
  EXPECT_EQ(gui.chassis().steering_rad(), 0.0);  // the refused turn did nothing
}

TEST(Wr8Task, TurnCompletesWhenTheWheelsReachTheAngle) {
  Gui gui;
  gui.settle(at_ms(1000));
  gui.turn(1, 15);
  // The servo slews 1.5 degrees per 1/120 s step: ten steps, the last ending
  // at 1083.3 ms; the control tick at 1090 ms sees the wheels there.
  gui.run_until(at_ms(1089));
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1000, 1, kStarted}}));
  gui.run_until(at_ms(1100));
  const auto got = gui.take();
  EXPECT_EQ(answers(got), (std::vector<Answer>{{1090, 1, kCompleted}}));
  const auto data = select<wr8::Data>(got);
  ASSERT_EQ(data.size(), 1u);
  EXPECT_EQ(data[0].second.state, wr8::State::stop);
  EXPECT_FLOAT_EQ(static_cast<float>(value(data[0].second, wr8::data_code::wheel_angle)), 15.0f);
  EXPECT_EQ(gui.state().commanded_wheel_angle_deg, 15.0);
  // Back to -15: 30 degrees, twenty steps from 1100 ms, the last ending at 1266.7 ms.
  gui.turn(2, -15);
  gui.run_until(at_ms(1300));
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1100, 2, kStarted}, {1270, 2, kCompleted}}));
  EXPECT_NEAR(gui.chassis().steering_rad(), sim::deg_to_rad(-15), 1e-12);
}

TEST(Wr8Task, RunStateWhileTheWheelsTurn) {
  Gui gui;
  gui.authenticate();
  gui.run_until(at_ms(1050));
  gui.turn(1, 30);  // 20 steps, 166.7 ms
  gui.run_until(at_ms(1100));
  const auto data = select<wr8::Data>(gui.take());
  ASSERT_FALSE(data.empty());
  EXPECT_EQ(data.back().second.state, wr8::State::run);
  const double angle = value(data.back().second, wr8::data_code::wheel_angle);
  EXPECT_GT(angle, 0);
  EXPECT_LT(angle, 30);
}

TEST(Wr8Task, TurnOutOfTheSteeringRangeIsAnError) {
  Gui gui;
  gui.settle(at_ms(1000));
  gui.turn(1, 31);
  gui.turn(2, -31);
  gui.turn(3, 30);  // the limit itself is fine
  gui.run_until(at_ms(1500));
  EXPECT_EQ(answers(gui.take()),
            (std::vector<Answer>{
                {1000, 1, kError}, {1000, 2, kError}, {1000, 3, kStarted}, {1170, 3, kCompleted}}));
}

TEST(Wr8Task, TurningToTheAngleTheWheelsAlreadyHaveCompletesOnTheNextTick) {
  Gui gui;
  gui.settle(at_ms(1003));
  gui.turn(1, 0);
  gui.run_until(at_ms(1100));
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1003, 1, kStarted}, {1010, 1, kCompleted}}));
}

TEST(Wr8Task, BlinkCompletesAfterTheBlinkTimeInWaitState) {
  Gui gui;
  gui.settle(at_ms(1000));
  gui.task(1, wr8::TaskCode::blink);
  gui.run_until(at_ms(1500));
  gui.task(2, wr8::TaskCode::blink);  // one blink at a time
  gui.run_until(at_ms(3100));
  const auto got = gui.take();
  EXPECT_EQ(answers(got),
            (std::vector<Answer>{{1000, 1, kStarted}, {1500, 2, kError}, {3000, 1, kCompleted}}));
  for (const auto& [t, d] : select<wr8::Data>(got))
    EXPECT_EQ(d.state, ms_of(t) < 3000 ? wr8::State::wait : wr8::State::stop) << ms_of(t);
  EXPECT_EQ(gui.vehicle().odometry().distance_m, 0.0);
}

TEST(Wr8Task, BlinkTimeIsConfigurable) {
  Wr8Config config;
  config.blink_duration = milliseconds(750);
  Gui gui(config);
  gui.settle(at_ms(1000));
  gui.task(1, wr8::TaskCode::blink);
  gui.run_until(at_ms(2000));
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1000, 1, kStarted}, {1750, 1, kCompleted}}));
}

TEST(Wr8Task, GetSettingsSendsAllFourSettingsWithTheSameCoiThenCompleted) {
  Gui gui;
  gui.authenticate_raw();
  gui.client().write(wr8::encode(wr8::Task{5, wr8::TaskCode::get_settings, {}}));
  gui.car().run_for(milliseconds(0));
  // SETTINGS COI 5: P 1.5, I 0.25, D 0.05 (float32), servo zero 90 (int32); then RESPONSE.
  EXPECT_EQ(gui.take_hex(),
            "04 05 14 00 00 00 C0 3F 01 00 00 80 3E 02 CD CC 4C 3D 03 5A 00 00 00 05 05 02");
}

// ---------------------------------------------------------------- settings

TEST(Wr8Settings, RoundTripThroughGetSettings) {
  Gui gui;
  gui.authenticate();
  gui.take();
  const std::vector<wr8::Setting> wanted = {setting(wr8::SettingCode::p, 3.0f),
                                            setting(wr8::SettingCode::i, 0.5f),
                                            setting(wr8::SettingCode::d, 0.125f), servo_zero(92)};
  gui.settings(1, wanted);
  gui.task(2, wr8::TaskCode::get_settings);
  const auto got = gui.take();
  ASSERT_EQ(got.size(), 3u);
  EXPECT_EQ(std::get<wr8::Response>(got[0].message), (wr8::Response{1, kCompleted}));
  EXPECT_EQ(std::get<wr8::Settings>(got[1].message), (wr8::Settings{2, wanted}));
  EXPECT_EQ(std::get<wr8::Response>(got[2].message), (wr8::Response{2, kCompleted}));
  EXPECT_EQ(gui.state().p, 3.0);
  EXPECT_EQ(gui.state().servo_zero_deg, 92.0);
}

TEST(Wr8Settings, EntriesApplyInOrderAndAnEmptySettingsIsFine) {
  Gui gui;
  gui.authenticate();
  gui.take();
  gui.settings(1, {setting(wr8::SettingCode::p, 2.0f), setting(wr8::SettingCode::p, 2.5f)});
  gui.settings(2, {});
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1, 1, kCompleted}, {1, 2, kCompleted}}));
  EXPECT_EQ(gui.state().p, 2.5);
}

TEST(Wr8Settings, AnInvalidValueIsAnErrorAndChangesNothing) {
  Gui gui;
  gui.authenticate();
  gui.take();
  gui.settings(1, {setting(wr8::SettingCode::p, -1.0f)});
  gui.settings(2, {setting(wr8::SettingCode::i, std::nanf(""))});
  gui.settings(3, {setting(wr8::SettingCode::d, std::numeric_limits<float>::infinity())});
  gui.settings(4, {setting(wr8::SettingCode::p, 101.0f)});  // above max_gain
  gui.settings(5, {servo_zero(181)});
  gui.settings(6, {servo_zero(-1)});
  // One bad entry spoils the whole packet: P stays as it was.
  gui.settings(7, {setting(wr8::SettingCode::p, 4.0f), servo_zero(500)});
  const auto got = answers(gui.take());
  ASSERT_EQ(got.size(), 7u);
  for (const auto& a : got)
    EXPECT_EQ(a.code, kError) << a;
  gui.task(8, wr8::TaskCode::get_settings);
  const auto settings = select<wr8::Settings>(gui.take());
  ASSERT_EQ(settings.size(), 1u);
  EXPECT_EQ(settings[0].second.params,
            (std::vector<wr8::Setting>{setting(wr8::SettingCode::p, 1.5f),
                                       setting(wr8::SettingCode::i, 0.25f),
                                       setting(wr8::SettingCode::d, 0.05f), servo_zero(90)}));
}

TEST(Wr8Settings, ZeroGainsMeanNoMotionAndTheDriveFailsAfterTheStallTimeout) {
  Gui gui;
  gui.authenticate();
  gui.run_until(at_ms(1000));
  gui.settings(1, {setting(wr8::SettingCode::p, 0), setting(wr8::SettingCode::i, 0),
                   setting(wr8::SettingCode::d, 0)});
  gui.take();
  gui.drive(2, 100);
  gui.run_until(at_ms(2999));
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1000, 2, kStarted}}));
  EXPECT_EQ(gui.vehicle().odometry().distance_m, 0.0);
  gui.run_until(at_ms(3100));
  const auto got = gui.take();
  EXPECT_EQ(answers(got), (std::vector<Answer>{{3000, 2, kError}}));
  EXPECT_EQ(select<wr8::Data>(got).back().second.state, wr8::State::stop);
  EXPECT_EQ(gui.vehicle().odometry().distance_m, 0.0);
  EXPECT_FALSE(gui.state().drive.has_value());
}

TEST(Wr8Settings, TheStallTimeoutIsConfigurable) {
  Wr8Config config;
  config.p = config.i = config.d = 0;
  config.stall_timeout = milliseconds(500);
  Gui gui(config);
  gui.settle(at_ms(1000));
  gui.drive(1, 100);
  gui.run_until(at_ms(2000));
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1000, 1, kStarted}, {1500, 1, kError}}));
}

/// How long a 100 cm drive takes with these gains, in ms (0: never done).
std::int64_t drive_100_ms(float p, float i, float d) {
  Gui gui;
  gui.authenticate();
  gui.run_until(at_ms(1000));
  gui.settings(1, {setting(wr8::SettingCode::p, p), setting(wr8::SettingCode::i, i),
                   setting(wr8::SettingCode::d, d)});
  gui.take();
  gui.drive(2, 100);
  gui.run_until(at_ms(20000));
  for (const Answer& a : answers(gui.take())) {
    if (a.code == kCompleted) {
      EXPECT_GE(gui.vehicle().odometry().distance_m, 1.0);
      return a.at_ms - 1000;
    }
  }
  return 0;
}

TEST(Wr8Settings, TheGainsChangeHowTheCarDrives) {
  const std::int64_t standard = drive_100_ms(1.5f, 0.25f, 0.05f);
  const std::int64_t soft = drive_100_ms(0.5f, 0, 0);
  const std::int64_t integral_only = drive_100_ms(0, 0.5f, 0);
  ASSERT_GT(standard, 0);
  // A smaller P slows down sooner and crawls longer.
  EXPECT_GT(soft, standard + 1000);
  // I alone still gets there, its integral building up the speed.
  EXPECT_GT(integral_only, 0);
  EXPECT_NE(integral_only, standard);
}

TEST(Wr8Settings, ServoZeroOffsetsTheWheelsAndTheCarDrifts) {
  Gui gui;
  gui.settle(at_ms(1000));
  gui.settings(1, {servo_zero(95)});  // 5 servo degrees left of the mechanical centre
  gui.run_until(at_ms(1100));
  auto got = gui.take();
  EXPECT_EQ(answers(got), (std::vector<Answer>{{1000, 1, kCompleted}}));
  // Straight ahead is still what was commanded, but the wheel angle shows 5 degrees.
  EXPECT_EQ(gui.state().commanded_wheel_angle_deg, 0.0);
  EXPECT_FLOAT_EQ(
      static_cast<float>(value(select<wr8::Data>(got).back().second, wr8::data_code::wheel_angle)),
      5.0f);
  const sim::Pose start = gui.vehicle().pose();
  gui.drive(2, 100);
  gui.run_until(at_ms(6000));
  got = gui.take();
  ASSERT_EQ(answers(got).back().code, kCompleted);
  // 1 m on a 2.97 m radius (wheelbase 0.26 m / tan 5 deg): 19.3 degrees and
  // 16.7 cm to the left.
  const sim::Pose end = gui.vehicle().pose();
  EXPECT_NEAR(sim::rad_to_deg(end.heading_rad - start.heading_rad), 19.3, 0.5);
  EXPECT_NEAR(end.y_m - start.y_m, 0.167, 0.01);

  // Below the centre the wheels point right.
  Gui right;
  right.authenticate();
  right.settings(1, {servo_zero(84)});
  right.run_until(at_ms(200));
  EXPECT_NEAR(sim::rad_to_deg(right.chassis().steering_rad()), -6.0, 1e-9);
  // A turn task adds to the offset.
  right.turn(2, 10);
  right.run_until(at_ms(300));
  EXPECT_NEAR(sim::rad_to_deg(right.chassis().steering_rad()), 4.0, 1e-9);
}

TEST(Wr8Settings, TheMechanicalCentreIsConfigurable) {
  Wr8Config config;
  config.servo_center_deg = 93;  // this car's servo horn sits three degrees off
  Gui gui(config);
  gui.authenticate();
  gui.run_until(at_ms(200));
  EXPECT_NEAR(sim::rad_to_deg(gui.chassis().steering_rad()), -3.0, 1e-9);
  gui.settings(1, {servo_zero(93)});  // calibrated
  gui.run_until(at_ms(300));
  EXPECT_NEAR(gui.chassis().steering_rad(), 0.0, 1e-12);
}

// ---------------------------------------------------------------- faults and behaviours

TEST(Wr8Fault, StopsTheCarFailsTheTaskAndRefusesTasksUntilCleared) {
  Gui gui;
  gui.authenticate();
  gui.run_until(at_ms(1000));
  gui.drive(1, 100);
  gui.fw().arm(Behaviour{"", When{at_ms(2000), "", 1}, EnterFault{}});
  gui.fw().arm(Behaviour{"", When{at_ms(3000), "", 1}, ClearFault{}});
  gui.run_until(at_ms(2500));
  gui.task(2, wr8::TaskCode::check);
  gui.drive(3, 10);
  gui.settings(4, {setting(wr8::SettingCode::p, 2.0f)});  // settings still apply
  gui.send(wr8::Auth{gui.config().profile.auth_text});
  auto got = gui.take();
  EXPECT_EQ(answers(got), (std::vector<Answer>{{1000, 1, kStarted},
                                               {2000, 1, kError},
                                               {2500, 2, kError},
                                               {2500, 3, kError},
                                               {2500, 4, kCompleted}}));
  EXPECT_EQ(select<wr8::AuthReply>(got).back().second.state, wr8::State::fault);
  for (const auto& [t, d] : select<wr8::Data>(got))
    EXPECT_EQ(d.state, ms_of(t) <= 1000  ? wr8::State::stop
                       : ms_of(t) < 2000 ? wr8::State::run
                                         : wr8::State::fault)
        << ms_of(t);
  // Braking from at most 0.5 m/s at 2 m/s^2 takes 0.25 s.
  EXPECT_EQ(gui.chassis().speed_mps(), 0.0);
  const double stopped_at = gui.vehicle().odometry().distance_m;
  EXPECT_LT(stopped_at, 1.0);
  gui.run_until(at_ms(3100));
  EXPECT_EQ(gui.vehicle().odometry().distance_m, stopped_at);
  got = gui.take();
  EXPECT_EQ(select<wr8::Data>(got).back().second.state, wr8::State::stop);
  gui.task(5, wr8::TaskCode::check);
  gui.drive(6, 10);
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{3100, 5, kCompleted}, {3100, 6, kStarted}}));
}

TEST(Wr8Behaviour, RejectAnswersErrorWithNoEffect) {
  Gui gui;
  gui.settle(at_ms(1000));
  gui.fw().arm(Behaviour{"", When{}, Reject{"TASK", 1}});
  gui.fw().arm(Behaviour{"", When{}, Reject{"SETTINGS", 1}});
  gui.drive(1, 100);
  gui.settings(2, {servo_zero(100)});
  gui.run_until(at_ms(1500));
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1000, 1, kError}, {1000, 2, kError}}));
  EXPECT_EQ(gui.vehicle().odometry().distance_m, 0.0);
  EXPECT_EQ(gui.state().servo_zero_deg, 90.0);
  EXPECT_EQ(gui.fw().stats().rejected, 2u);
  gui.drive(3, 10);  // the reject is used up
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1500, 3, kStarted}}));
}

TEST(Wr8Behaviour, ARejectedAuthIsARefusedLogin) {
  Gui gui;
  gui.fw().arm(Behaviour{"", When{}, Reject{"AUTH", 1}});
  gui.send(wr8::Auth{gui.config().profile.auth_text});
  EXPECT_EQ(gui.state().session, Wr8Session::refused);
  gui.run_until(at_ms(1001));
  EXPECT_TRUE(gui.take().empty());
  EXPECT_TRUE(gui.client().closed.has_value());
}

TEST(Wr8Behaviour, IgnoreSwallowsCommandsWithoutAnswerOrEffect) {
  Gui gui;
  gui.settle(at_ms(1000));
  gui.fw().arm(Behaviour{"", When{}, Ignore{"TASK", 2, std::nullopt}});
  gui.drive(1, 100);
  gui.task(2, wr8::TaskCode::check);
  gui.run_until(at_ms(1500));
  const auto got = gui.take();
  EXPECT_TRUE(answers(got).empty());
  EXPECT_EQ(select<wr8::Data>(got).size(), 5u);  // DATA goes on
  EXPECT_EQ(gui.vehicle().odometry().distance_m, 0.0);
  EXPECT_EQ(gui.fw().stats().ignored, 2u);
  gui.task(3, wr8::TaskCode::check);
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1500, 3, kCompleted}}));
}

TEST(Wr8Behaviour, AfterFrameTriggersCountHandledTasks) {
  Gui gui;
  gui.authenticate();
  gui.take();
  gui.fw().arm(Behaviour{"", When{std::nullopt, "TASK", 2}, SendBytes{{0x05, 0x63, 0x00}}});
  gui.task(1, wr8::TaskCode::check);
  gui.task(2, wr8::TaskCode::check);
  EXPECT_EQ(answers(gui.take()),
            (std::vector<Answer>{{1, 1, kCompleted}, {1, 2, kCompleted}, {1, 0x63, kError}}));
}

// ---------------------------------------------------------------- connection

TEST(Wr8Connection, ADisconnectStopsTheCarAndTheNextClientMustAuthenticate) {
  Gui gui;
  gui.authenticate();
  gui.run_until(at_ms(1000));
  gui.drive(1, 100);
  gui.run_until(at_ms(2000));
  gui.client().pipe->close();
  gui.run_until(at_ms(2001));
  EXPECT_FALSE(gui.fw().connected());
  EXPECT_FALSE(gui.state().drive.has_value());
  EXPECT_EQ(gui.state().session, Wr8Session::unauthenticated);
  // The car brakes to a stop on its own control ticks, with nobody connected.
  gui.car().run_until(at_ms(2500));
  EXPECT_EQ(gui.chassis().speed_mps(), 0.0);
  const double stopped_at = gui.vehicle().odometry().distance_m;
  EXPECT_LT(stopped_at, 1.0);
  gui.car().run_until(at_ms(4000));
  EXPECT_EQ(gui.vehicle().odometry().distance_m, stopped_at);

  auto next = gui.car().connect();
  next->write(wr8::encode(wr8::Task{9, wr8::TaskCode::check, {}}));
  gui.car().run_for(milliseconds(1));
  EXPECT_TRUE(next->take().empty());  // not authenticated yet
  next->write(wr8::encode(wr8::Auth{gui.config().profile.auth_text}));
  gui.car().run_for(milliseconds(0));
  EXPECT_EQ(next->take(), (Bytes{0x02, 0x08, 0x01, 0x02}));
}

TEST(Wr8Connection, WithStopOnDisconnectOffTheDriveFinishesUnwatched) {
  Wr8Config config;
  config.stop_on_disconnect = false;
  Gui gui(config);
  gui.authenticate();
  gui.run_until(at_ms(1000));
  gui.drive(1, 100);
  gui.run_until(at_ms(2000));
  gui.client().pipe->close();
  gui.car().run_until(at_ms(8000));
  EXPECT_FALSE(gui.state().drive.has_value());
  EXPECT_GE(gui.vehicle().odometry().distance_m, 1.0);
  EXPECT_EQ(gui.state().tasks_completed, 1u);
}

// ---------------------------------------------------------------- malformed input

TEST(Wr8Malformed, TasksAndSettingsThatCannotBeUsedAreAnsweredErrorWithTheirCoi) {
  Gui gui;
  gui.settle(at_ms(1000));
  const auto body = [](std::initializer_list<std::uint8_t> b) { return Bytes(b); };
  // drive with no distance (the profile wants one parameter)
  gui.send_bytes(wr8::raw_packet(3, body({0x11, 0x01, 0x00})));
  // task code 9
  gui.send_bytes(wr8::raw_packet(3, body({0x12, 0x09, 0x00})));
  // block size 3 is not a multiple of 4
  gui.send_bytes(wr8::raw_packet(3, body({0x13, 0x01, 0x03, 0x00, 0x00, 0x00})));
  // setting type 7
  gui.send_bytes(wr8::raw_packet(4, body({0x14, 0x05, 0x07, 0x00, 0x00, 0x80, 0x3F})));
  // settings block of 4 bytes, not a multiple of 5
  gui.send_bytes(wr8::raw_packet(4, body({0x15, 0x04, 0x00, 0x00, 0x00, 0x00})));
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1000, 0x11, kError},
                                                      {1000, 0x12, kError},
                                                      {1000, 0x13, kError},
                                                      {1000, 0x14, kError},
                                                      {1000, 0x15, kError}}));
  EXPECT_EQ(gui.fw().stats().bad_frames, 5u);
  EXPECT_EQ(gui.state().p, 1.5);
}

TEST(Wr8Malformed, GarbageAndVehiclePacketsAreCountedAndSkipped) {
  Gui gui;
  gui.settle(at_ms(1000));
  // Bytes that are no packet code, then packet codes only a vehicle sends,
  // then a good task: the stream stays in step.
  gui.send_bytes(Bytes{0xFF, 0xFE, 0x80, 0x06, 0x05, 0x02, 0x03, 0x21, 0x00, 0x00});
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1000, 0x21, kCompleted}}));
  EXPECT_EQ(gui.fw().stats().bad_frames, 2u);  // one garbage run, one unknown-code run
  EXPECT_EQ(gui.fw().stats().frames_in, 2u);   // AUTH and the check
}

TEST(Wr8Malformed, OversizedPacketsAreDroppedInPiecesWithoutAnswer) {
  Wr8Config config;
  config.max_packet_bytes = 16;
  Gui gui(config);
  gui.authenticate();
  gui.take();
  Bytes body = {0x31, 0x01, 0x10};  // a drive with a 16-byte block: 20 bytes in all
  body.resize(body.size() + 16, 0x01);
  gui.send_bytes(wr8::raw_packet(3, body));
  gui.task(0x32, wr8::TaskCode::check);
  EXPECT_EQ(answers(gui.take()), (std::vector<Answer>{{1, 0x32, kCompleted}}));
  EXPECT_EQ(gui.fw().stats().bad_frames, 2u);
}

TEST(Wr8Malformed, BadPacketsBeforeAuthenticationAreNotAnswered) {
  Gui gui;
  gui.send_bytes(wr8::raw_packet(3, Bytes{0x11, 0x01, 0x00}));
  gui.send_bytes(Bytes{0xFF, 0x00});  // a garbage byte ends where the EMPTY starts
  gui.run_until(at_ms(500));
  EXPECT_TRUE(gui.take().empty());
  EXPECT_EQ(gui.fw().stats().bad_frames, 2u);
  EXPECT_EQ(gui.state().dropped_unauthenticated, 1u);  // the EMPTY
}

TEST(Wr8Malformed, APacketCutOffByTheHangUpIsCounted) {
  Gui gui;
  gui.authenticate();
  gui.send_bytes(Bytes{0x03, 0x01, 0x01});
  gui.client().pipe->close();
  gui.run_until(at_ms(10));
  EXPECT_FALSE(gui.fw().connected());
  EXPECT_EQ(gui.fw().stats().bad_frames, 1u);
}

TEST(Wr8Malformed, APacketSplitOverManyWritesIsOnePacket) {
  Gui gui;
  gui.authenticate();
  gui.take();
  const Bytes packet = wr8::encode(wr8::Task{0x41, wr8::TaskCode::turn, {wr8::Word::from_i32(5)}});
  for (const std::uint8_t b : packet) {
    gui.send_bytes(Bytes{b});
    gui.run_for(milliseconds(2));
  }
  EXPECT_EQ(answers(gui.take()).front(), (Answer{15, 0x41, kStarted}));
}

// ---------------------------------------------------------------- profiles

TEST(Wr8Profile, ABigEndianEntriesProfileIsSpokenBothWays) {
  Wr8Config config;
  config.profile.byte_order = wr8::ByteOrder::big;
  config.profile.block_unit = wr8::BlockSizeUnit::entries;
  // The server's link frames this car's bytes by its own profile
  // (Wr8Firmware::adapter()), so a frame-aware link carries them whole.
  ServerOptions options;
  Gui gui(config, options);  // its GUI decodes with the same profile
  gui.settle(at_ms(1000));
  gui.drive(1, 20);
  gui.run_until(at_ms(3000));
  const auto got = gui.take();
  const auto done = answers(got);
  ASSERT_EQ(done.size(), 2u);
  EXPECT_EQ(done[1].code, kCompleted);
  EXPECT_EQ(value(select<wr8::Data>(got).back().second, wr8::data_code::odometry), 20);
  // DATA at 3100 ms: STOP, timestamp 00 00 0C 1C, four entries.
  gui.client().take();
  gui.car().run_until(at_ms(3100));
  const Bytes raw = gui.client().take();
  ASSERT_GE(raw.size(), 7u);
  EXPECT_EQ(protocol::to_hex(protocol::ByteView(raw).first(7)), "06 02 00 00 0C 1C 04");
}

TEST(Wr8Profile, DataFollowsTheProfilesTypesForEachParameter) {
  Wr8Config config;
  for (auto& row : config.profile.data_parameters) {
    if (row.code == wr8::data_code::odometry) row.type = wr8::ValueType::float32;
    if (row.code == wr8::data_code::battery) row.size_bytes = 2;
  }
  ServerOptions options;
  Gui gui(config, options);
  gui.authenticate();
  gui.run_until(at_ms(1000));
  gui.drive(1, 30);
  gui.run_until(at_ms(4000));
  const auto data = select<wr8::Data>(gui.take()).back().second;
  for (const auto& v : data.values) {
    if (v.code == wr8::data_code::odometry) {
      EXPECT_NEAR(v.value.as_f32(), 30.0f, 0.5f);
    }
    if (v.code == wr8::data_code::battery) {
      EXPECT_EQ(v.value.bits, 100u);
    }
  }
}

TEST(Wr8Summary, ShowsStateReadingsAndRunningTasks) {
  Gui gui;
  EXPECT_EQ(gui.fw().summary(), "STOP unauthenticated ODO 0cm SP 0.00 ANG 0.0 BAT 100%");
  gui.authenticate();
  gui.drive(1, 100);
  gui.task(2, wr8::TaskCode::blink);
  gui.run_until(at_ms(50));
  EXPECT_NE(gui.fw().summary().find("RUN ODO"), std::string::npos) << gui.fw().summary();
  EXPECT_NE(gui.fw().summary().find("DRIVE"), std::string::npos);
  EXPECT_NE(gui.fw().summary().find("BLINK"), std::string::npos);
}

// ---------------------------------------------------------------- login security

std::array<std::uint8_t, wr8::kAuthTextBytes> text_of(std::string_view s) {
  std::array<std::uint8_t, wr8::kAuthTextBytes> text{};
  std::copy(s.begin(), s.end(), text.begin());
  return text;
}

TEST(Wr8AuthSecurity, FailedLoginsInARowDoubleTheCloseDelayAcrossConnectionsUpToTheCap) {
  Wr8Config config;
  config.wrong_auth_max_delay = seconds(3);
  Gui gui(config);
  const Bytes wrong = wr8::encode(wr8::Auth{text_of("NOT-IT-000")}, config.profile);
  const Bytes right = wr8::encode(wr8::Auth{config.profile.auth_text}, config.profile);

  // Failure 1 at 1 ms: closed exactly 1 s later.
  gui.send_bytes(wrong);
  gui.run_until(at_ms(1000));
  EXPECT_FALSE(gui.client().closed.has_value());
  gui.run_until(at_ms(1001));
  EXPECT_TRUE(gui.client().closed.has_value());

  // Each later failure in a row waits twice as long, also on a new
  // connection (connect() takes 1 ms): 2 s, then 4 s capped at 3 s.
  const std::int64_t expected_delay_ms[] = {2000, 3000, 3000};
  for (const std::int64_t delay_ms : expected_delay_ms) {
    auto client = gui.car().connect();
    const Time sent = gui.car().now();
    client->write(protocol::ByteView(wrong));
    // Everything else on this connection meanwhile is ignored, the right
    // string included: no answer, no DATA, no motion.
    client->write(protocol::ByteView(right));
    client->write(wr8::encode(wr8::Task{5, wr8::TaskCode::drive, {wr8::Word::from_i32(50)}}));
    gui.car().run_until(sent + milliseconds(delay_ms) - milliseconds(1));
    EXPECT_FALSE(client->closed.has_value()) << "delay " << delay_ms << " ms";
    gui.car().run_until(sent + milliseconds(delay_ms));
    EXPECT_TRUE(client->closed.has_value()) << "delay " << delay_ms << " ms";
    EXPECT_TRUE(client->take().empty());
  }
  EXPECT_EQ(gui.state().auth_failures, 4u);
  EXPECT_EQ(gui.state().auth_failures_in_a_row, 4u);
  EXPECT_EQ(gui.state().dropped_unauthenticated, 6u);
  EXPECT_EQ(gui.vehicle().odometry().distance_m, 0.0);

  // A right login resets the run: the next failure waits 1 s again.
  auto client = gui.car().connect();
  client->write(protocol::ByteView(right));
  gui.car().run_for(milliseconds(0));
  EXPECT_EQ(client->take(), (Bytes{0x02, 0x08, 0x01, 0x02}));
  EXPECT_EQ(gui.state().auth_failures_in_a_row, 0u);
  const Time sent = gui.car().now();
  client->write(protocol::ByteView(wrong));
  gui.car().run_until(sent + milliseconds(999));
  EXPECT_FALSE(client->closed.has_value());
  gui.car().run_until(sent + seconds(1));
  EXPECT_TRUE(client->closed.has_value());
  EXPECT_EQ(gui.state().auth_failures, 5u);
}

TEST(Wr8AuthSecurity, TheDelayDoublesFromTheConfiguredOneAndTheCapMustNotBeBelowIt) {
  Wr8Config config;
  config.wrong_auth_close_delay = milliseconds(250);
  config.wrong_auth_max_delay = seconds(30);
  EXPECT_EQ(wrong_auth_delay(config, 1), milliseconds(250));
  EXPECT_EQ(wrong_auth_delay(config, 2), milliseconds(500));
  EXPECT_EQ(wrong_auth_delay(config, 7), milliseconds(16000));
  EXPECT_EQ(wrong_auth_delay(config, 8), seconds(30));        // 32 s, capped
  EXPECT_EQ(wrong_auth_delay(config, 1000000), seconds(30));  // no overflow
  config.wrong_auth_max_delay = milliseconds(100);
  EXPECT_THROW(Car(sim::wr8_vehicle(),
                   [config](sim::World& w, sim::Vehicle& v) {
                     return std::make_unique<Wr8Firmware>(w, v, config);
                   }),
               std::invalid_argument);
}

TEST(Wr8AuthSecurity, LogLinesCountFailedLoginsAndDroppedPacketsButNeverHoldAString) {
  auto lines = std::make_shared<std::vector<std::string>>();
  Wr8Config config;
  config.log = [lines](const std::string& line) { lines->push_back(line); };
  Gui gui(config);
  gui.task(1, wr8::TaskCode::check);           // before any login: dropped
  gui.send(wr8::Auth{text_of("HIL-WR8-02")});  // one character off the real one
  gui.run_until(at_ms(1001));
  ASSERT_TRUE(gui.client().closed.has_value());
  gui.car().run_for(milliseconds(1));

  auto client = gui.car().connect();
  client->write(wr8::encode(wr8::Auth{config.profile.auth_text}, config.profile));
  gui.car().run_for(milliseconds(0));

  std::string all;
  for (const auto& l : *lines)
    all += l + "\n";
  EXPECT_NE(all.find("login refused (AUTH **********): failed login 1 in a row, 1 in all; "
                     "closing the connection in 1.000 s"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("1 packet(s) from this client dropped unanswered before a login"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("login accepted after 1 failed login(s) in a row"), std::string::npos) << all;
  EXPECT_EQ(all.find("HIL-WR8-0"), std::string::npos) << all;  // neither the tried nor the real
  EXPECT_NE(gui.fw().summary().find("AUTH FAILED 1"), std::string::npos);
}

}  // namespace
}  // namespace hil::mocks
