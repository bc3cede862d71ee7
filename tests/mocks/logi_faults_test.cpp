// The LOGI car's mock firmware when things go wrong, under the virtual-time
// driver: the fault state, scripted behaviours (reject, ignore, muted
// telemetry, sent frames, hang-ups) and the client leaving.

#include "mocks/logi.hpp"

#include <gtest/gtest.h>

#include <array>
#include <optional>

#include "protocol/common/bytes.hpp"
#include "protocol/logi/codec.hpp"
#include "tests/mocks/logi_bench.hpp"

namespace hil::mocks::test {
namespace {

using link::milliseconds;
using link::seconds;
using logi::Direction;

// ---------------------------------------------------------------- fault and behaviours

TEST(LogiFirmware, TheFaultStateStopsTheCarAndRefusesMotion) {
  LogiBench b;
  b.start_run("002");
  b.fw().arm(Behaviour{"", When{at_ms(1000), "", 1}, EnterFault{}});
  b.run_until(at_ms(1000));
  EXPECT_TRUE(b.fw().in_fault());
  EXPECT_FALSE(b.state().running);
  EXPECT_EQ(b.state().last_run_end, LogiRunEnd::fault);
  b.run_for(milliseconds(500));
  EXPECT_NEAR(speed_of(b.vehicle().velocity()), 0.0, 1e-6);
  EXPECT_EQ(b.fw().summary().substr(0, 10), "AUTO FAULT");
  EXPECT_EQ(b.ask("ST:RUN"), "FB:ST:0");
  EXPECT_EQ(b.ask("SP:080"), "FB:SP:1");  // settings still work
  expect_answers(b, {
                        {"GS:001", "FB:GS:1"},
                        {"ST:STOP", "FB:ST:1"},
                        {"MD:MAN", "FB:MD:1"},
                        {"MV:FWD", "FB:MV:0"},
                        {"MV:CW", "FB:MV:0"},
                        {"MV:STOP", "FB:MV:1"},
                    });
  const sim::Pose held = b.pose();
  b.run_for(seconds(1));
  EXPECT_EQ(b.pose(), held);
  const auto stats = b.stats();
  ASSERT_FALSE(stats.empty());
  EXPECT_FALSE(stats.back().second.running);
  EXPECT_EQ(stats.back().second.rpm, (std::array<int, 4>{0, 0, 0, 0}));

  b.fw().arm(Behaviour{"", When{}, ClearFault{}});
  b.run_for(milliseconds(1));
  EXPECT_FALSE(b.fw().in_fault());
  EXPECT_EQ(b.state().manual, Direction::stop);  // nothing restarts by itself
  expect_answers(b, {
                        {"MV:FWD", "FB:MV:1"},
                        {"MD:AUTO", "FB:MD:1"},
                        {"ST:RUN", "FB:ST:1"},
                    });
}

TEST(LogiFirmware, ARejectAnswersNegativelyWithoutEffect) {
  LogiBench b;
  b.fw().arm(Behaviour{"", When{}, Reject{"SP", 1}});
  b.run_for(milliseconds(1));
  EXPECT_EQ(b.ask("SP:030"), "FB:SP:0");
  EXPECT_EQ(b.state().speed_percent, 50);
  EXPECT_EQ(b.ask("SP:030"), "FB:SP:1");
  EXPECT_EQ(b.state().speed_percent, 30);

  b.ask("MD:MAN");
  b.fw().arm(Behaviour{"", When{}, Reject{"MV", 1}});
  b.run_for(milliseconds(1));
  EXPECT_EQ(b.ask("MV:FWD"), "FB:MV:0");
  b.run_for(milliseconds(500));
  EXPECT_EQ(b.state().manual, Direction::stop);
  EXPECT_NEAR(b.pose().x_m, 1.2, 1e-6);

  b.ask("MD:AUTO");
  b.ask("GS:001");
  b.fw().arm(Behaviour{"", When{}, Reject{"ST:RUN", 1}});
  b.run_for(milliseconds(1));
  EXPECT_EQ(b.ask("ST:STOP"), "FB:ST:1");  // another kind
  EXPECT_EQ(b.ask("ST:RUN"), "FB:ST:0");
  EXPECT_FALSE(b.state().running);
  EXPECT_EQ(b.fw().stats().rejected, 3u);
}

TEST(LogiFirmware, AnIgnoreSwallowsCommandsWithoutAnswerOrEffect) {
  LogiBench b;
  b.fw().arm(Behaviour{"", When{}, Ignore{"GS", 2, std::nullopt}});
  b.run_for(milliseconds(1));
  EXPECT_EQ(b.ask("GS:001"), "");
  EXPECT_EQ(b.ask("GS:x"), "");  // a malformed GS is swallowed too
  EXPECT_EQ(b.state().station, 0);
  EXPECT_EQ(b.ask("SP:030"), "FB:SP:1");
  EXPECT_EQ(b.ask("GS:001"), "FB:GS:1");
  EXPECT_EQ(b.fw().stats().ignored, 2u);
}

TEST(LogiFirmware, MutedTelemetryStillAnswersCommands) {
  LogiBench b;
  b.fw().arm(Behaviour{"", When{at_ms(600), "", 1}, MuteTelemetry{milliseconds(1000)}});
  b.run_until(at_ms(1200));
  EXPECT_EQ(b.ask("SP:040"), "FB:SP:1");
  b.run_until(at_ms(2500));
  const auto stats = b.stats();
  // 500 went out; 1000 and 1500 fell in the mute (600..1600); 2000 and 2500 did not.
  ASSERT_EQ(stats.size(), 3u);
  EXPECT_EQ(stats[0].first, at_ms(500));
  EXPECT_EQ(stats[1].first, at_ms(2000));
  EXPECT_EQ(stats[2].first, at_ms(2500));
  EXPECT_EQ(stats[1].second.speed_percent, 40);
}

TEST(LogiFirmware, ScriptedFramesAndHangUpsReachTheClient) {
  LogiBench b;
  b.fw().arm(Behaviour{"", When{std::nullopt, "SP", 1},
                       SendBytes{protocol::to_bytes(logi::frame_text("FB:SP:0"))}});
  EXPECT_EQ(b.ask("SP:030"), "FB:SP:1 FB:SP:0");
  b.fw().arm(Behaviour{"", When{std::nullopt, "MD", 1}, CloseConnection{}});
  EXPECT_EQ(b.ask("MD:MAN"), "FB:MD:1");
  b.run_for(milliseconds(5));
  EXPECT_TRUE(b.client().closed.has_value());
  EXPECT_FALSE(b.fw().connected());
}

// ---------------------------------------------------------------- disconnect

TEST(LogiFirmware, MotionGoesOnWhenTheClientLeavesByDefault) {
  ManualLogiBench b;
  b.ask("MV:LEFT");
  b.run_for(milliseconds(500));
  b.client().pipe->close();
  b.run_for(milliseconds(10));
  EXPECT_FALSE(b.fw().connected());
  const sim::Pose left_at = b.pose();
  b.run_for(seconds(1));
  EXPECT_NEAR(b.pose().y_m - left_at.y_m, 0.25, 0.01);  // still strafing
  EXPECT_EQ(b.state().manual, Direction::left);
  EXPECT_GE(b.car().world().time(), b.now() - milliseconds(10));
}

TEST(LogiFirmware, StopOnDisconnectHaltsManualMotionAndEndsARun) {
  LogiConfig config;
  config.stop_on_disconnect = true;
  {
    ManualLogiBench b(config);
    b.ask("MV:LEFT");
    b.run_for(milliseconds(500));
    b.client().pipe->close();
    b.run_for(milliseconds(500));
    EXPECT_EQ(b.state().manual, Direction::stop);
    EXPECT_NEAR(speed_of(b.vehicle().velocity()), 0.0, 1e-6);
  }
  {
    LogiBench b(config);
    b.start_run("002");
    b.run_for(milliseconds(500));
    b.client().pipe->close();
    b.run_for(milliseconds(500));
    EXPECT_FALSE(b.state().running);
    EXPECT_EQ(b.state().last_run_end, LogiRunEnd::disconnect);
    EXPECT_TRUE(b.state().station_armed);
    EXPECT_NEAR(speed_of(b.vehicle().velocity()), 0.0, 1e-6);
  }
}

TEST(LogiFirmware, AnAutoRunFinishesWithNoClientConnected) {
  LogiBench b;
  b.start_run("001");
  b.client().pipe->close();
  b.run_until(at_ms(10000));
  EXPECT_FALSE(b.fw().connected());
  EXPECT_EQ(b.state().last_run_end, LogiRunEnd::arrived);
  EXPECT_NEAR(b.pose().x_m, 2.0, 0.05);
}

}  // namespace
}  // namespace hil::mocks::test
