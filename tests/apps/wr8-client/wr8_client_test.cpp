// wr8-client run as a user runs it, against `hil mock wr8` over real TCP:
// a batch of actions, a wrong login string, the interactive mode through a
// pipe, scripts (the shipped examples and a typo), nothing listening, and
// Ctrl-C. Waits are bounded and generous; no upper bound on durations.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "tests/apps/client_program_support.hpp"

namespace hil::test {
namespace {

using namespace std::chrono_literals;

/// The largest `odometry_cm=N` in a log.
int max_odometry_cm(const std::string& log) {
  static const std::regex re("odometry_cm=([0-9]+)");
  int best = -1;
  for (auto it = std::sregex_iterator(log.begin(), log.end(), re); it != std::sregex_iterator();
       ++it)
    best = std::max(best, std::stoi((*it)[1].str()));
  return best;
}

/// The mock vehicle on a free port and a temp dir for files.
struct Wr8ClientCli : ClientProgramTest {
  Wr8ClientCli() : ClientProgramTest(WR8_CLIENT_BINARY, "hil-wr8-client", "9100", 20s) {}

  void start_mock() { ClientProgramTest::start_mock(mock_on_tcp_args("wr8")); }
};

TEST_F(Wr8ClientCli, ABatchLogsInDrivesTurnsAndReadsTheSettings) {
  start_mock();
  const auto log = dir / "run.ndjson";
  const auto r =
      client({"--log", log.string(), "--data", "connect", "drive 30", "turn 10", "get-settings"});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex("connect +ok +logged in: device 8, id 1")))
      << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex("drive 30 +ok +completed"))) << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex("turn 10 +ok +completed"))) << r.output;
  EXPECT_TRUE(std::regex_search(r.output,
                                std::regex("get-settings +ok +p=1.5 i=0.25 d=0.05 servo-zero=90")))
      << r.output;
  EXPECT_TRUE(contains(r.output, " data  ")) << r.output;  // --data
  // What the car did, from the DATA the client logged.
  const std::string text = read_file(log);
  EXPECT_TRUE(contains(text, "\"kind\":\"TX\"")) << text;
  EXPECT_GE(max_odometry_cm(text), 29) << text;
  EXPECT_TRUE(mock->process().wait_for_line("client")) << mock->output();
}

TEST_F(Wr8ClientCli, AWrongLoginStringFailsConnectWithTheReason) {
  start_mock();
  const auto r = client({"--auth", "WRONG-AUTH", "connect", "drive 10"});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex("connect +FAIL +closed before AUTH-REPLY")))
      << r.output;
  EXPECT_FALSE(contains(r.output, "drive 10")) << r.output;  // the batch stopped
}

TEST_F(Wr8ClientCli, KeepGoingRunsTheRestOfTheBatchAfterAFailureAndStillExits1) {
  start_mock();
  const auto r = client({"--keep-going", "--auth", "WRONG-AUTH", "connect", "drive 10"});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex("connect +FAIL +closed before AUTH-REPLY")))
      << r.output;
  // The batch went on: the drive ran (and failed, there being no session).
  EXPECT_TRUE(std::regex_search(r.output, std::regex("drive 10 +FAIL"))) << r.output;
}

TEST_F(Wr8ClientCli, InteractiveThroughAPipeDrivesShowsStateAndSavesTheLog) {
  start_mock();
  const auto csv = dir / "session.csv";
  HilProcess p(WR8_CLIENT_BINARY, {"--port", port});
  ASSERT_TRUE(
      p.write_stdin("connect\ndrive 20\nbogus 1\nstate\nsave-log " + csv.string() + "\nquit\n"));
  ASSERT_NO_FATAL_FAILURE(expect_exit_status(p, 0, 20s));
  const std::string& out = p.output();
  EXPECT_FALSE(contains(out, "wr8> ")) << out;  // no prompt for a pipe
  EXPECT_TRUE(std::regex_search(out, std::regex("task drive \\(COI 0\\) started"))) << out;
  EXPECT_TRUE(std::regex_search(out, std::regex("drive 20 +ok +completed"))) << out;
  EXPECT_TRUE(contains(out, "error: column 1: unknown action 'bogus'")) << out;
  // The state printed after the drive has its distance.
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex("odometry: +([0-9]+) cm"))) << out;
  EXPECT_GE(std::stoi(m[1].str()), 19) << out;
  expect_contains(out, {"connection: connected", "battery:    100 %"});
  const std::string text = read_file(csv);
  EXPECT_EQ(text.rfind("time_ms,kind,raw,description", 0), 0u) << text;
  // AUTH, its string masked: the log never holds it.
  EXPECT_TRUE(contains(text, "\"01 ** ** ** ** ** ** ** ** ** **\"")) << text;
  EXPECT_FALSE(contains(text, "HIL-WR8-01")) << text;
  EXPECT_FALSE(contains(text, "48 49 4C 2D 57 52 38 2D 30 31")) << text;
  EXPECT_TRUE(contains(text, "\"03 00 01 04 14 00 00 00\"")) << text;  // drive 20
  EXPECT_TRUE(contains(text, "Response coi=0 completed")) << text;
}

TEST_F(Wr8ClientCli, EndOfInputEndsTheInteractiveModeWithZero) {
  start_mock();
  HilProcess p(WR8_CLIENT_BINARY, {"--port", port});
  ASSERT_TRUE(p.write_stdin("connect\nwait 200ms\nhistory\n"));
  p.close_stdin();
  ASSERT_NO_FATAL_FAILURE(expect_exit_status(p, 0, 20s));
  EXPECT_TRUE(std::regex_search(p.output(), std::regex("wait 200ms +ok"))) << p.output();
}

TEST_F(Wr8ClientCli, CtrlCDisconnectsAndExits130) {
  start_mock();
  HilProcess p(WR8_CLIENT_BINARY, {"--port", port});
  ASSERT_TRUE(p.write_stdin("connect\n"));
  ASSERT_TRUE(p.wait_for_line("logged in", 20s)) << p.output();
  const auto code = p.interrupt(20s);
  ASSERT_TRUE(code) << p.output();
  EXPECT_EQ(*code, 130) << p.output();
  EXPECT_TRUE(contains(p.output(), "interrupted")) << p.output();
}

TEST_F(Wr8ClientCli, TheShippedExampleScriptsRunAgainstTheMock) {
  start_mock();
  for (const char* name : {"drive-and-turn.wr8", "settings.wr8"}) {
    const auto r = client({"--script", std::string("scenarios/clients/wr8-client/") + name});
    EXPECT_EQ(r.exit_code, 0) << name << "\n" << r.output;
    EXPECT_FALSE(contains(r.output, "FAIL")) << r.output;
  }
}

TEST_F(Wr8ClientCli, AScriptTypoExits2WithFileLineAndColumn) {
  const auto out = expect_script_refused("typo.wr8", "connect\n  drve 30\nturn 10\n",
                                         ":2:3: unknown action 'drve'");
  EXPECT_FALSE(contains(out, "connect ")) << out;  // nothing ran
}

TEST_F(Wr8ClientCli, BadUsageExits2) {
  EXPECT_EQ(client({"--auth", "short", "connect"}).exit_code, 2);
  const auto r = client({"connect", "drive far"});
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "argument 2:7: expected a distance in cm")) << r.output;
}

TEST_F(Wr8ClientCli, NothingListeningFailsConnectAndExits1) {
  const ClosedPort closed;
  port = closed.port();
  const auto r = client({"--connect-timeout", "5", "connect", "drive 10"});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex("connect +FAIL +connect failed"))) << r.output;
}

}  // namespace
}  // namespace hil::test
