// wr8-client's console for the real programs' profiles (svgui-2019,
// svgui-head): what it prints and its exit code, against hil's mock of the
// real vehicle programs on mem:// in virtual time.

#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <utility>

#include "apps/wr8-client/console.hpp"
#include "mocks/server.hpp"
#include "mocks/wr8_svgui.hpp"
#include "sim/presets.hpp"
#include "tests/client/client_test_support.hpp"

namespace hil::apps::wr8_client {
namespace {

using link::milliseconds;
using link::seconds;
namespace svgui = wr8::svgui;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// The mock vehicle of `version`, a session, a runner and the console.
class Bench {
 public:
  Bench(svgui::Version version, ConsoleOptions options) {
    mocks::SvguiConfig car;
    car.version = version;
    mocks::ServerOptions server = client::test::on_mem("car");
    server.name = "wr8";
    car_.start_car(sim::wr8_vehicle(), std::move(server), car);
    wr8::SvguiConfig config;
    config.version = version;
    session_ =
        std::make_unique<wr8::SvguiSession>(car_.context, link::MemEndpoint{"car"}, config,
                                            [this](link::Time now, const wr8::SvguiEvent& e) {
                                              runner_->on_event(now, e);
                                              console_->on_event(now, e);
                                            });
    runner_ = std::make_unique<wr8::SvguiRunner>(car_.executor, *session_);
    console_ = std::make_unique<SvguiConsole>(car_.executor, *session_, *runner_, out_,
                                              std::move(options), [this](int code) {
                                                exit_code_ = code;
                                                exit_at_ = car_.executor.now();
                                              });
  }

  SvguiConsole& console() { return *console_; }
  void run_until(link::Time t) { car_.executor.run_until(t); }
  void run_to_exit() {
    while (!exit_code_ && car_.executor.now() < seconds(60))
      car_.executor.run_until(car_.executor.now() + milliseconds(10));
  }
  std::string output() const { return out_.str(); }
  std::optional<int> exit_code() const { return exit_code_; }

 private:
  client::test::VirtualCar<mocks::SvguiFirmware> car_;
  std::unique_ptr<wr8::SvguiSession> session_;
  std::unique_ptr<wr8::SvguiRunner> runner_;
  std::unique_ptr<SvguiConsole> console_;
  std::ostringstream out_;
  std::optional<int> exit_code_;
  std::optional<link::Time> exit_at_;
};

ConsoleOptions interactive() {
  ConsoleOptions o;
  o.interactive = true;
  return o;
}

TEST(SvguiConsole, HeadInteractiveShowsStateHelpAndAWordOfTheOtherProfile) {
  Bench bench(svgui::Version::head, interactive());
  for (const char* line : {"connect", "wait 1.5s", "state", "forward 10", "help", "quit"})
    bench.console().line(line);
  bench.run_to_exit();
  EXPECT_EQ(bench.exit_code(), kExitOk);
  const std::string out = bench.output();
  EXPECT_TRUE(contains(out, "connect                  ok    logged in: device 1, id 2, WAIT"))
      << out;
  EXPECT_TRUE(contains(out, "map received: ")) << out;
  EXPECT_TRUE(contains(out, "profile:    svgui-head")) << out;
  EXPECT_TRUE(contains(out, "high-freq:  encoder ")) << out;
  EXPECT_TRUE(contains(out, "low-freq:   WAIT")) << out;
  EXPECT_TRUE(contains(out, "control:    off")) << out;
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
  bench.console().run_batch({wr8::op::Connect{}, wr8::op::Wait{milliseconds(2500)}});
  bench.run_to_exit();
  EXPECT_EQ(bench.exit_code(), kExitOk);
  const std::string out = bench.output();
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
  bench.console().run_batch({wr8::op::Connect{}, wr8::op::Settings2019{{1, 0, 0, 90}}});
  bench.run_to_exit();
  EXPECT_EQ(bench.exit_code(), kExitOk);
  const std::string out = bench.output();
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
    bench.console().run_batch({wr8::op::Connect{}, wr8::op::Settings2019{{1, 0, 0, 90}},
                               wr8::op::Signals{}, wr8::op::Wait{milliseconds(10)}});
    bench.run_to_exit();
    EXPECT_EQ(bench.exit_code(), kExitFailed);
    const std::string out = bench.output();
    EXPECT_TRUE(contains(out, "signals                  FAIL  no ANSWER within 5s")) << out;
    EXPECT_EQ(contains(out, "wait 10ms"), keep_going) << out;
  }
}

}  // namespace
}  // namespace hil::apps::wr8_client
