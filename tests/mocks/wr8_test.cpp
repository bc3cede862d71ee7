// The WR8 mock firmware under the virtual-time driver: authentication and
// its security, the DATA stream, the connection, malformed input and the
// profiles, with exact times.

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
#include "tests/mocks/wr8_gui.hpp"

namespace hil::mocks::test {
namespace {

using link::milliseconds;
using link::seconds;
using protocol::Bytes;

using Car = VirtualCar<Wr8Firmware>;
using Gui = Wr8Gui;

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
}  // namespace hil::mocks::test
