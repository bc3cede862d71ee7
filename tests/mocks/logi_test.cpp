// The LOGI car's mock firmware under the virtual-time driver: STAT timing
// and fields, every command and its feedback, malformed and dropped input,
// and the configuration it refuses.

#include "mocks/logi.hpp"

#include <gtest/gtest.h>

#include <array>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "protocol/logi/codec.hpp"
#include "sim/presets.hpp"
#include "tests/mocks/logi_bench.hpp"

namespace hil::mocks::test {
namespace {

using link::milliseconds;
using link::seconds;
using logi::Direction;
using logi::Mode;

// ---------------------------------------------------------------- boot and STAT

TEST(LogiFirmware, BootsInAutoAtHalfSpeedWithNoStation) {
  LogiBench b;
  EXPECT_EQ(b.fw().protocol(), "logi");
  EXPECT_EQ(b.state().speed_percent, 50);
  EXPECT_EQ(b.state().mode, Mode::automatic);
  EXPECT_EQ(b.state().station, 0);
  EXPECT_FALSE(b.state().station_armed);
  EXPECT_FALSE(b.state().running);
  EXPECT_EQ(b.state().manual, Direction::stop);
  EXPECT_EQ(b.fw().summary(), "AUTO IDLE STA 000 SP 50 DIS 232");
}

TEST(LogiFirmware, StatComesEvery500MsOnTheGridWhileConnected) {
  LogiBench b;  // connected at 0
  b.run_until(at_ms(500) - link::Duration(1));
  EXPECT_TRUE(b.stats().empty());
  b.run_until(at_ms(500));
  auto first = b.stats();
  ASSERT_EQ(first.size(), 1u);
  EXPECT_EQ(first[0].first, at_ms(500));
  b.run_until(at_ms(5000));
  const auto later = b.stats();
  ASSERT_EQ(later.size(), 9u);
  for (std::size_t i = 0; i < later.size(); ++i) {
    EXPECT_EQ(later[i].first, at_ms(1000 + 500 * static_cast<int>(i)));
  }
  EXPECT_EQ(b.decode_errors(), 0u);
}

TEST(LogiFirmware, ABootOffsetShiftsTheStatAndControlGridsByItself) {
  // A car switched on 137 ms in: STAT at 137 + k * 500 ms, and the control
  // loop, while it has work, at 137 + k * 10 ms; nothing at the zero grid.
  LogiConfig config;
  config.boot_offset = link::milliseconds(137);
  LogiBench b(config);  // connected at 0
  b.run_until(at_ms(137) - link::Duration(1));
  EXPECT_TRUE(b.stats().empty());
  b.run_until(at_ms(2000));
  const auto stats = b.stats();
  ASSERT_EQ(stats.size(), 4u);
  for (std::size_t i = 0; i < stats.size(); ++i)
    EXPECT_EQ(stats[i].first, at_ms(137 + 500 * static_cast<int>(i)));
  // Driving, the control loop wakes on its own grid, offset alike.
  ASSERT_EQ(b.ask("MD:MAN"), "FB:MD:1");
  ASSERT_EQ(b.ask("MV:FWD"), "FB:MV:1");
  const auto wake = b.fw().next_wakeup();
  ASSERT_TRUE(wake.has_value());
  EXPECT_EQ((*wake - at_ms(137)) % link::milliseconds(10), link::Duration::zero())
      << link::to_ms(*wake) << " ms";
  EXPECT_EQ(b.decode_errors(), 0u);
}

TEST(LogiFirmware, GridsFromTheFirstConnectionCountFromItAndKeepCountingAfterIt) {
  // A car whose client first connects 729 ms in (an external client's
  // origin): STAT at 1229, 1729 ms, as at 500, 1000 ms from a connection at 0.
  LogiConfig config;
  config.grid_from_first_connection = true;
  VirtualCar<LogiFirmware> car(sim::logi_car(), [config](sim::World& w, sim::Vehicle& v) {
    return std::make_unique<LogiFirmware>(w, v, config);
  });
  car.run_until(at_ms(729));
  auto client = car.connect();  // up at 729 ms
  car.run_until(at_ms(1229) - link::Duration(1));
  EXPECT_EQ(client->text(), "") << "nothing on the 500 ms grid from 0";
  car.run_until(at_ms(1229));
  EXPECT_TRUE(client->text().starts_with("LOGI:STAT:")) << client->text();
  // A second connection keeps the first one's grid.
  client->pipe->close();
  car.run_until(at_ms(1400));
  auto again = car.connect();
  car.run_until(at_ms(1729) - link::Duration(1));
  EXPECT_EQ(again->text(), "");
  car.run_until(at_ms(1729));
  EXPECT_TRUE(again->text().starts_with("LOGI:STAT:")) << again->text();
}

TEST(LogiFirmware, AClockOriginGivenBeforeTheFirstConnectionIsWhereTheGridsCountFrom) {
  // An external client that printed a line at 700 ms (its origin) and
  // connected only at 729 ms: the STATs are on the grid from 700 ms, at
  // 1200 and 1700 ms, as the scenario's windows count from 700 ms.
  LogiConfig config;
  config.grid_from_first_connection = true;
  VirtualCar<LogiFirmware> car(sim::logi_car(), [config](sim::World& w, sim::Vehicle& v) {
    return std::make_unique<LogiFirmware>(w, v, config);
  });
  car.run_until(at_ms(700));
  car.firmware().set_clock_origin(at_ms(700));
  car.run_until(at_ms(729));
  auto client = car.connect();
  car.run_until(at_ms(1200) - link::Duration(1));
  EXPECT_EQ(client->text(), "");
  car.run_until(at_ms(1200));
  EXPECT_TRUE(client->text().starts_with("LOGI:STAT:")) << client->text();
  // Given again later (it never is), the grid stays where it is.
  car.firmware().set_clock_origin(at_ms(1300));
  const auto before = client->text().size();
  car.run_until(at_ms(1700) - link::Duration(1));
  EXPECT_EQ(client->text().size(), before);
  car.run_until(at_ms(1700));
  EXPECT_GT(client->text().size(), before);
}

TEST(LogiFirmware, ABootOffsetOutsideOneStatPeriodIsRefused) {
  LogiConfig config;
  config.boot_offset = link::milliseconds(501);
  EXPECT_THROW(LogiBench{config}, std::invalid_argument);
  config.boot_offset = link::milliseconds(-1);
  EXPECT_THROW(LogiBench{config}, std::invalid_argument);
}

TEST(LogiFirmware, AClientConnectingBetweenGridPointsGetsItsFirstStatAtTheNextOne) {
  LogiBench b;
  b.client().pipe->close();
  b.run_until(at_ms(1234));
  EXPECT_FALSE(b.fw().connected());
  auto late = b.car().connect();  // connected at 1234 ms
  b.car().run_until(at_ms(1500) - link::Duration(1));
  EXPECT_TRUE(late->received.empty());
  b.car().run_until(at_ms(1500));
  logi::Decoder decoder;
  std::vector<logi::Item> items;
  decoder.feed(late->take(), items);
  ASSERT_EQ(items.size(), 1u);
  const auto& frame = std::get<protocol::Frame<logi::Message>>(items[0]);
  EXPECT_TRUE(std::holds_alternative<logi::Status>(frame.message));
}

TEST(LogiFirmware, StatFieldsAtRestOnTheWarehouseStart) {
  LogiBench b;
  b.run_until(at_ms(500));
  const auto stats = b.stats();
  ASSERT_EQ(stats.size(), 1u);
  // The beam's right edge (15 degrees) meets the south wall 0.6 m / sin 15 = 2.32 m
  // from the nose, nearer than the east wall straight ahead (2.66 m); the
  // tape is centred between H3 and H2.
  const logi::Status expected{.speed_percent = 50,
                              .station = 0,
                              .running = false,
                              .mode = Mode::automatic,
                              .manual = Direction::stop,
                              .distance_cm = 232,
                              .track_mask = 0b0110,
                              .deviation = 0,
                              .obstacle = false,
                              .rpm = {0, 0, 0, 0}};
  EXPECT_EQ(stats[0].second, expected);
  EXPECT_EQ(logi::encode_text(stats[0].second),
            logi::frame_text("STAT:SP:050,STA:000,RUN:0,MODE:AUTO,MAN:STOP,DIS:232,TRK:0110,DEV:0,"
                             "OBS:0,RPM:0:0:0:0"));
}

TEST(LogiFirmware, StatFieldsFollowTheSimulationWhileStrafing) {
  ManualLogiBench b;
  b.ask("SP:100");
  EXPECT_EQ(b.ask("MV:LEFT"), "FB:MV:1");
  b.run_until(at_ms(1000));
  const auto stats = b.stats();
  ASSERT_EQ(stats.size(), 2u);
  const logi::Status& s = stats[1].second;
  EXPECT_EQ(s.mode, Mode::manual);
  EXPECT_EQ(s.manual, Direction::left);
  EXPECT_EQ(s.speed_percent, 100);
  EXPECT_FALSE(s.running);
  // 12.5 rad/s = 119.4 RPM; strafing left turns LR and RF forward, LF and RR back.
  EXPECT_EQ(s.rpm, (std::array<int, 4>{119, -119, 119, -119}));
  // Facing +x at x = 2.0: the sonar sees the east wall 4.0 - 2.14 m away.
  EXPECT_NEAR(s.distance_cm, 186, 1);
  EXPECT_EQ(s.track_mask, 0);
  EXPECT_EQ(s.deviation, 0);
  EXPECT_GT(b.pose().y_m, 1.5 + 0.3);
}

TEST(LogiFirmware, StatKeepsStationAndRunFromTheRun) {
  LogiBench b;
  b.start_run("002");
  b.run_until(at_ms(1000));
  const auto stats = b.stats();
  ASSERT_EQ(stats.size(), 2u);
  EXPECT_EQ(stats[1].second.station, 2);
  EXPECT_TRUE(stats[1].second.running);
  EXPECT_EQ(stats[1].second.mode, Mode::automatic);
  // Driving straight at 0.25 m/s: every wheel at 6.25 rad/s = 59.7 RPM.
  EXPECT_EQ(stats[1].second.rpm, (std::array<int, 4>{60, 60, 60, 60}));
}

TEST(LogiFirmware, NoStatWithoutAClient) {
  LogiBench b;
  b.client().pipe->close();
  b.run_until(at_ms(2000));
  EXPECT_FALSE(b.fw().connected());
  EXPECT_EQ(b.fw().stats().frames_out, 0u);
  EXPECT_EQ(b.fw().next_wakeup(), std::nullopt);  // idle and alone: nothing to do
}

// ---------------------------------------------------------------- commands

TEST(LogiFirmware, SpeedAcceptsZeroToHundred) {
  LogiBench b;
  for (const auto& [command, speed] :
       std::vector<std::pair<std::string, int>>{{"SP:030", 30}, {"SP:000", 0}, {"SP:100", 100}}) {
    EXPECT_EQ(b.ask(command), "FB:SP:1");
    EXPECT_EQ(b.state().speed_percent, speed) << command;
  }
}

TEST(LogiFirmware, MalformedSpeedIsRefusedAndLeavesTheSpeed) {
  LogiBench b;
  b.ask("SP:030");
  for (const char* bad : {"SP:101", "SP:150", "SP:abc", "SP:50", "SP:0500", "SP:", "SP:-10"}) {
    EXPECT_EQ(b.ask(bad), "FB:SP:0") << bad;
  }
  EXPECT_EQ(b.state().speed_percent, 30);
  EXPECT_EQ(b.fw().stats().bad_frames, 7u);
  EXPECT_EQ(b.fw().stats().frames_in, 1u);
}

TEST(LogiFirmware, TheSourcesPresetFramesGetTheirFeedback) {
  LogiBench b;
  EXPECT_EQ(b.ask_raw("LOGI:SP:030:D5#"), "FB:SP:1");
  EXPECT_EQ(b.ask_raw("LOGI:SP:050:D7#"), "FB:SP:1");
  EXPECT_EQ(b.ask_raw("LOGI:SP:080:DA#"), "FB:SP:1");
  EXPECT_EQ(b.ask_raw("LOGI:GS:001:CA#"), "FB:GS:1");
  EXPECT_EQ(b.ask_raw("LOGI:GS:002:CB#"), "FB:GS:1");
  EXPECT_EQ(b.ask_raw("LOGI:MV:FWD:23#"), "FB:MV:0");  // AUTO mode
  EXPECT_EQ(b.ask_raw("LOGI:ST:RUN:3B#"), "FB:ST:1");
  EXPECT_EQ(b.ask_raw("LOGI:ST:STOP:8C#"), "FB:ST:1");
  EXPECT_EQ(b.ask_raw("LOGI:MD:MAN:0C#"), "FB:MD:1");
  for (const char* frame :
       {"LOGI:MV:FWD:23#", "LOGI:MV:BWD:1F#", "LOGI:MV:LEFT:6D#", "LOGI:MV:RIGHT:C0#",
        "LOGI:MV:LF:D4#", "LOGI:MV:RF:DA#", "LOGI:MV:LB:D0#", "LOGI:MV:RB:D6#", "LOGI:MV:CW:DC#",
        "LOGI:MV:CCW:1F#", "LOGI:MV:STOP:88#"}) {
    EXPECT_EQ(b.ask_raw(frame), "FB:MV:1") << frame;
  }
  EXPECT_EQ(b.ask_raw("LOGI:MD:AUTO:69#"), "FB:MD:1");
  EXPECT_EQ(b.fw().stats().frames_in, 21u);
  EXPECT_EQ(b.fw().stats().bad_frames, 0u);
}

TEST(LogiFirmware, StationAcceptsTheConfiguredListOnly) {
  LogiBench b;
  for (const auto& [command, station] :
       std::vector<std::pair<std::string, int>>{{"GS:001", 1}, {"GS:002", 2}}) {
    EXPECT_EQ(b.ask(command), "FB:GS:1");
    EXPECT_EQ(b.state().station, station) << command;
  }
  expect_answers(b, {
                        {"GS:003", "FB:GS:0"},
                        {"GS:000", "FB:GS:0"},
                        {"GS:999", "FB:GS:0"},
                        {"GS:x", "FB:GS:0"},
                        {"GS:1", "FB:GS:0"},
                    });
  EXPECT_EQ(b.state().station, 2);

  LogiBench seven(LogiConfig{.stations = {1, 2, 7}});
  EXPECT_EQ(seven.ask("GS:007"), "FB:GS:1");
  EXPECT_EQ(seven.state().station, 7);
}

TEST(LogiFirmware, ModeSwitchesBothWaysAndRefusesNonsense) {
  LogiBench b;
  EXPECT_EQ(b.ask("MD:MAN"), "FB:MD:1");
  EXPECT_EQ(b.state().mode, Mode::manual);
  // MAN again (already there), then AUTO.
  expect_answers(b, {{"MD:MAN", "FB:MD:1"}, {"MD:AUTO", "FB:MD:1"}});
  EXPECT_EQ(b.state().mode, Mode::automatic);
  expect_answers(b, {{"MD:HALF", "FB:MD:0"}, {"MD:auto", "FB:MD:0"}});
  EXPECT_EQ(b.state().mode, Mode::automatic);
}

TEST(LogiFirmware, EveryMoveIsRefusedInAutoAndNothingMoves) {
  LogiBench b;
  for (const Direction d : logi::kAllDirections) {
    EXPECT_EQ(b.ask("MV:" + std::string(logi::to_string(d))), "FB:MV:0") << logi::to_string(d);
  }
  b.run_for(seconds(1));
  EXPECT_EQ(b.state().manual, Direction::stop);
  EXPECT_NEAR(b.pose().x_m, 1.2, 1e-6);
  EXPECT_EQ(b.fw().next_wakeup(), at_ms(1500));  // only STAT: the control loop sleeps
}

TEST(LogiFirmware, MalformedMoveAndRunAreRefused) {
  LogiBench b;
  b.ask("MD:MAN");
  expect_answers(b, {
                        {"MV:UP", "FB:MV:0"},
                        {"MV:fwd", "FB:MV:0"},
                        {"ST:GO", "FB:ST:0"},
                        {"ST:", "FB:ST:0"},
                    });
  EXPECT_EQ(b.state().manual, Direction::stop);
}

TEST(LogiFirmware, RunNeedsAutoModeAndAStation) {
  LogiBench b;
  EXPECT_EQ(b.ask("ST:RUN"), "FB:ST:0");  // no station yet
  EXPECT_FALSE(b.state().running);
  b.ask("GS:001");
  b.ask("MD:MAN");
  EXPECT_EQ(b.ask("ST:RUN"), "FB:ST:0");  // manual mode
  EXPECT_FALSE(b.state().running);
  b.ask("MD:AUTO");
  EXPECT_EQ(b.ask("ST:RUN"), "FB:ST:1");
  EXPECT_TRUE(b.state().running);
  EXPECT_EQ(b.ask("ST:RUN"), "FB:ST:1");  // already running: still fine
  EXPECT_EQ(b.fw().summary(), "AUTO RUN STA 001 SP 50 DIS 232");
}

TEST(LogiFirmware, StopAlwaysSucceeds) {
  LogiBench b;
  EXPECT_EQ(b.ask("ST:STOP"), "FB:ST:1");
  b.ask("MD:MAN");
  EXPECT_EQ(b.ask("ST:STOP"), "FB:ST:1");
}

// ---------------------------------------------------------------- bad input

TEST(LogiFirmware, ABadChecksumIsDroppedAndTheConnectionStays) {
  LogiBench b;
  EXPECT_EQ(b.ask_raw("LOGI:SP:030:D6#"), "");
  EXPECT_EQ(b.state().speed_percent, 50);
  EXPECT_EQ(b.fw().stats().bad_frames, 1u);
  EXPECT_TRUE(b.fw().connected());
  EXPECT_FALSE(b.client().closed.has_value());
  EXPECT_EQ(b.ask_raw("LOGI:SP:030:D5#"), "FB:SP:1");
  // A malformed payload behind a bad checksum is noise too: no answer.
  EXPECT_EQ(b.ask_raw("LOGI:SP:abc:00#"), "");
  EXPECT_EQ(b.ask_raw("LOGI:SP:030:ZZ#"), "");
  EXPECT_EQ(b.fw().stats().bad_frames, 3u);
  b.run_until(at_ms(500));
  EXPECT_EQ(b.stats().size(), 1u);  // telemetry goes on
}

TEST(LogiFirmware, ALowercaseChecksumIsDroppedUnlessConfigured) {
  LogiBench strict;
  EXPECT_EQ(strict.ask_raw("LOGI:SP:030:d5#"), "");
  EXPECT_EQ(strict.fw().stats().bad_frames, 1u);
  LogiBench lenient(LogiConfig{.accept_lowercase_checksum = true});
  EXPECT_EQ(lenient.ask_raw("LOGI:SP:030:d5#"), "FB:SP:1");
  EXPECT_EQ(lenient.state().speed_percent, 30);
}

TEST(LogiFirmware, GarbageUnknownCodesAndOversizedRunsAreDroppedAndCounted) {
  LogiBench b;
  EXPECT_EQ(b.ask_raw("hello"), "");
  expect_answers(b, {
                        {"ZZ:1", ""},
                        {"SPEED:050", ""},
                        {"NOCOLON", ""},
                    });
  EXPECT_EQ(b.fw().stats().bad_frames, 4u);
  // 256 bytes at most are held: the first 256 come out as one oversized piece...
  EXPECT_EQ(b.ask_raw("LOGI:" + std::string(400, 'A')), "");
  EXPECT_EQ(b.fw().stats().bad_frames, 5u);
  // ...and the rest, with a CR LF, when the next header shows where it ends.
  EXPECT_EQ(b.ask_raw("\r\n" + logi::frame_text("SP:040")), "FB:SP:1");
  EXPECT_EQ(b.fw().stats().bad_frames, 6u);
  EXPECT_EQ(b.state().speed_percent, 40);
  EXPECT_TRUE(b.fw().connected());
}

TEST(LogiFirmware, TheCarsOwnFramesFromTheClientAreDropped) {
  LogiBench b;
  EXPECT_EQ(b.ask_raw(logi::encode_text(logi::Feedback{logi::Command::sp, true})), "");
  EXPECT_EQ(b.ask_raw(logi::encode_text(logi::Status{})), "");
  EXPECT_EQ(b.ask("STAT:SP:abc"), "");
  EXPECT_EQ(b.fw().stats().bad_frames, 3u);
  EXPECT_EQ(b.fw().stats().frames_in, 0u);
}

TEST(LogiFirmware, SplitAndStickyFramesAreEachAnsweredOnce) {
  LogiBench b;
  const std::string frame = logi::frame_text("SP:070");
  b.send_raw(frame.substr(0, 6));
  EXPECT_EQ(b.answers(), "");
  b.send_raw(frame.substr(6));
  EXPECT_EQ(b.answers(), "FB:SP:1");
  EXPECT_EQ(b.ask_raw(logi::frame_text("MD:MAN") + logi::frame_text("MV:FWD") +
                      logi::frame_text("GS:005")),
            "FB:MD:1 FB:MV:1 FB:GS:0");
  EXPECT_EQ(b.state().speed_percent, 70);
}

// ---------------------------------------------------------------- construction

TEST(LogiFirmware, RefusesAVehicleWithoutMecanumWheels) {
  sim::World world({sim::default_warehouse_arena()});
  sim::Vehicle& robot = world.add_vehicle(sim::arduino_robot());
  EXPECT_THROW(LogiFirmware(world, robot), std::invalid_argument);
}

TEST(LogiFirmware, RefusesConfigValuesOutOfRange) {
  sim::World world({sim::default_warehouse_arena()});
  sim::Vehicle& car = world.add_vehicle(sim::logi_car());
  const auto make = [&](auto change) {
    LogiConfig config;
    change(config);
    return LogiFirmware(world, car, config);
  };
  EXPECT_THROW(make([](LogiConfig& c) { c.stations = {1, 1000}; }), std::invalid_argument);
  EXPECT_THROW(make([](LogiConfig& c) { c.boot_speed_percent = 101; }), std::invalid_argument);
  EXPECT_THROW(make([](LogiConfig& c) { c.stat_period = {}; }), std::invalid_argument);
  EXPECT_THROW(make([](LogiConfig& c) { c.control_period = {}; }), std::invalid_argument);
  EXPECT_THROW(make([](LogiConfig& c) { c.obstacle_stop_cm = -1; }), std::invalid_argument);
  EXPECT_NO_THROW(make([](LogiConfig& c) { c.boot_mode = Mode::manual; }));
}

TEST(LogiFirmware, BootSettingsAreConfigurable) {
  LogiConfig config;
  config.boot_speed_percent = 30;
  config.boot_mode = Mode::manual;
  LogiBench b(config, open_floor());
  EXPECT_EQ(b.state().speed_percent, 30);
  EXPECT_EQ(b.ask("MV:FWD"), "FB:MV:1");
  EXPECT_EQ(b.fw().summary(), "MAN FWD SP 30 DIS 186");
}

}  // namespace
}  // namespace hil::mocks::test
