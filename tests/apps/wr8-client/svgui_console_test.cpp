// wr8-client's console for the real programs' profiles (svgui-2019,
// svgui-head): what it prints and its exit code, against hil's mock of the
// real vehicle programs on mem:// in virtual time.

#include <gtest/gtest.h>

#include <string>
#include <utility>

#include "apps/wr8-client/console.hpp"
#include "mocks/wr8_svgui.hpp"
#include "tests/apps/wr8-client/console_bench.hpp"

namespace hil::apps::wr8_client {
namespace {

using link::milliseconds;
using link::seconds;
namespace svgui = wr8::svgui;

/// The mock vehicle of `version`, a session, a runner and the console.
struct Bench
    : ConsoleBench<mocks::SvguiFirmware, wr8::SvguiSession, wr8::SvguiRunner, SvguiConsole> {
  Bench(svgui::Version version, ConsoleOptions options)
      : ConsoleBench(of_version<wr8::SvguiConfig>(version), std::move(options),
                     of_version<mocks::SvguiConfig>(version)) {}

  /// A default `Config` (the client's or the car's) for `version`.
  template <class Config>
  static Config of_version(svgui::Version version) {
    Config config;
    config.version = version;
    return config;
  }
};

TEST(SvguiConsole, HeadInteractiveShowsStateHelpAndAWordOfTheOtherProfile) {
  Bench bench(svgui::Version::head, interactive());
  const std::string out =
      bench.lines_to_exit({"connect", "wait 1.5s", "state", "forward 10", "help", "quit"});
  EXPECT_EQ(bench.exit_code(), kExitOk);
  EXPECT_TRUE(contains(out, "connect                  ok    logged in: device 1, id 2, WAIT"))
      << out;
  expect_contains(out, {"map received: ", "profile:    svgui-head", "high-freq:  encoder ",
                        "low-freq:   WAIT", "control:    off"});
  EXPECT_TRUE(contains(out, "error: column 1: 'forward' is not a word of profile svgui-head"))
      << out;
  EXPECT_TRUE(contains(out, "control X Y")) << out;  // help
  EXPECT_FALSE(contains(out, "bad bytes")) << out;
  EXPECT_FALSE(contains(out, "ignored")) << out;  // DATA before login is not news
}

TEST(SvguiConsole, HeadBatchPrintsEachDataStreamOnItsOwnSchedule) {
  ConsoleOptions o;
  o.print_data = true;
  Bench bench(svgui::Version::head, o);
  const std::string out =
      bench.batch_to_exit({wr8::op::Connect{}, wr8::op::Wait{milliseconds(2500)}});
  EXPECT_EQ(bench.exit_code(), kExitOk);
  std::size_t high = 0;
  std::size_t low = 0;
  for (std::size_t at = 0; (at = out.find("data  high-freq", at)) != std::string::npos; ++at)
    ++high;
  for (std::size_t at = 0; (at = out.find("data  low-freq", at)) != std::string::npos; ++at)
    ++low;
  // HIGH-FREQ comes every 50 ms but prints once a second: 3 lines in 2.5 s.
  EXPECT_EQ(high, 3u) << out;
  EXPECT_GE(low, 2u) << out;
  EXPECT_LE(low, 3u) << out;
}

TEST(SvguiConsole, V2019SettingsSayTheyAreUnconfirmed) {
  Bench bench(svgui::Version::v2019, ConsoleOptions{});
  const std::string out =
      bench.batch_to_exit({wr8::op::Connect{}, wr8::op::Settings2019{{1, 0, 0, 90}}});
  EXPECT_EQ(bench.exit_code(), kExitOk);
  EXPECT_TRUE(contains(out,
                       "settings p=1 i=0 d=0 servo-zero=90 ok    sent under COI 1; not "
                       "confirmed: the v2019 vehicle never answers SETTINGS"))
      << out;
}

TEST(SvguiConsole, V2019BatchStopsAtTheFirstFailureUnlessKeepGoing) {
  // Settings make the v2019 vehicle busy: the next task is dropped and times out.
  for (const bool keep_going : {false, true}) {
    ConsoleOptions o;
    o.keep_going = keep_going;
    Bench bench(svgui::Version::v2019, o);
    const std::string out =
        bench.batch_to_exit({wr8::op::Connect{}, wr8::op::Settings2019{{1, 0, 0, 90}},
                             wr8::op::Signals{}, wr8::op::Wait{milliseconds(10)}});
    EXPECT_EQ(bench.exit_code(), kExitFailed);
    EXPECT_TRUE(contains(out, "signals                  FAIL  no ANSWER within 5s")) << out;
    EXPECT_EQ(contains(out, "wait 10ms"), keep_going) << out;
  }
}

}  // namespace
}  // namespace hil::apps::wr8_client
