// The WR8 operator vocabulary: lines and scripts parsed into actions (with
// file:line:col errors), and the runner carrying them out on a session
// against the mock vehicle on mem:// in virtual time, with exact times.

#include "client/wr8/operator.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <utility>
#include <vector>

#include "link/executor.hpp"
#include "link/transport.hpp"
#include "mocks/server.hpp"
#include "mocks/wr8.hpp"
#include "sim/presets.hpp"
#include "sim/world.hpp"
#include "tests/client/client_test_support.hpp"

namespace hil::client::wr8 {
namespace {

using link::milliseconds;
using link::seconds;

OperatorAction parse_ok(std::string_view line) {
  const auto parsed = parse_operator_line(line);
  EXPECT_FALSE(parsed.error) << line << ": " << parsed.error->message;
  EXPECT_TRUE(parsed.action) << line;
  return parsed.action.value_or(op::Connect{});
}

LineError parse_bad(std::string_view line) {
  const auto parsed = parse_operator_line(line);
  EXPECT_FALSE(parsed.action) << line;
  EXPECT_TRUE(parsed.error) << line;
  return parsed.error.value_or(LineError{});
}

TEST(Wr8OperatorParse, ReadsEveryActionOfTheVocabulary) {
  EXPECT_EQ(parse_ok("connect"), OperatorAction(op::Connect{}));
  EXPECT_EQ(parse_ok("  DISCONNECT  "), OperatorAction(op::Disconnect{}));
  EXPECT_EQ(parse_ok("drive 30"), OperatorAction(op::Drive{30}));
  EXPECT_EQ(parse_ok("drive -5"), OperatorAction(op::Drive{-5}));
  EXPECT_EQ(parse_ok("turn -15"), OperatorAction(op::Turn{-15}));
  EXPECT_EQ(parse_ok("turn +12 # left"), OperatorAction(op::Turn{12}));
  EXPECT_EQ(parse_ok("task blink"), OperatorAction(op::RawTask{proto::TaskCode::blink, {}}));
  EXPECT_EQ(parse_ok("task 1 100"),
            OperatorAction(op::RawTask{proto::TaskCode::drive, {proto::Word::from_i32(100)}}));
  EXPECT_EQ(parse_ok("task turn 0xFFFFFFF1"),
            OperatorAction(op::RawTask{proto::TaskCode::turn, {proto::Word::from_i32(-15)}}));
  EXPECT_EQ(parse_ok("get-settings"), OperatorAction(op::GetSettings{}));
  EXPECT_EQ(parse_ok("set p=1.5 servo-zero=92"),
            OperatorAction(
                op::SetSettings{{{proto::SettingCode::p, proto::Word::from_f32(1.5F)},
                                 {proto::SettingCode::servo_zero, proto::Word::from_i32(92)}}}));
  EXPECT_EQ(parse_ok("wait 500ms"), OperatorAction(op::Wait{milliseconds(500)}));
  EXPECT_EQ(parse_ok("wait 1s"), OperatorAction(op::Wait{seconds(1)}));
  EXPECT_EQ(parse_ok("wait 1.5s"), OperatorAction(op::Wait{milliseconds(1500)}));
  EXPECT_EQ(parse_ok("wait-data"), OperatorAction(op::WaitData{}));
}

TEST(Wr8OperatorParse, BlankLinesAndCommentsAreNoAction) {
  for (const char* line : {"", "   ", "# a comment", "   # indented comment", "\t\r"}) {
    const auto parsed = parse_operator_line(line);
    EXPECT_FALSE(parsed.action) << line;
    EXPECT_FALSE(parsed.error) << line;
  }
}

TEST(Wr8OperatorParse, ErrorsNameTheColumnAndWhatWasExpected) {
  auto e = parse_bad("drive thirty");
  EXPECT_EQ(e.column, 7u);
  EXPECT_NE(e.message.find("expected a distance in cm"), std::string::npos) << e.message;
  EXPECT_NE(e.message.find("'thirty'"), std::string::npos) << e.message;

  e = parse_bad("drive");
  EXPECT_EQ(e.column, 6u);  // just past the end of the line
  EXPECT_NE(e.message.find("expected a distance"), std::string::npos) << e.message;

  e = parse_bad("  dirve 30");
  EXPECT_EQ(e.column, 3u);
  EXPECT_NE(e.message.find("unknown action 'dirve'"), std::string::npos) << e.message;
  EXPECT_NE(e.message.find("connect"), std::string::npos) << e.message;

  e = parse_bad("turn 10 20");
  EXPECT_EQ(e.column, 9u);
  EXPECT_NE(e.message.find("unexpected '20'"), std::string::npos) << e.message;

  e = parse_bad("set p=1 q=2");
  EXPECT_EQ(e.column, 9u);
  EXPECT_NE(e.message.find("setting name"), std::string::npos) << e.message;

  e = parse_bad("set servo-zero=1.5");
  EXPECT_EQ(e.column, 16u);  // the value after '='
  EXPECT_NE(e.message.find("whole number"), std::string::npos) << e.message;

  e = parse_bad("set p");
  EXPECT_EQ(e.column, 5u);
  e = parse_bad("wait 5 s");
  EXPECT_EQ(e.column, 6u);
  EXPECT_NE(e.message.find("500ms"), std::string::npos) << e.message;
  e = parse_bad("task fly");
  EXPECT_EQ(e.column, 6u);
  e = parse_bad("connect now");
  EXPECT_EQ(e.column, 9u);
  e = parse_bad("drive 99999999999");
  EXPECT_EQ(e.column, 7u);
}

TEST(Wr8OperatorParse, TextOfAnActionParsesBackToIt) {
  for (const char* line :
       {"connect", "disconnect", "drive 30", "turn -15", "task blink", "task drive 100",
        "get-settings", "set p=1.5 i=0.25 servo-zero=90", "wait 250ms", "wait 2s", "wait-data"}) {
    const auto action = parse_ok(line);
    EXPECT_EQ(to_text(action), line);
    EXPECT_EQ(parse_ok(to_text(action)), action);
  }
}

TEST(Wr8OperatorParse, AScriptReportsEveryBadLineAsFileLineColumn) {
  const auto script = parse_operator_script(
      "# demo\nconnect\n\ndrive 30\n  trun 10\nwait 1x\nget-settings\n", "demo.wr8");
  ASSERT_EQ(script.steps.size(), 3u);
  EXPECT_EQ(script.steps[0].line, 2);
  EXPECT_EQ(script.steps[1].line, 4);
  EXPECT_EQ(script.steps[1].action, OperatorAction(op::Drive{30}));
  EXPECT_EQ(script.steps[2].line, 7);
  ASSERT_EQ(script.errors.size(), 2u);
  EXPECT_EQ(script.errors[0].to_string().rfind("demo.wr8:5:3: unknown action 'trun'", 0), 0u)
      << script.errors[0].to_string();
  EXPECT_EQ(script.errors[1].to_string().rfind("demo.wr8:6:6: ", 0), 0u)
      << script.errors[1].to_string();
}

TEST(Wr8OperatorParse, ShippedExampleScriptsParse) {
  for (const char* name : {"drive-and-turn.wr8", "settings.wr8"}) {
    const std::string path = std::string(HIL_SOURCE_DIR) + "/scenarios/clients/wr8-client/" + name;
    std::FILE* f = std::fopen(path.c_str(), "rb");
    ASSERT_NE(f, nullptr) << path;
    std::string text;
    char buf[4096];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;)
      text.append(buf, n);
    std::fclose(f);
    const auto script = parse_operator_script(text, name);
    EXPECT_TRUE(script.errors.empty()) << script.errors.front().to_string();
    EXPECT_FALSE(script.steps.empty()) << name;
  }
}

/// The mock vehicle on mem://car, a session and a runner, in virtual time.
class Bench : public test::SessionOnMem<Wr8Session, mocks::Wr8Firmware, Event> {
 public:
  explicit Bench(mocks::Wr8Config car = {}, ClientConfig config = {})
      : SessionOnMem("wr8", sim::wr8_vehicle(), {}, std::move(config), car),
        runner_(std::make_unique<OperatorRunner>(executor(), session())) {
    forward_events([this](Time now, const Event& e) { runner_->on_event(now, e); });
  }

  /// Runs `script` from the current time until it ends (at most 60 s).
  std::vector<ActionResult> run(std::string_view script, bool keep_going = false) {
    const auto parsed = parse_operator_script(script, "test");
    EXPECT_TRUE(parsed.errors.empty());
    std::vector<OperatorAction> actions;
    for (const auto& s : parsed.steps)
      actions.push_back(s.action);
    std::vector<ActionResult> results;
    finished_.reset();
    runner_->run(
        actions, keep_going, [&](const ActionResult& r) { results.push_back(r); },
        [this](bool ok) { finished_ = ok; });
    const Time limit = now() + seconds(60);
    while (!finished_ && now() < limit)
      run_until(now() + milliseconds(10));
    EXPECT_TRUE(finished_.has_value()) << "the script did not end";
    return results;
  }

  std::optional<bool> finished() const { return finished_; }

 private:
  std::unique_ptr<OperatorRunner> runner_;
  std::optional<bool> finished_;
};

/// `r` ended ok (or not) with `detail` at `finished`.
void expect_end(const ActionResult& r, bool ok, const std::string& detail, Time finished) {
  EXPECT_EQ(r.ok, ok) << r.detail;
  EXPECT_EQ(r.detail, detail);
  EXPECT_EQ(r.finished, finished);
}

TEST(Wr8OperatorRunner, ConnectsWaitsExactlyAndWaitsForData) {
  Bench bench;
  const auto r = bench.run("connect\nwait 1s\nwait-data\nwait 250ms\n");
  ASSERT_EQ(r.size(), 4u);
  // mem:// answers in the same instant.
  expect_end(r[0], true, "logged in: device 8, id 1, STOP", Time{0});
  EXPECT_EQ(r[1].started, Time{0});
  EXPECT_EQ(r[1].finished, seconds(1));
  // DATA comes on the 100 ms grid: the packet due at 1000 ms is sent after
  // the wait's timer in that same instant, so it ends the wait-data.
  expect_end(r[2], true, "DATA STOP at 1000 ms", milliseconds(1000));
  EXPECT_EQ(r[3].finished, milliseconds(1250));
  EXPECT_EQ(bench.finished(), true);
}

TEST(Wr8OperatorRunner, A50CmDriveCompletesAndTheCarHasMoved) {
  Bench bench;
  const auto r = bench.run("connect\ndrive 50\nwait-data\n");
  ASSERT_EQ(r.size(), 3u);
  EXPECT_TRUE(r[1].ok) << r[1].detail;
  EXPECT_EQ(r[1].detail, "completed");
  // Completion is seen on the 10 ms control grid, about 2.3 s for 50 cm.
  EXPECT_EQ(r[1].finished.count() % milliseconds(10).count(), 0);
  EXPECT_GT(r[1].finished, seconds(1));
  EXPECT_LT(r[1].finished, seconds(4));
  const auto& live = bench.session().core().live();
  ASSERT_TRUE(live);
  EXPECT_GE(*live->odometry_cm, 50.0);
  EXPECT_LE(*live->odometry_cm, 53.0);
}

TEST(Wr8OperatorRunner, ATurnCompletesWhenTheWheelsGetThere) {
  Bench bench;
  const auto r = bench.run("connect\nwait 1s\nturn 15\n");
  ASSERT_EQ(r.size(), 3u);
  EXPECT_TRUE(r[2].ok);
  EXPECT_EQ(r[2].started, seconds(1));
  EXPECT_EQ(r[2].finished, milliseconds(1090));
}

TEST(Wr8OperatorRunner, SettingsAreSetThenReadBack) {
  Bench bench;
  const auto r = bench.run("connect\nset p=2 servo-zero=92\nget-settings\n");
  ASSERT_EQ(r.size(), 3u);
  EXPECT_TRUE(r[1].ok) << r[1].detail;
  expect_end(r[2], true, "p=2 i=0.25 d=0.05 servo-zero=92", Time{0});
  EXPECT_EQ(bench.firmware().state().servo_zero_deg, 92.0);
}

/// A script run on a fresh bench and how one of its actions must end; an
/// empty field is not checked.
struct ScriptEnd {
  const char* what;
  const char* script;
  std::size_t actions_run;
  std::size_t step;
  bool ok;
  std::optional<std::string> detail;
  std::optional<Time> finished;
  std::optional<bool> script_ok;  ///< what the runner reported at the end
};

void expect_script_end(const ScriptEnd& c) {
  Bench bench;
  const auto r = bench.run(c.script);
  ASSERT_EQ(r.size(), c.actions_run);
  EXPECT_EQ(r[c.step].ok, c.ok) << r[c.step].detail;
  if (c.detail) EXPECT_EQ(r[c.step].detail, *c.detail);
  if (c.finished) EXPECT_EQ(r[c.step].finished, *c.finished);
  if (c.script_ok) EXPECT_EQ(bench.finished(), *c.script_ok);
}

TEST(Wr8OperatorRunner, EachActionEndsAsItsAnswerSays) {
  const ScriptEnd cases[] = {
      {"a raw blink task ends after two seconds",
       "connect\ntask blink\n",
       2,
       1,
       true,
       {},
       seconds(2),
       {}},
      // The wait never runs.
      {"a refused task fails with the reason and stops the script",
       "connect\nturn 45\nwait 1s\n",
       2,
       1,
       false,
       "the vehicle answered error",
       {},
       false},
      {"a task before connect is refused as not connected",
       "drive 10\n",
       1,
       0,
       false,
       "refused: not connected",
       Time{0},
       {}},
      {"a raw task the profile cannot encode is refused as bad request",
       "connect\ntask drive\n",
       2,
       1,
       false,
       "refused: bad request",
       {},
       {}},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    expect_script_end(c);
  }
}

TEST(Wr8OperatorRunner, KeepGoingRunsTheRestAfterAFailure) {
  Bench bench;
  const auto r = bench.run("connect\nturn 45\nwait 1s\n", true);
  ASSERT_EQ(r.size(), 3u);
  EXPECT_FALSE(r[1].ok);
  EXPECT_TRUE(r[2].ok);
  EXPECT_EQ(r[2].finished, seconds(1));
  EXPECT_EQ(bench.finished(), false);
}

TEST(Wr8OperatorRunner, ARejectedLoginFailsConnectWithTheReasonAndStopsRetrying) {
  ClientConfig config;
  config.profile.auth_text = {'W', 'R', 'O', 'N', 'G', '-', 'A', 'U', 'T', 'H'};
  Bench bench({}, config);
  const auto r = bench.run("connect\n");
  ASSERT_EQ(r.size(), 1u);
  // The mock closes 1 s after a wrong string.
  expect_end(r[0], false, "closed before AUTH-REPLY", seconds(1));
  bench.run("wait 10s\n");
  EXPECT_EQ(bench.session().core().state(), ConnectionState::disconnected);
}

TEST(Wr8OperatorRunner, AnIgnoredTaskFailsExactly500MsAfterItWasSent) {
  Bench bench;
  ASSERT_TRUE(bench.run("connect\nwait 1s\n").at(0).ok);
  bench.firmware().arm({.name = "", .when = {}, .action = mocks::Ignore{"TASK", 1, {}}});
  const auto r = bench.run("drive 20\n");
  ASSERT_EQ(r.size(), 1u);
  expect_end(r[0], false, "no answer within 500ms", milliseconds(1500));
}

TEST(Wr8OperatorRunner, WaitDataFailsWhenNotConnectedAndAfterDisconnect) {
  Bench bench;
  const auto r = bench.run("wait-data\nconnect\ntask check\ndisconnect\nwait-data\n", true);
  ASSERT_EQ(r.size(), 5u);
  EXPECT_FALSE(r[0].ok);
  EXPECT_EQ(r[0].detail, "not connected");
  EXPECT_TRUE(r[2].ok);
  EXPECT_EQ(r[2].detail, "completed");
  EXPECT_TRUE(r[3].ok);
  EXPECT_FALSE(r[4].ok);
  EXPECT_EQ(bench.session().core().state(), ConnectionState::disconnected);
}

TEST(Wr8OperatorRunner, ExecuteWhileBusyIsAProgrammerError) {
  Bench bench;
  link::VirtualExecutor executor;
  OperatorRunner runner(executor, bench.session());
  runner.execute(op::Wait{seconds(1)}, {});
  EXPECT_TRUE(runner.busy());
  EXPECT_THROW(runner.execute(op::Wait{seconds(1)}, {}), std::logic_error);
}

}  // namespace
}  // namespace hil::client::wr8
