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
#include <vector>

#include "apps/logi-client/batch.hpp"
#include "tests/apps/client_program_support.hpp"

namespace hil::test {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;

/// `hil mock logi` on a free port (the same car every run).
struct MockLogi : MockCar {
  explicit MockLogi(std::vector<std::string> extra = {})
      : MockCar(mock_on_tcp_args("logi", with_seed(std::move(extra))), kTcpReady) {}
  static std::vector<std::string> with_seed(std::vector<std::string> extra) {
    extra.insert(extra.begin(), {"--seed", "1"});
    return extra;
  }
};

TEST(LogiClientBatch, TheManualDriveScriptDrivesTheMockCarAndExits0) {
  MockLogi car;
  ASSERT_FALSE(car.port().empty()) << car.process().output();
  const TempDir temp("logi-client-manual");
  const auto& dir = temp.path();
  const auto log = dir / "run.txt";
  HilProcess client(LOGI_CLIENT_BINARY, {"--port", car.port(), "--log", log.string(), "--script",
                                         "scenarios/clients/logi-client/manual-drive.txt"});
  const auto status = client.wait_exit(30s);
  ASSERT_TRUE(status) << client.output();
  EXPECT_EQ(*status, 0) << client.output();
  const std::string& out = client.output();
  EXPECT_NE(out.find("link connected"), std::string::npos) << out;
  EXPECT_TRUE(std::regex_search(out, std::regex(R"(\[ *\d+\.\d{3} s\] ok   speed 40)"))) << out;
  EXPECT_NE(out.find("ok   press FWD"), std::string::npos) << out;
  EXPECT_NE(out.find("ok   release"), std::string::npos) << out;
  EXPECT_NE(out.find("ok   disconnect"), std::string::npos) << out;
  EXPECT_EQ(out.find("FAIL"), std::string::npos) << out;
  // The car really drove: its telemetry showed MAN FWD, both in the
  // program's output and in the log of what the car sent.
  EXPECT_NE(out.find("car  MODE MAN  RUN 0  STA 000  SP 40  MAN FWD"), std::string::npos) << out;
  const std::string text = read_file(log);
  EXPECT_NE(text.find("TX   LOGI:MV:FWD:23#"), std::string::npos) << text;
  EXPECT_NE(text.find("RX   LOGI:FB:MV:1:"), std::string::npos) << text;
  EXPECT_TRUE(std::regex_search(text, std::regex("RX   LOGI:STAT:[^ ]*MAN:FWD"))) << text;
  EXPECT_TRUE(std::regex_search(text, std::regex("RX   LOGI:STAT:[^ ]*MAN:CW"))) << text;
}

TEST(LogiClientBatch, AMoveTheCarRefusesExits1WithTheReasonAndRunsNothingAfterIt) {
  MockLogi car({"--behaviours", "scenarios/clients/logi-client/car-refuses-moves.yaml"});
  ASSERT_FALSE(car.port().empty()) << car.process().output();
  HilProcess client(LOGI_CLIENT_BINARY, {"--port", car.port(), "connect", "speed 50", "mode MAN",
                                         "press FWD", "wait 1s", "release"});
  const auto status = client.wait_exit(20s);
  ASSERT_TRUE(status) << client.output();
  EXPECT_EQ(*status, 1) << client.output();
  const std::string& out = client.output();
  EXPECT_NE(out.find("ok   mode MAN"), std::string::npos) << out;
  EXPECT_NE(out.find("note Not in manual mode, switching to MAN"), std::string::npos) << out;
  EXPECT_NE(out.find("FAIL press FWD: rejected by the car (FB:MV:0)"), std::string::npos) << out;
  EXPECT_EQ(out.find("wait 1s"), std::string::npos) << out;
}

TEST(LogiClientBatch, ContinueOnErrorRunsEveryActionAndStillExits1) {
  MockLogi car;
  ASSERT_FALSE(car.port().empty()) << car.process().output();
  HilProcess client(LOGI_CLIENT_BINARY, {"--port", car.port(), "--continue-on-error", "connect",
                                         "station 7", "speed 30", "disconnect"});
  const auto status = client.wait_exit(20s);
  ASSERT_TRUE(status) << client.output();
  EXPECT_EQ(*status, 1) << client.output();
  EXPECT_NE(client.output().find("FAIL station 7: rejected by the car (FB:GS:0)"),
            std::string::npos)
      << client.output();
  EXPECT_NE(client.output().find("ok   speed 30"), std::string::npos) << client.output();
  EXPECT_NE(client.output().find("ok   disconnect"), std::string::npos) << client.output();
}

TEST(LogiClientBatch, AScriptWithATypoExits2NamingFileLineAndColumn) {
  const TempDir temp("logi-client-typo");
  const auto& dir = temp.path();
  const auto script = dir / "drive.txt";
  std::ofstream(script) << "# drive\nconnect\nspeed 50\nmode MAN\npress  FORWARD\n";
  HilProcess client(LOGI_CLIENT_BINARY, {"--port", "1", "--script", script.string()});
  const auto status = client.wait_exit(10s);
  ASSERT_TRUE(status) << client.output();
  EXPECT_EQ(*status, 2) << client.output();
  EXPECT_NE(client.output().find(script.string() +
                                 ":5:8: expected a direction (STOP, FWD, BWD, LEFT, RIGHT, LF, "
                                 "RF, LB, RB, CW, CCW), got 'FORWARD'"),
            std::string::npos)
      << client.output();
  EXPECT_EQ(client.output().find("connect"), std::string::npos) << "nothing ran";

  HilProcess args(LOGI_CLIENT_BINARY, {"connect", "spead 50"});
  EXPECT_EQ(args.wait_exit(10s), 2) << args.output();
  EXPECT_NE(args.output().find("<command line>:2:1: unknown action 'spead'"), std::string::npos)
      << args.output();

  HilProcess missing(LOGI_CLIENT_BINARY, {"--script", (dir / "nope.txt").string()});
  EXPECT_EQ(missing.wait_exit(10s), 2) << missing.output();
  EXPECT_NE(missing.output().find("nope.txt: cannot read the script"), std::string::npos)
      << missing.output();

  HilProcess bad_log(LOGI_CLIENT_BINARY, {"--log", "run.xml", "connect"});
  EXPECT_EQ(bad_log.wait_exit(10s), 2) << bad_log.output();
  EXPECT_NE(bad_log.output().find(".txt, .csv or .ndjson"), std::string::npos) << bad_log.output();
}

TEST(LogiClientBatch, WithNoCarListeningConnectFailsAfterItsBoundAndExits1) {
  HilProcess client(LOGI_CLIENT_BINARY,
                    {"--port", free_tcp_port(), "--connect-timeout", "2s", "connect", "speed 50"});
  const auto status = client.wait_exit(20s);
  ASSERT_TRUE(status) << client.output();
  EXPECT_EQ(*status, 1) << client.output();
  const std::string& out = client.output();
  EXPECT_NE(out.find("WARN not connected (lost or refused); reconnecting"), std::string::npos)
      << out;
  EXPECT_NE(out.find("FAIL connect: not connected after 2s"), std::string::npos) << out;
  EXPECT_EQ(out.find("speed 50"), std::string::npos) << out;
}

TEST(LogiClientBatch, CtrlCDuringAWaitStopsTheCarAndExits130) {
  MockLogi car;
  ASSERT_FALSE(car.port().empty()) << car.process().output();
  const TempDir temp("logi-client-sigint");
  const auto& dir = temp.path();
  const auto log = dir / "run.ndjson";
  HilProcess client(LOGI_CLIENT_BINARY, {"--port", car.port(), "--log", log.string(), "connect",
                                         "speed 50", "mode MAN", "press FWD", "wait 30s"});
  ASSERT_TRUE(client.wait_for_line("ok   press FWD", 15s)) << client.output();
  const auto status = client.interrupt(10s);
  ASSERT_TRUE(status) << client.output();
  EXPECT_EQ(*status, 130) << client.output();
  const std::string& out = client.output();
  EXPECT_NE(out.find("interrupted (SIGINT): stopping"), std::string::npos) << out;
  EXPECT_NE(out.find("FAIL wait 30s: cancelled"), std::string::npos) << out;
  EXPECT_NE(out.find("emergency stop: MV:STOP"), std::string::npos) << out;
  // The car got the MV:STOP and answered it before the client hung up.
  const std::string text = read_file(log);
  const auto stop = text.find(R"("kind":"TX","raw":"LOGI:MV:STOP:88#")");
  ASSERT_NE(stop, std::string::npos) << text;
  EXPECT_NE(text.find(R"("kind":"RX","raw":"LOGI:FB:MV:1:)", stop), std::string::npos) << text;
}

TEST(LogiClientBatch, ActionsCanComeFromStandardInput) {
  MockLogi car;
  ASSERT_FALSE(car.port().empty()) << car.process().output();
  HilProcess client(LOGI_CLIENT_BINARY, {"--port", car.port(), "--script", "-"});
  client.write_stdin("connect\nspeed 60\nmode AUTO\nstation 001\nstop\nwait 1200ms\ndisconnect\n");
  client.close_stdin();
  const auto status = client.wait_exit(20s);
  ASSERT_TRUE(status) << client.output();
  EXPECT_EQ(*status, 0) << client.output();
  EXPECT_NE(client.output().find("ok   station 001"), std::string::npos) << client.output();
  EXPECT_NE(client.output().find("car  MODE AUTO  RUN 0  STA 001  SP 60"), std::string::npos)
      << client.output();
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
            "[  3.000 s] WARN telemetry stale: no STAT for 2 s or more");
}

TEST(LogiClientBatchPieces, ArgumentsAreOneActionEachAndErrorsNameTheArgument) {
  const auto ok = apps::logi_client::load_script_arguments({"connect", "speed 50 # half", ""});
  ASSERT_TRUE(ok.ok()) << ok.error;
  ASSERT_EQ(ok.steps.size(), 2u);
  EXPECT_EQ(ok.steps[1].line, 2);
  EXPECT_EQ(ok.steps[1].text, "speed 50");
  const auto bad = apps::logi_client::load_script_arguments({"connect", "mode", "run"});
  EXPECT_EQ(bad.error, "<command line>:2:5: expected MAN or AUTO after 'mode'");
}

}  // namespace
}  // namespace hil::test
