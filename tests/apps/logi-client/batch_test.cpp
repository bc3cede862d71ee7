// logi-client in batch mode as a user runs it: against `hil mock logi` over
// real TCP, reading its output, its exit status and the communication log
// it writes. Every wait is bounded.

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "apps/logi-client/batch.hpp"
#include "tests/apps/logi-client/logi_client_support.hpp"

namespace hil::test {
namespace {

using namespace std::chrono_literals;

struct LogiClientBatch : LogiClientTest {
  // A port nothing listens on for the runs that must not get as far as
  // connecting.
  LogiClientBatch() : LogiClientTest("logi-client-batch") { port = "1"; }
};

TEST_F(LogiClientBatch, TheManualDriveScriptDrivesTheMockCarAndExits0) {
  ASSERT_NO_FATAL_FAILURE(start_car());
  const auto log = dir / "run.txt";
  HilProcess client(LOGI_CLIENT_BINARY,
                    on_port({"--log", log.string(), "--script",
                             "scenarios/clients/logi-client/manual-drive.txt"}));
  ASSERT_NO_FATAL_FAILURE(expect_exit_status(client, 0, 30s));
  const std::string& out = client.output();
  // The car really drove: its telemetry showed MAN FWD, both in the
  // program's output and in the log of what the car sent.
  expect_contains(out, {"link connected", "ok   press FWD", "ok   release", "ok   disconnect",
                        "car  MODE MAN  RUN 0  STA 000  SP 40  MAN FWD"});
  EXPECT_TRUE(std::regex_search(out, std::regex(R"(\[ *\d+\.\d{3} s\] ok   speed 40)"))) << out;
  EXPECT_EQ(out.find("FAIL"), std::string::npos) << out;
  const std::string text = read_file(log);
  expect_contains(text, {"TX   LOGI:MV:FWD:23#", "RX   LOGI:FB:MV:1:"});
  EXPECT_TRUE(std::regex_search(text, std::regex("RX   LOGI:STAT:[^ ]*MAN:FWD"))) << text;
  EXPECT_TRUE(std::regex_search(text, std::regex("RX   LOGI:STAT:[^ ]*MAN:CW"))) << text;
}

TEST_F(LogiClientBatch, AMoveTheCarRefusesExits1WithTheReasonAndRunsNothingAfterIt) {
  ASSERT_NO_FATAL_FAILURE(
      start_car({"--behaviours", "scenarios/clients/logi-client/car-refuses-moves.yaml"}));
  HilProcess client(LOGI_CLIENT_BINARY, on_port({"connect", "speed 50", "mode MAN", "press FWD",
                                                 "wait 1s", "release"}));
  ASSERT_NO_FATAL_FAILURE(expect_exit_status(client, 1, 20s));
  const std::string& out = client.output();
  expect_contains(out, {"ok   mode MAN", "note Not in manual mode, switching to MAN",
                        "FAIL press FWD: rejected by the car (FB:MV:0)"});
  EXPECT_EQ(out.find("wait 1s"), std::string::npos) << out;
}

TEST_F(LogiClientBatch, ContinueOnErrorRunsEveryActionAndStillExits1) {
  ASSERT_NO_FATAL_FAILURE(start_car());
  HilProcess client(LOGI_CLIENT_BINARY, on_port({"--continue-on-error", "connect", "station 7",
                                                 "speed 30", "disconnect"}));
  ASSERT_NO_FATAL_FAILURE(expect_exit_status(client, 1, 20s));
  expect_contains(client.output(), {"FAIL station 7: rejected by the car (FB:GS:0)",
                                    "ok   speed 30", "ok   disconnect"});
}

TEST_F(LogiClientBatch, AScriptWithATypoExits2NamingFileLineAndColumn) {
  const auto out = expect_script_refused(
      "drive.txt", "# drive\nconnect\nspeed 50\nmode MAN\npress  FORWARD\n",
      ":5:8: expected a direction (STOP, FWD, BWD, LEFT, RIGHT, LF, RF, LB, RB, CW, CCW), got "
      "'FORWARD'");
  EXPECT_EQ(out.find("connect"), std::string::npos) << "nothing ran";

  for (const auto& [args, says] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"connect", "spead 50"}, "<command line>:2:1: unknown action 'spead'"},
           {{"--script", (dir / "nope.txt").string()}, "nope.txt: cannot read the script"},
           {{"--log", "run.xml", "connect"}, ".txt, .csv or .ndjson"}}) {
    HilProcess refused(LOGI_CLIENT_BINARY, args);
    EXPECT_EQ(refused.wait_exit(10s), 2) << refused.output();
    expect_contains(refused.output(), {says});
  }
}

TEST_F(LogiClientBatch, EveryBadLineOfAScriptIsReportedInOrder) {
  const auto out = expect_script_refused(
      "typos.txt", "connect\nspead 50\nmode MAN\npress  FORWARD\n", ":2:1: unknown action 'spead'");
  const std::string script = (dir / "typos.txt").string();
  const auto first = out.find(script + ":2:1: unknown action 'spead'");
  const auto second = out.find(script + ":4:8: expected a direction");
  ASSERT_NE(second, std::string::npos) << out;
  EXPECT_LT(first, second) << out;
  EXPECT_EQ(out.find("ok   connect"), std::string::npos) << "nothing ran: " << out;
}

TEST_F(LogiClientBatch, WithNoCarListeningConnectFailsAfterItsBoundAndExits1) {
  const ClosedPort closed;
  HilProcess client(LOGI_CLIENT_BINARY,
                    {"--port", closed.port(), "--connect-timeout", "2s", "connect", "speed 50"});
  ASSERT_NO_FATAL_FAILURE(expect_exit_status(client, 1, 20s));
  const std::string& out = client.output();
  expect_contains(out, {"WARN not connected (lost or refused); reconnecting",
                        "FAIL connect: not connected after 2s"});
  EXPECT_EQ(out.find("speed 50"), std::string::npos) << out;
}

TEST_F(LogiClientBatch, CtrlCDuringAWaitStopsTheCarAndExits130) {
  ASSERT_NO_FATAL_FAILURE(start_car());
  const auto log = dir / "run.ndjson";
  HilProcess client(LOGI_CLIENT_BINARY, on_port({"--log", log.string(), "connect", "speed 50",
                                                 "mode MAN", "press FWD", "wait 30s"}));
  ASSERT_TRUE(client.wait_for_line("ok   press FWD", 15s)) << client.output();
  const auto status = client.interrupt(10s);
  ASSERT_TRUE(status) << client.output();
  EXPECT_EQ(*status, 130) << client.output();
  expect_contains(client.output(), {"interrupted (SIGINT): stopping", "FAIL wait 30s: cancelled",
                                    "emergency stop: MV:STOP"});
  // The car got the MV:STOP and answered it before the client hung up.
  const std::string text = read_file(log);
  const auto stop = text.find(R"("kind":"TX","raw":"LOGI:MV:STOP:88#")");
  ASSERT_NE(stop, std::string::npos) << text;
  EXPECT_NE(text.find(R"("kind":"RX","raw":"LOGI:FB:MV:1:)", stop), std::string::npos) << text;
}

TEST_F(LogiClientBatch, ActionsCanComeFromStandardInput) {
  ASSERT_NO_FATAL_FAILURE(start_car());
  HilProcess client(LOGI_CLIENT_BINARY, on_port({"--script", "-"}));
  client.write_stdin("connect\nspeed 60\nmode AUTO\nstation 001\nstop\nwait 1200ms\ndisconnect\n");
  client.close_stdin();
  ASSERT_NO_FATAL_FAILURE(expect_exit_status(client, 0, 20s));
  expect_contains(client.output(), {"ok   station 001", "car  MODE AUTO  RUN 0  STA 001  SP 60"});
}

// ---- the program's pieces, without a process ----

TEST(LogiClientBatchPieces, ResultLinesShowTimeVerdictActionAndReason) {
  client::logi::ActionResult ok;
  ok.text = "speed 50";
  ok.ok = true;
  ok.ended = std::chrono::milliseconds(1234);
  EXPECT_EQ(apps::logi_client::BatchReporter::result_line(ok), "[  1.234 s] ok   speed 50");
  client::logi::ActionResult bad = ok;
  bad.text = "press FWD";
  bad.ok = false;
  bad.reason = "rejected by the car (FB:MV:0)";
  bad.ended = std::chrono::seconds(62);
  EXPECT_EQ(apps::logi_client::BatchReporter::result_line(bad),
            "[ 62.000 s] FAIL press FWD: rejected by the car (FB:MV:0)");
}

TEST(LogiClientBatchPieces, TelemetryIsPrintedOnlyWhenAFieldTheOperatorActsOnChanges) {
  apps::logi_client::BatchReporter reporter;
  protocol::logi::Status s;
  s.speed_percent = 50;
  s.distance_cm = 232;
  const auto first =
      reporter.event_line(std::chrono::milliseconds(500), client::logi::StatusEvent{s});
  ASSERT_TRUE(first);
  EXPECT_EQ(*first, "[  0.500 s] car  MODE AUTO  RUN 0  STA 000  SP 50  MAN STOP  DIS 232 cm");
  s.distance_cm = 180;  // the sonar alone: no line
  EXPECT_FALSE(reporter.event_line(std::chrono::seconds(1), client::logi::StatusEvent{s}));
  s.running = true;
  s.station = 2;
  const auto running = reporter.event_line(std::chrono::seconds(2), client::logi::StatusEvent{s});
  ASSERT_TRUE(running);
  EXPECT_NE(running->find("RUN 1  STA 002"), std::string::npos) << *running;
  EXPECT_EQ(*reporter.event_line(std::chrono::seconds(3), client::logi::StaleEvent{true}),
            "[  3.000 s] WARN telemetry stale: no STAT for more than 2 s");
}

TEST(LogiClientBatchPieces, ArgumentsAreOneActionEachAndErrorsNameTheArgument) {
  const auto ok = apps::logi_client::load_script_arguments({"connect", "speed 50 # half", ""});
  ASSERT_TRUE(ok.ok()) << ok.errors.front().to_string();
  ASSERT_EQ(ok.steps.size(), 2u);
  EXPECT_EQ(ok.steps[1].line, 2);
  EXPECT_EQ(ok.steps[1].text, "speed 50");
  const auto bad = apps::logi_client::load_script_arguments({"connect", "mode", "run", "spead"});
  ASSERT_EQ(bad.errors.size(), 2u);
  EXPECT_EQ(bad.errors[0].to_string(), "<command line>:2:5: expected MAN or AUTO after 'mode'");
  EXPECT_EQ(bad.errors[1].to_string().rfind("<command line>:4:1: unknown action 'spead'", 0), 0u)
      << bad.errors[1].to_string();
}

}  // namespace
}  // namespace hil::test
