// The LOGI operator-action vocabulary: the parser (every action, every error
// with its column) and the runner against the mock car on mem:// in virtual
// time, with exact times.

#include "client/logi/operator.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "link/executor.hpp"
#include "link/transport.hpp"
#include "mocks/logi.hpp"
#include "mocks/server.hpp"
#include "sim/presets.hpp"
#include "sim/world.hpp"
#include "tests/client/client_test_support.hpp"
#include "tests/client/operator_test_support.hpp"

namespace hil::client::logi {
namespace {

using link::milliseconds;
using link::seconds;
using proto::Direction;
using proto::Mode;

// ---- parser ----

OperatorAction parse_ok(std::string_view line) {
  const auto r = parse_operator_action(line);
  EXPECT_TRUE(r.ok()) << line << ": " << (r.error ? r.error->message : "");
  EXPECT_TRUE(r.action.has_value()) << line;
  return r.action.value_or(op::Connect{});
}

OperatorSyntaxError parse_error(std::string_view line) {
  const auto r = parse_operator_action(line);
  EXPECT_FALSE(r.ok()) << line << " parsed";
  return r.error.value_or(OperatorSyntaxError{});
}

TEST(OperatorParser, EveryActionParses) {
  EXPECT_EQ(parse_ok("connect"), OperatorAction(op::Connect{}));
  EXPECT_EQ(parse_ok("disconnect"), OperatorAction(op::Disconnect{}));
  EXPECT_EQ(parse_ok("speed 50"), OperatorAction(op::Speed{50}));
  EXPECT_EQ(parse_ok("speed 0"), OperatorAction(op::Speed{0}));
  EXPECT_EQ(parse_ok("speed 100"), OperatorAction(op::Speed{100}));
  EXPECT_EQ(parse_ok("speed 030"), OperatorAction(op::Speed{30}));
  EXPECT_EQ(parse_ok("mode MAN"), OperatorAction(op::SetMode{Mode::manual}));
  EXPECT_EQ(parse_ok("mode auto"), OperatorAction(op::SetMode{Mode::automatic}));
  EXPECT_EQ(parse_ok("mode Man"), OperatorAction(op::SetMode{Mode::manual}));
  EXPECT_EQ(parse_ok("release"), OperatorAction(op::Release{}));
  EXPECT_EQ(parse_ok("station 1"), OperatorAction(op::Station{1}));
  EXPECT_EQ(parse_ok("station 002"), OperatorAction(op::Station{2}));
  EXPECT_EQ(parse_ok("run"), OperatorAction(op::Run{}));
  EXPECT_EQ(parse_ok("stop"), OperatorAction(op::Stop{}));
  EXPECT_EQ(parse_ok("estop"), OperatorAction(op::EmergencyStop{}));
  EXPECT_EQ(parse_ok("confirm"), OperatorAction(op::Confirm{}));
  EXPECT_EQ(parse_ok("wait 500ms"), OperatorAction(op::Wait{milliseconds(500)}));
  EXPECT_EQ(parse_ok("wait 1s"), OperatorAction(op::Wait{seconds(1)}));
  EXPECT_EQ(parse_ok("wait 1.5s"), OperatorAction(op::Wait{milliseconds(1500)}));
  EXPECT_EQ(parse_ok("wait 2m"), OperatorAction(op::Wait{seconds(120)}));
  EXPECT_EQ(parse_ok("wait 0.25s"), OperatorAction(op::Wait{milliseconds(250)}));
  EXPECT_EQ(parse_ok("wait 0s"), OperatorAction(op::Wait{seconds(0)}));
  EXPECT_EQ(parse_ok("  CONNECT  "), OperatorAction(op::Connect{}));
  EXPECT_EQ(parse_ok("\tspeed 80   # fast"), OperatorAction(op::Speed{80}));
  EXPECT_EQ(parse_ok("run#go"), OperatorAction(op::Run{}));
}

TEST(OperatorParser, PressTakesEveryDirectionOfTheProtocolInAnyCase) {
  for (const auto d : proto::kAllDirections) {
    const std::string name(proto::to_string(d));
    EXPECT_EQ(parse_ok("press " + name), OperatorAction(op::Press{d})) << name;
    std::string low = name;
    for (auto& c : low)
      c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    EXPECT_EQ(parse_ok("press " + low), OperatorAction(op::Press{d})) << low;
  }
}

TEST(OperatorParser, BlankLinesAndCommentsAreNoAction) {
  for (const char* line : {"", "   ", "\t", "# a comment", "   # indented comment", "\r"}) {
    const auto r = parse_operator_action(line);
    EXPECT_TRUE(r.ok()) << line;
    EXPECT_FALSE(r.action.has_value()) << line;
  }
}

TEST(OperatorParser, EveryErrorNamesItsColumnAndWhatWasExpected) {
  const std::vector<test::SyntaxErrorCase> cases = {
      {"spead 50", 1, "unknown action 'spead'"},
      {"  fly", 3, "expected one of connect, disconnect, speed"},
      {"speed", 6, "expected a speed 0..100 after 'speed'"},
      {"speed   # none", 6, "expected a speed 0..100"},
      {"speed 150", 7, "expected a speed 0..100, got '150'"},
      {"speed -1", 7, "got '-1'"},
      {"speed 5O", 7, "got '5O'"},
      {"speed 0050", 7, "got '0050'"},
      {"speed 50 60", 10, "unexpected '60' after 'speed 50'"},
      {"mode", 5, "expected MAN or AUTO after 'mode'"},
      {"mode HALF", 6, "expected MAN or AUTO, got 'HALF'"},
      {"press", 6, "expected a direction"},
      {"press UP", 7,
       "expected a direction (STOP, FWD, BWD, LEFT, RIGHT, LF, RF, LB, RB, CW, CCW)"},
      {"press L", 7, "got 'L'"},
      {"station", 8, "expected a station number"},
      {"station 0", 9, "got '0'"},
      {"station 1000", 9, "got '1000'"},
      {"station two", 9, "got 'two'"},
      {"wait", 5, "expected a duration with a unit (500ms, 1s, 1.5s, 2m) after 'wait'"},
      {"wait 5", 6, "expected a duration with a unit (500ms, 1s, 1.5s, 2m), got '5'"},
      {"wait 1.s", 6, "got '1.s'"},
      {"wait -1s", 6, "got '-1s'"},
      {"wait 1h", 6, "got '1h'"},
      {"wait 25m0", 6, "got '25m0'"},
      {"wait 2000m", 6, "got '2000m'"},
      {"wait 0.0000000001s", 6, "got '0.0000000001s'"},
      {"connect now", 9, "unexpected 'now' after 'connect' (it takes no argument)"},
      {"release FWD", 9, "unexpected 'FWD' after 'release'"},
      {"estop  x", 8, "unexpected 'x'"},
  };
  test::expect_syntax_errors(cases, test::MessageMatch::part, parse_error);
}

TEST(OperatorParser, DurationsAreExactAndPrintTheirShortestForm) {
  EXPECT_EQ(parse_duration("1.5s"), milliseconds(1500));
  EXPECT_EQ(parse_duration("0.001s"), milliseconds(1));
  EXPECT_EQ(parse_duration("2.5m"), seconds(150));
  EXPECT_EQ(parse_duration("250MS"), milliseconds(250));
  EXPECT_EQ(parse_duration("24m"), seconds(24 * 60));
  EXPECT_EQ(parse_duration("1440m"), seconds(86400));
  EXPECT_EQ(parse_duration("1441m"), std::nullopt);
  EXPECT_EQ(format_duration(milliseconds(1500)), "1.5s");
  EXPECT_EQ(format_duration(milliseconds(500)), "500ms");
  EXPECT_EQ(format_duration(seconds(120)), "2m");
  EXPECT_EQ(format_duration(seconds(10)), "10s");
  EXPECT_EQ(format_duration(link::microseconds(1500)), "1.5ms");
  for (const char* text : {"1.5s", "500ms", "2m", "10s", "1.25s", "0s"}) {
    EXPECT_EQ(format_duration(*parse_duration(text)), text);
  }
  // Every action's canonical text parses back to the same action.
  for (const char* line : {"connect", "speed 7", "mode MAN", "press CCW", "station 2", "wait 1.5s",
                           "estop", "confirm", "release", "stop", "run", "disconnect"}) {
    const auto action = parse_ok(line);
    EXPECT_EQ(to_string(action), line);
  }
}

TEST(OperatorParser, ScriptKeepsLineNumbersAndReportsEveryErrorAsFileLineColumn) {
  const auto script = parse_operator_script(
      "# manual drive\n\nconnect\n  speed 50   # half\nmode MAN\r\n", "drive.txt");
  ASSERT_TRUE(script.ok()) << script.errors.front().to_string();
  ASSERT_EQ(script.steps.size(), 3u);
  EXPECT_EQ(script.steps[0].line, 3);
  EXPECT_EQ(script.steps[0].text, "connect");
  EXPECT_EQ(script.steps[1].line, 4);
  EXPECT_EQ(script.steps[1].text, "speed 50");
  EXPECT_EQ(script.steps[1].action, OperatorAction(op::Speed{50}));
  EXPECT_EQ(script.steps[2].text, "mode MAN");

  const auto bad = parse_operator_script("connect\nspeed 50\npress  UP\nmode HALF\n", "drive.txt");
  ASSERT_FALSE(bad.ok());
  ASSERT_EQ(bad.errors.size(), 2u) << "both bad lines, in order";
  EXPECT_EQ(bad.errors[0].line, 3u);
  EXPECT_EQ(bad.errors[0].column, 8u);
  EXPECT_EQ(bad.errors[0].to_string().rfind("drive.txt:3:8: expected a direction", 0), 0u)
      << bad.errors[0].to_string();
  EXPECT_EQ(bad.errors[1].to_string().rfind("drive.txt:4:6: expected MAN or AUTO", 0), 0u)
      << bad.errors[1].to_string();
  EXPECT_TRUE(parse_operator_script("", "empty.txt").steps.empty());
}

// ---- runner ----

/// The mock car on mem://car, a session and a runner, in virtual time.
class RunnerBench : public test::SessionOnMem<LogiSession, mocks::LogiFirmware, Event> {
 public:
  RunnerBench() : SessionOnMem("logi", sim::logi_car(), {}, ClientConfig{}) {
    forward_events([this](Time now, const Event& e) {
      if (runner_) runner_->on_event(now, e);
    });
  }

  OperatorRunner& runner() { return *runner_; }

  /// Starts `script`; run() then runs it to its end.
  void start(const std::string& script, OperatorRunnerOptions options = {}) {
    const auto parsed = parse_operator_script(script, "test");
    ASSERT_TRUE(parsed.ok()) << parsed.errors.front().to_string();
    runner_ = std::make_unique<OperatorRunner>(
        session(), executor(), parsed.steps, options,
        [this](const ActionResult& r) { results_.push_back(r); },
        [this](const RunSummary& s) { summary_ = s; });
    runner_->start();
  }
  /// Runs until the runner is done (at most `limit` of virtual time).
  bool run(link::Duration limit = seconds(120)) {
    const Time end = now() + limit;
    while (!summary_ && now() < end) {
      executor().run_one();
    }
    return summary_.has_value();
  }
  const std::vector<ActionResult>& results() const { return results_; }
  /// Runs until `t`; how many actions have a result by then.
  std::size_t results_by(Time t) {
    run_until(t);
    return results_.size();
  }
  const std::optional<RunSummary>& summary() const { return summary_; }

  /// Time of the first received frame whose raw text contains `text`.
  std::optional<Time> rx_time(const std::string& text, Time after = Time{0}) const {
    for (const auto& e : session().log()->entries()) {
      if (e.kind == LogKind::rx && e.at >= after && e.raw.find(text) != std::string::npos)
        return e.at;
    }
    return std::nullopt;
  }
  std::vector<std::string> sent() const {
    std::vector<std::string> out;
    for (const auto& e : session().log()->entries()) {
      if (e.kind == LogKind::tx) out.push_back(e.raw);
    }
    return out;
  }

 private:
  std::unique_ptr<OperatorRunner> runner_;
  std::vector<ActionResult> results_;
  std::optional<RunSummary> summary_;
};

TEST(OperatorRunner, AManualDriveRunsEveryActionAtItsExactTime) {
  RunnerBench b;
  b.start("connect\nspeed 50\nmode MAN\npress FWD\nwait 1s\nrelease\ndisconnect\n");
  ASSERT_TRUE(b.run());
  ASSERT_TRUE(b.summary()->ok);
  const auto& r = b.results();
  ASSERT_EQ(r.size(), 7u);
  for (const auto& x : r)
    EXPECT_TRUE(x.ok) << x.text << ": " << x.reason;
  EXPECT_EQ(r[1].text, "speed 50");
  EXPECT_EQ(r[1].line, 2);
  // Each command action ends the instant its FB arrives; the next starts then.
  const auto fb_sp = b.rx_time("FB:SP:1");
  ASSERT_TRUE(fb_sp);
  EXPECT_EQ(r[1].ended, *fb_sp);
  EXPECT_EQ(r[2].started, r[1].ended);
  EXPECT_EQ(r[2].ended, *b.rx_time("FB:MD:1"));
  EXPECT_EQ(r[3].ended, *b.rx_time("FB:MV:1"));
  // wait 1s: exactly one second.
  EXPECT_EQ(r[4].started, r[3].ended);
  EXPECT_EQ(r[4].ended, r[4].started + seconds(1));
  EXPECT_EQ(r[5].ended, *b.rx_time("FB:MV:1", r[4].ended));
  EXPECT_EQ(b.sent(), (std::vector<std::string>{"LOGI:SP:050:D7#", "LOGI:MD:MAN:0C#",
                                                "LOGI:MV:FWD:23#", "LOGI:MV:STOP:88#"}));
  EXPECT_EQ(b.firmware().state().manual, Direction::stop);
  EXPECT_EQ(b.session().core().state(), ConnectionState::disconnected);
}

TEST(OperatorRunner, ACommandTheCarRejectsFailsTheRunWithTheReason) {
  RunnerBench b;
  b.firmware().arm(mocks::Behaviour{"no speed", {}, mocks::Reject{"SP", 1}});
  b.start("connect\nspeed 50\nmode MAN\n");
  ASSERT_TRUE(b.run());
  EXPECT_FALSE(b.summary()->ok);
  EXPECT_EQ(b.summary()->failed, 1u);
  ASSERT_EQ(b.results().size(), 2u) << "the run stops at the first failure";
  EXPECT_FALSE(b.results()[1].ok);
  EXPECT_EQ(b.results()[1].reason, "rejected by the car (FB:SP:0)");
  EXPECT_EQ(b.results()[1].ended, *b.rx_time("FB:SP:0"));
  EXPECT_EQ(b.sent(), (std::vector<std::string>{"LOGI:SP:050:D7#"}));
}

TEST(OperatorRunner, ContinueOnErrorRunsEveryActionAndStillReportsTheFailure) {
  RunnerBench b;
  b.firmware().arm(mocks::Behaviour{"no speed", {}, mocks::Reject{"SP", 1}});
  OperatorRunnerOptions options;
  options.continue_on_error = true;
  b.start("connect\nspeed 50\nmode MAN\nstation 3\n", options);
  ASSERT_TRUE(b.run());
  EXPECT_FALSE(b.summary()->ok);
  EXPECT_EQ(b.summary()->ran, 4u);
  EXPECT_EQ(b.summary()->failed, 2u);
  EXPECT_TRUE(b.results()[2].ok);
  EXPECT_EQ(b.results()[3].reason, "rejected by the car (FB:GS:0)");
}

TEST(OperatorRunner, PressOnADisconnectedCarFailsAsNotConnected) {
  RunnerBench b;
  b.firmware().arm(mocks::Behaviour{"hang up", mocks::When{milliseconds(500), {}, 1},
                                    mocks::CloseConnection{link::CloseMode::reset}});
  b.start("connect\nspeed 50\nmode MAN\nwait 1s\npress FWD\nwait 1s\n");
  ASSERT_TRUE(b.run());
  ASSERT_EQ(b.results().size(), 5u);
  EXPECT_TRUE(b.results()[3].ok);
  EXPECT_FALSE(b.results()[4].ok);
  EXPECT_EQ(b.results()[4].reason, "refused: not connected");
  EXPECT_EQ(b.results()[4].ended, b.results()[4].started) << "refused at once, nothing sent";
  EXPECT_EQ(b.firmware().state().manual, Direction::stop);
}

TEST(OperatorRunner, MovementBeforeModeAndSpeedIsRefused) {
  RunnerBench b;
  b.start("connect\npress FWD\n");
  ASSERT_TRUE(b.run());
  ASSERT_EQ(b.results().size(), 2u);
  EXPECT_EQ(b.results()[1].reason,
            "refused: movement needs a 'mode' and a 'speed' on this connection first");
}

TEST(OperatorRunner, ConnectWithNoCarFailsAtItsBoundAndStopsRetrying) {
  RunnerBench b;
  b.server().close();
  OperatorRunnerOptions options;
  options.connect_timeout = seconds(3);
  b.start("wait 250ms\nconnect\nspeed 50\n", options);
  ASSERT_TRUE(b.run());
  ASSERT_EQ(b.results().size(), 2u);
  const auto& c = b.results()[1];
  EXPECT_FALSE(c.ok);
  EXPECT_EQ(c.started, milliseconds(250));
  EXPECT_EQ(c.ended, milliseconds(3250));
  EXPECT_EQ(c.reason.rfind("not connected after 3s (the connection failed", 0), 0u) << c.reason;
  EXPECT_EQ(b.session().core().state(), ConnectionState::disconnected);
}

TEST(OperatorRunner, ConnectSucceedsOnALaterAttemptWithinItsBound) {
  RunnerBench b;
  b.server().close();
  b.executor().call_at(milliseconds(1500), [&] { b.server().start(); });
  b.start("connect\n");
  ASSERT_TRUE(b.run());
  ASSERT_TRUE(b.summary()->ok);
  // Attempts at 0 s and 1 s fail; the one at 3 s connects.
  EXPECT_EQ(b.results()[0].ended, seconds(3));
}

TEST(OperatorRunner, AnUnansweredRunIsUncertainAfter800msAndConfirmSendsItAgain) {
  RunnerBench b;
  b.firmware().arm(mocks::Behaviour{"lose one run", {}, mocks::Ignore{"ST:RUN", 1, {}}});
  OperatorRunnerOptions options;
  options.continue_on_error = true;
  b.start("connect\nspeed 50\nmode AUTO\nstation 2\nrun\nconfirm\nwait 1s\nstop\n", options);
  ASSERT_TRUE(b.run());
  const auto& r = b.results();
  ASSERT_EQ(r.size(), 8u);
  EXPECT_FALSE(r[4].ok);
  EXPECT_EQ(r[4].ended, r[4].started + milliseconds(800));
  EXPECT_EQ(r[4].reason,
            "no feedback to ST:RUN within 800ms (1 send), uncertain; 'confirm' sends it again");
  EXPECT_TRUE(r[5].ok) << r[5].reason;
  EXPECT_EQ(r[5].ended, *b.rx_time("FB:ST:1"));
  EXPECT_TRUE(r[7].ok);
  EXPECT_EQ(b.summary()->failed, 1u);
  const auto tx = b.sent();
  EXPECT_EQ(std::count(tx.begin(), tx.end(), "LOGI:ST:RUN:3B#"), 2);
  EXPECT_EQ(tx.back(), "LOGI:ST:STOP:8C#");
}

TEST(OperatorRunner, ConfirmWithNothingUncertainFails) {
  RunnerBench b;
  b.start("connect\nconfirm\n");
  ASSERT_TRUE(b.run());
  EXPECT_EQ(b.results()[1].reason, "nothing to confirm: no ST:RUN or GS awaits a resend");
}

TEST(OperatorRunner, EmergencyStopEndsAnAutoRunEvenThoughTheCarRefusesMvInAuto) {
  RunnerBench b;
  b.start("connect\nspeed 50\nmode AUTO\nstation 2\nrun\nwait 2s\nestop\n");
  ASSERT_TRUE(b.run());
  ASSERT_TRUE(b.summary()->ok) << b.results().back().reason;
  EXPECT_FALSE(b.firmware().state().running);
  EXPECT_EQ(b.firmware().state().last_run_end, mocks::LogiRunEnd::stopped);
  const auto tx = b.sent();
  ASSERT_GE(tx.size(), 2u);
  EXPECT_EQ(tx[tx.size() - 2], "LOGI:MV:STOP:88#");
  EXPECT_EQ(tx.back(), "LOGI:ST:STOP:8C#");
  EXPECT_EQ(b.results().back().ended, *b.rx_time("FB:ST:1", b.results().back().started));
}

TEST(OperatorRunner, ReleaseWithNothingHeldFails) {
  RunnerBench b;
  b.start("connect\nspeed 40\nmode MAN\nrelease\n");
  ASSERT_TRUE(b.run());
  EXPECT_EQ(b.results().back().reason, "refused: no direction held");
}

TEST(OperatorRunner, CancelEndsTheActionUnderWayAndStartsNoOther) {
  RunnerBench b;
  b.start("connect\nwait 30s\nspeed 50\n");
  b.executor().run_until(seconds(2));
  ASSERT_EQ(b.runner().current(), 1u);
  b.runner().cancel();
  ASSERT_TRUE(b.summary());
  EXPECT_TRUE(b.summary()->cancelled);
  EXPECT_FALSE(b.summary()->ok);
  ASSERT_EQ(b.results().size(), 2u);
  EXPECT_EQ(b.results()[1].reason, "cancelled");
  EXPECT_EQ(b.results()[1].ended, seconds(2));
  EXPECT_EQ(b.results_by(seconds(40)), 2u);
  EXPECT_TRUE(b.sent().empty());
}

// start() and the end of an action begin the next action on a later turn;
// a cancel that comes before that turn still reports that action, so every
// action taken gets a result (a Ctrl-C never leaves one unanswered).
TEST(OperatorRunner, CancelBeforeTheFirstTurnReportsTheFirstAction) {
  RunnerBench b;
  b.start("connect\nwait 30s\n");
  b.runner().cancel();
  ASSERT_TRUE(b.summary());
  EXPECT_TRUE(b.summary()->cancelled);
  ASSERT_EQ(b.results().size(), 1u);
  EXPECT_EQ(b.results()[0].text, "connect");
  EXPECT_EQ(b.results()[0].reason, "cancelled");
  EXPECT_EQ(b.results()[0].started, Time{0});
  EXPECT_EQ(b.results()[0].ended, Time{0});
  EXPECT_EQ(b.results_by(seconds(40)), 1u);
  EXPECT_TRUE(b.sent().empty());
}

TEST(OperatorRunner, CancelBetweenTwoActionsReportsTheNextOne) {
  RunnerBench b;
  b.start("connect\nwait 30s\nspeed 50\n");
  // Task by task until the connect ended: the wait's first turn is posted.
  while (b.results().empty() && b.executor().now() < seconds(10))
    b.executor().run_one();
  ASSERT_EQ(b.results().size(), 1u);
  ASSERT_TRUE(b.results()[0].ok) << b.results()[0].reason;
  ASSERT_FALSE(b.runner().current().has_value());
  const Time at = b.executor().now();
  b.runner().cancel();
  ASSERT_TRUE(b.summary());
  ASSERT_EQ(b.results().size(), 2u);
  EXPECT_EQ(b.results()[1].text, "wait 30s");
  EXPECT_EQ(b.results()[1].index, 1u);
  EXPECT_EQ(b.results()[1].reason, "cancelled");
  EXPECT_EQ(b.results()[1].started, at);
  EXPECT_EQ(b.results()[1].ended, at);
  EXPECT_EQ(b.results_by(seconds(40)), 2u);
}

// The example scripts of scenarios/clients/logi-client/ run to the end
// against the mock car, and the car does what they say.
std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(OperatorRunner, TheManualDriveExampleDrivesTheCarAndStopsIt) {
  const auto path =
      std::filesystem::path(HIL_SOURCE_DIR) / "scenarios/clients/logi-client/manual-drive.txt";
  RunnerBench b;
  b.start(read_file(path));
  ASSERT_TRUE(b.run());
  for (const auto& r : b.results())
    EXPECT_TRUE(r.ok) << r.line << " " << r.text << ": " << r.reason;
  EXPECT_TRUE(b.summary()->ok);
  EXPECT_EQ(b.firmware().state().manual, Direction::stop);
  EXPECT_GT(b.firmware().stats().frames_in, 5u);
}

TEST(OperatorRunner, TheAutoRunExampleReachesStation2) {
  const auto path =
      std::filesystem::path(HIL_SOURCE_DIR) / "scenarios/clients/logi-client/auto-to-station-2.txt";
  RunnerBench b;
  b.start(read_file(path));
  ASSERT_TRUE(b.run(seconds(300)));
  for (const auto& r : b.results())
    EXPECT_TRUE(r.ok) << r.line << " " << r.text << ": " << r.reason;
  EXPECT_TRUE(b.summary()->ok);
  EXPECT_EQ(b.firmware().state().arrivals, 1u);
  EXPECT_EQ(b.firmware().state().last_run_end, mocks::LogiRunEnd::arrived);
}

}  // namespace
}  // namespace hil::client::logi
