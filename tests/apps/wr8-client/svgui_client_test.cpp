// wr8-client --profile svgui-2019|svgui-head run as a user runs it, against
// `hil mock wr8 --profile ...` over real TCP: a batch of each version's
// words, the log with the length bytes, a word of another profile, a script
// typo, --keep-going, --auth refused, and each profile's default port.
// Waits are bounded and generous; no upper bound on durations.

#include <gtest/gtest.h>

#include <filesystem>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include "tests/apps/client_program_support.hpp"

namespace hil::test {
namespace {

using namespace std::chrono_literals;

struct SvguiClientCli : ClientProgramTest {
  SvguiClientCli() : ClientProgramTest(WR8_CLIENT_BINARY, "hil-wr8-svgui-client", "5556") {}

  void start_mock(const std::string& profile) {
    ClientProgramTest::start_mock(mock_on_tcp_args("wr8", {"--profile", profile}));
  }
};

TEST_F(SvguiClientCli, AHeadBatchReadsBackHoldsControlAndLogsEveryLengthByte) {
  start_mock("svgui-head");
  const auto log = dir / "head.txt";
  const auto r = client({"--profile", "svgui-head", "--log", log.string(), "--data", "connect",
                         "set-request", "set steering-p=2.5", "set-request", "control 0 0.3",
                         "wait 500ms", "control off", "disconnect"});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(
      std::regex_search(r.output, std::regex("connect +ok +logged in: device 1, id 2, WAIT")))
      << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex("set-request +ok +steering-p="))) << r.output;
  // The vehicle answers no SET; the read-back after it shows the new value.
  EXPECT_TRUE(std::regex_search(
      r.output, std::regex("set steering-p=2.5 +ok +sent; not confirmed: no ANSWER within")))
      << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex("set-request +ok +steering-p=2.5 ")))
      << r.output;
  EXPECT_TRUE(
      std::regex_search(r.output, std::regex("control 0 0.3 +ok +held: CONTROL every 100ms")))
      << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex("control off +ok +released"))) << r.output;
  EXPECT_TRUE(contains(r.output, " data  high-freq  encoder ")) << r.output;  // --data
  const std::string text = read_file(log);
  expect_contains(
      text, {"TX   0C 01 6B 6F 6E 6E 69 63 68 69 77 61 00",
             "RX   04 02 01 02 03  AuthReply device=1 id=2 state=WAIT", "TX   01 06  SetRequest"});
  EXPECT_TRUE(contains(text, "TX   19 0A 00 00 00 01 00 00 00 00 00 00 00 00 00 00 00 02 3F D3"))
      << text;  // CONTROL x 0, y 0.3
  EXPECT_FALSE(contains(text, "ERR")) << text;
}

TEST_F(SvguiClientCli, AV2019BatchDrivesTurnsAndSendsUnconfirmedSettings) {
  start_mock("svgui-2019");
  const auto r = client({"--profile", "svgui-2019", "connect", "forward 10", "wheels 5",
                         "settings p=1 i=0 d=0 servo-zero=90"});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex("forward 10 +ok +completed"))) << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex("wheels 5 +ok +completed"))) << r.output;
  EXPECT_TRUE(contains(r.output, "not confirmed: the v2019 vehicle never answers SETTINGS"))
      << r.output;
}

TEST_F(SvguiClientCli, KeepGoingRunsTheRestAfterAFailure) {
  start_mock("svgui-head");
  // Without a read-back the other eleven SET values are unknown: set fails.
  auto r = client({"--profile", "svgui-head", "connect", "set steering-p=2", "wait 10ms"});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex("set steering-p=2 +FAIL +set needs all")))
      << r.output;
  EXPECT_FALSE(contains(r.output, "wait 10ms")) << r.output;
  r = client(
      {"--keep-going", "--profile", "svgui-head", "connect", "set steering-p=2", "wait 10ms"});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(std::regex_search(r.output, std::regex("wait 10ms +ok"))) << r.output;
}

TEST_F(SvguiClientCli, AWordOfAnotherProfileOrAScriptTypoExits2WithItsPlace) {
  auto r = client({"--profile", "svgui-2019", "connect", "control 0 0"});
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output,
                       "argument 2:1: 'control' is not a word of profile svgui-2019 (svgui-head "
                       "only)"))
      << r.output;
  r = client({"connect", "signals"});  // profile document
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "'signals' is not a word of profile document")) << r.output;

  expect_script_refused("typo.wr8", "connect\ncontrol 0.5 2\n",
                        ":2:13: expected the y axis (engine)", {"--profile", "svgui-head"});
}

TEST_F(SvguiClientCli, AuthIsForTheDocumentProfileOnly) {
  const auto r = client({"--profile", "svgui-head", "--auth", "HIL-WR8-01", "connect"});
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "--auth is for profile document")) << r.output;
}

TEST(SvguiClientPorts, EachProfileHasItsDefaultPort) {
  for (const auto& [args, banner] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{}, "127.0.0.1:9100 (profile document)"},
           {{"--profile", "svgui-2019"}, "127.0.0.1:5556 (profile svgui-2019)"},
           {{"--profile", "svgui-head"}, "127.0.0.1:5556 (profile svgui-head)"},
           {{"--profile", "svgui-head", "--port", "6000"},
            "127.0.0.1:6000 (profile svgui-head)"}}) {
    HilProcess p(WR8_CLIENT_BINARY, args);
    ASSERT_TRUE(p.write_stdin("help\nquit\n"));
    ASSERT_NO_FATAL_FAILURE(expect_exit_status(p, 0, 20s));
    EXPECT_TRUE(contains(p.output(), banner)) << p.output();
  }
}

}  // namespace
}  // namespace hil::test
