// The operator's words for the real smart_vehicle_gui dialects: lines and
// scripts of svgui-2019 and svgui-head parsed into actions (errors with
// their columns, words of another profile named as such), and the runner
// carrying them out on an SvguiSession in virtual time, against a scripted
// vehicle on a mem:// pipe (bytes as the real programs send them) and
// against hil's mock of the real vehicle programs.

#include "client/wr8/svgui_operator.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "link/executor.hpp"
#include "link/transport.hpp"
#include "mocks/server.hpp"
#include "mocks/wr8_svgui.hpp"
#include "sim/presets.hpp"
#include "tests/client/client_test_support.hpp"
#include "tests/client/operator_test_support.hpp"

namespace hil::client::wr8 {
namespace {

using link::milliseconds;
using link::seconds;
using svgui::Version;

SvguiAction parse_ok(std::string_view line, Version version) {
  const auto parsed = parse_svgui_line(line, version);
  EXPECT_FALSE(parsed.error) << line << ": " << parsed.error->message;
  EXPECT_TRUE(parsed.action) << line;
  return parsed.action.value_or(op::Connect{});
}

LineError parse_bad(std::string_view line, Version version) {
  const auto parsed = parse_svgui_line(line, version);
  EXPECT_FALSE(parsed.action) << line;
  EXPECT_TRUE(parsed.error) << line;
  return parsed.error.value_or(LineError{});
}

bool has(const std::string& text, std::string_view part) {
  return text.find(part) != std::string::npos;
}

TEST(SvguiOperatorParse, ReadsEveryWordOfV2019) {
  const auto v = Version::v2019;
  EXPECT_EQ(parse_ok("connect", v), SvguiAction(op::Connect{}));
  EXPECT_EQ(parse_ok(" DISCONNECT ", v), SvguiAction(op::Disconnect{}));
  EXPECT_EQ(parse_ok("forward 30", v), SvguiAction(op::Forward{30}));
  EXPECT_EQ(parse_ok("wheels -15 # left", v), SvguiAction(op::Wheels{-15}));
  EXPECT_EQ(parse_ok("signals", v), SvguiAction(op::Signals{}));
  EXPECT_EQ(parse_ok("settings servo-zero=92 p=1 d=3 i=2", v),
            SvguiAction(op::Settings2019{{1, 2, 3, 92}}));
  EXPECT_EQ(parse_ok("wait 1.5s", v), SvguiAction(op::Wait{milliseconds(1500)}));
  EXPECT_EQ(parse_ok("wait-data", v), SvguiAction(op::WaitData{}));
}

TEST(SvguiOperatorParse, ReadsEveryWordOfHead) {
  const auto v = Version::head;
  EXPECT_EQ(parse_ok("control 0.5 -1", v), SvguiAction(op::Control{0.5, -1.0}));
  EXPECT_EQ(parse_ok("control +1 1e-1", v), SvguiAction(op::Control{1.0, 0.1}));
  EXPECT_EQ(parse_ok("control OFF", v), SvguiAction(op::ControlOff{}));
  EXPECT_EQ(parse_ok("set steering-p=1.5 Backward-Int=10", v),
            SvguiAction(op::Set{{{0, 1.5}, {11, 10.0}}}));
  EXPECT_EQ(parse_ok("set-request", v), SvguiAction(op::SetRequest{}));
  EXPECT_EQ(parse_ok("wait 250ms", v), SvguiAction(op::Wait{milliseconds(250)}));
  for (const char* line : {"", "  ", "# a comment"}) {
    const auto parsed = parse_svgui_line(line, v);
    EXPECT_FALSE(parsed.action) << line;
    EXPECT_FALSE(parsed.error) << line;
  }
}

TEST(SvguiOperatorParse, ErrorsNameTheColumnAndWhatWasExpected) {
  // An empty part: only the column is checked.
  const std::vector<std::pair<Version, test::SyntaxErrorCase>> cases = {
      {Version::v2019, {"forward far", 9, "expected a distance in cm"}},
      {Version::v2019, {"wheels", 7, ""}},
      {Version::v2019, {"signals now", 9, ""}},
      {Version::v2019, {"settings p=1 i=2 d=3", 21, "servo-zero is missing"}},
      {Version::v2019, {"settings p=1.5", 12, "whole number"}},  // the value after '='
      {Version::v2019, {"settings q=1", 10, ""}},
      {Version::head, {"control 0.5", 12, "y axis"}},
      {Version::head, {"control 1.5 0", 9, "from -1 to 1"}},
      {Version::head, {"control 0 nan", 11, ""}},
      {Version::head, {"control 0 0 0", 13, ""}},
      {Version::head, {"set steering-q=1", 5, "forward-int"}},  // the names are listed
      {Version::head, {"set forward-p=x", 15, ""}},
      {Version::head, {"  bogus", 3, "unknown action 'bogus'"}},
      {Version::head, {"wait 5 s", 6, ""}},
  };
  for (const auto& [version, error] : cases) {
    test::expect_syntax_errors({error}, test::MessageMatch::part,
                               [v = version](std::string_view line) { return parse_bad(line, v); });
  }
}

TEST(SvguiOperatorParse, AWordOfAnotherProfileIsAnErrorNamingTheProfile) {
  auto e = parse_bad("control 0 0", Version::v2019);
  EXPECT_EQ(e.column, 1u);
  EXPECT_TRUE(has(e.message, "'control' is not a word of profile svgui-2019 (svgui-head only)"))
      << e.message;
  EXPECT_TRUE(has(e.message, "forward CM")) << e.message;  // what the profile takes
  e = parse_bad("  forward 10", Version::head);
  EXPECT_EQ(e.column, 3u);
  EXPECT_TRUE(has(e.message, "'forward' is not a word of profile svgui-head (svgui-2019 only)"))
      << e.message;
  e = parse_bad("drive 10", Version::v2019);
  EXPECT_TRUE(has(e.message, "profile svgui-2019 (document only)")) << e.message;
  e = parse_bad("set p=1", Version::v2019);
  EXPECT_TRUE(has(e.message, "(document and svgui-head only)")) << e.message;

  // And the document vocabulary says the same of the real programs' words.
  const auto doc = parse_operator_line("wheels 10");
  ASSERT_TRUE(doc.error);
  EXPECT_TRUE(
      has(doc.error->message, "'wheels' is not a word of profile document (svgui-2019 only)"))
      << doc.error->message;
}

TEST(SvguiOperatorParse, TextOfAnActionParsesBackToIt) {
  for (const char* line : {"connect", "disconnect", "forward 30", "wheels -15", "signals",
                           "settings p=1 i=2 d=3 servo-zero=90", "wait 250ms", "wait-data"}) {
    const auto action = parse_ok(line, Version::v2019);
    EXPECT_EQ(to_text(action), line);
  }
  for (const char* line :
       {"control 0.5 -0.25", "control off", "set steering-p=1.5 forward-int=10", "set-request"}) {
    const auto action = parse_ok(line, Version::head);
    EXPECT_EQ(to_text(action), line);
    EXPECT_EQ(parse_ok(to_text(action), Version::head), action);
  }
}

TEST(SvguiOperatorParse, AScriptReportsEveryBadLineAsFileLineColumn) {
  const auto script = parse_svgui_script("connect\n  forward 30\ncontrol 0 0\nsignals\nwheels x\n",
                                         "demo.wr8", Version::v2019);
  ASSERT_EQ(script.steps.size(), 3u);
  EXPECT_EQ(script.steps[1].line, 2);
  EXPECT_EQ(script.steps[1].action, SvguiAction(op::Forward{30}));
  ASSERT_EQ(script.errors.size(), 2u);
  EXPECT_EQ(script.errors[0].to_string().rfind(
                "demo.wr8:3:1: 'control' is not a word of profile svgui-2019", 0),
            0u)
      << script.errors[0].to_string();
  EXPECT_EQ(script.errors[1].to_string().rfind("demo.wr8:5:8: expected an angle", 0), 0u)
      << script.errors[1].to_string();
}

// ---- the runner against a scripted vehicle on mem:// ----

/// A vehicle that answers as the real programs do, written by hand: the
/// fixed AUTH-REPLY to any AUTH, ANSWER done 300 ms after a forward or
/// wheels TASK (signals are dropped, as a busy car drops a task), SET
/// answered 1 (applied), SET-REQUEST answered by a SET of `readback`.
class ScriptedVehicle {
 public:
  ScriptedVehicle(link::TransportContext& context, link::VirtualExecutor& executor, Version version)
      : executor_(executor), version_(version), decoder_(version) {
    listener_ = link::listen(context, link::MemEndpoint{"car"});
    listener_->start([this](link::BytePipePtr pipe) {
      pipe_ = pipe;
      pipe->start({[this](protocol::ByteView bytes) { on_bytes(bytes); }, {}});
    });
    for (std::size_t i = 0; i < readback.values.size(); ++i)
      readback.values[i] = static_cast<double>(i) * 0.5;
  }

  /// What the vehicle received, and when.
  std::vector<std::pair<Time, svgui::Message>> received;
  svgui::Set readback;

  void send(const svgui::Message& m) {
    if (pipe_) pipe_->write(svgui::encode_prefixed(m, version_));
  }

 private:
  void on_bytes(protocol::ByteView bytes) {
    std::vector<svgui::Item> items;
    decoder_.feed(bytes, items);
    for (const auto& item : items) {
      const auto* frame = std::get_if<protocol::Frame<svgui::Message>>(&item);
      if (frame == nullptr) continue;
      received.emplace_back(executor_.now(), frame->message);
      const auto& m = frame->message;
      if (std::holds_alternative<svgui::Auth>(m)) {
        send(svgui::kProgramAuthReply);
      } else if (const auto* t = std::get_if<svgui::Task>(&m)) {
        if (t->type == 3) continue;
        const std::uint8_t coi = t->coi;
        executor_.call_after(milliseconds(300), [this, coi] { send(svgui::Answer{coi, 2}); });
      } else if (std::holds_alternative<svgui::Set>(m)) {
        send(svgui::Answer{std::nullopt, 1});
      } else if (std::holds_alternative<svgui::SetRequest>(m)) {
        send(readback);
      }
    }
  }

  link::VirtualExecutor& executor_;
  Version version_;
  svgui::Decoder decoder_;
  std::unique_ptr<link::Listener> listener_;
  link::BytePipePtr pipe_;
};

/// The session and runner; `Vehicle` is set up first by the fixture.
class Runner {
 public:
  Runner(link::TransportContext& context, link::VirtualExecutor& executor, Version version,
         SvguiConfig config = {})
      : executor_(executor) {
    config.version = version;
    session_ = std::make_unique<SvguiSession>(context, link::MemEndpoint{"car"}, config,
                                              [this](Time now, const SvguiEvent& e) {
                                                events.emplace_back(now, e);
                                                if (runner_) runner_->on_event(now, e);
                                              });
    runner_ = std::make_unique<SvguiRunner>(executor_, *session_);
  }

  std::vector<SvguiActionResult> run(std::string_view script, Version version,
                                     bool keep_going = false) {
    const auto parsed = parse_svgui_script(script, "test", version);
    EXPECT_TRUE(parsed.errors.empty()) << parsed.errors.front().to_string();
    std::vector<SvguiAction> actions;
    for (const auto& s : parsed.steps)
      actions.push_back(s.action);
    std::vector<SvguiActionResult> results;
    std::optional<bool> finished;
    runner_->run(
        actions, keep_going, [&](const SvguiActionResult& r) { results.push_back(r); },
        [&](bool ok) { finished = ok; });
    const Time limit = executor_.now() + seconds(60);
    while (!finished && executor_.now() < limit)
      executor_.run_until(executor_.now() + milliseconds(10));
    EXPECT_TRUE(finished.has_value()) << "the script did not end";
    all_ok = finished.value_or(false);
    return results;
  }

  SvguiSession& session() { return *session_; }
  std::vector<std::pair<Time, SvguiEvent>> events;
  bool all_ok = false;

 private:
  link::VirtualExecutor& executor_;
  std::unique_ptr<SvguiSession> session_;
  std::unique_ptr<SvguiRunner> runner_;
};

struct SvguiRunnerOnMem : ::testing::Test {
  link::VirtualExecutor executor;
  link::TransportContext context{executor};
};

TEST_F(SvguiRunnerOnMem, V2019TasksCompleteByCoiSettingsAreUnconfirmedADroppedTaskTimesOut) {
  ScriptedVehicle car(context, executor, Version::v2019);
  SvguiConfig config;
  config.task_timeout[3] = seconds(2);  // signals
  Runner runner(context, executor, Version::v2019, config);
  const auto r = runner.run(
      "connect\nforward 30\nwheels -10\nsettings p=1 i=2 d=3 servo-zero=90\nsignals\nforward 5\n",
      Version::v2019, true);
  ASSERT_EQ(r.size(), 6u);
  EXPECT_TRUE(r[0].ok);
  EXPECT_EQ(r[0].detail, "logged in: device 1, id 2, WAIT");
  EXPECT_TRUE(r[1].ok);
  EXPECT_EQ(r[1].detail, "completed");
  // The TASK waits until 50 ms after the AUTH (send_gap); the answer 300 ms later.
  EXPECT_EQ(r[1].finished - r[1].started, milliseconds(350));
  EXPECT_TRUE(r[2].ok);
  EXPECT_TRUE(r[3].ok);
  EXPECT_TRUE(has(r[3].detail, "not confirmed")) << r[3].detail;
  EXPECT_EQ(r[3].finished, r[3].started);
  // Signals never answered: the timeout is the only sign, and the reason says so.
  EXPECT_FALSE(r[4].ok);
  EXPECT_EQ(r[4].finished - r[4].started, seconds(2));
  EXPECT_TRUE(has(r[4].detail, "drops a task")) << r[4].detail;
  // --keep-going: the batch went on after the failure.
  EXPECT_TRUE(r[5].ok);
  EXPECT_FALSE(runner.all_ok);

  // The vehicle got the v2019 packets: COIs 1, 2, 3 (settings), 4, 5.
  std::vector<std::uint8_t> cois;
  for (const auto& [t, m] : car.received) {
    if (const auto* task = std::get_if<svgui::Task>(&m)) cois.push_back(task->coi);
    if (const auto* s = std::get_if<svgui::Settings>(&m)) {
      cois.push_back(s->coi);
      EXPECT_EQ(s->values, (std::array<std::int32_t, 4>{1, 2, 3, 90}));
    }
  }
  EXPECT_EQ(cois, (std::vector<std::uint8_t>{1, 2, 3, 4, 5}));
}

TEST_F(SvguiRunnerOnMem, AFailureStopsTheBatchWithoutKeepGoing) {
  ScriptedVehicle car(context, executor, Version::v2019);
  SvguiConfig config;
  config.task_timeout[3] = seconds(1);
  Runner runner(context, executor, Version::v2019, config);
  const auto r = runner.run("connect\nsignals\nforward 5\n", Version::v2019);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_FALSE(r[1].ok);
  EXPECT_FALSE(runner.all_ok);
}

TEST_F(SvguiRunnerOnMem, HeadControlRepeatsSetIsAppliedAndSetRequestReadsBack) {
  ScriptedVehicle car(context, executor, Version::head);
  Runner runner(context, executor, Version::head);
  const auto r = runner.run(
      "connect\nset steering-p=2\nset-request\nset steering-p=2\ncontrol 0.5 0.25\nwait 950ms\n"
      "control off\nwait 500ms\n",
      Version::head, true);
  ASSERT_EQ(r.size(), 8u);
  EXPECT_FALSE(runner.all_ok);  // the first set
  // Without a read-back the other eleven values are unknown.
  EXPECT_FALSE(r[1].ok);
  EXPECT_TRUE(has(r[1].detail, "set-request first")) << r[1].detail;
  EXPECT_TRUE(r[2].ok);
  EXPECT_EQ(r[2].detail.rfind("steering-p=0 steering-i=0.5 steering-d=1", 0), 0u) << r[2].detail;
  EXPECT_TRUE(r[3].ok);
  EXPECT_EQ(r[3].detail, "applied");
  EXPECT_TRUE(r[4].ok);
  EXPECT_EQ(r[4].detail, "held: CONTROL every 100ms");
  EXPECT_TRUE(r[6].ok);
  EXPECT_EQ(r[6].detail, "released: CONTROL 0 0 sent");

  // The SET carried the read-back values with steering-p changed.
  const svgui::Set* sent_set = nullptr;
  std::vector<Time> controls;
  for (const auto& [t, m] : car.received) {
    if (const auto* s = std::get_if<svgui::Set>(&m)) sent_set = s;
    if (std::holds_alternative<svgui::Control>(m)) controls.push_back(t);
  }
  ASSERT_NE(sent_set, nullptr);
  EXPECT_EQ(sent_set->values[0], 2.0);
  EXPECT_EQ(sent_set->values[1], 0.5);
  EXPECT_EQ(sent_set->values[11], 5.5);
  // The first CONTROL 50 ms after the SET before it (send_gap), then one
  // every 100 ms on the grid from the control action, and the release at
  // 950 ms.
  ASSERT_EQ(controls.size(), 11u);
  EXPECT_EQ(controls[1] - controls[0], milliseconds(50));
  for (std::size_t i = 2; i < 10; ++i)
    EXPECT_EQ(controls[i] - controls[i - 1], milliseconds(100));
  EXPECT_EQ(controls[10] - controls[9], milliseconds(50));
  EXPECT_EQ(std::get<svgui::Control>(car.received.back().second), (svgui::Control{0, 0}));
}

TEST_F(SvguiRunnerOnMem, AWordRefusedByTheCoreFailsWithTheReason) {
  ScriptedVehicle car(context, executor, Version::head);
  Runner runner(context, executor, Version::head);
  const auto r = runner.run("control 0.1 0.1\nset-request\n", Version::head, true);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].detail, "refused: not connected");
  EXPECT_EQ(r[1].detail, "refused: not connected");
}

// ---- the session against hil's mock of the real vehicle programs ----

template <Version V>
struct MockVehicle : ::testing::Test {
  MockVehicle() {
    mocks::SvguiConfig config;
    config.version = V;
    mocks::ServerOptions options = test::on_mem("car");
    options.name = "wr8";
    car.start_car(sim::wr8_vehicle(), std::move(options), config);
  }
  test::VirtualCar<mocks::SvguiFirmware> car;
};

using MockHead = MockVehicle<Version::head>;
using Mock2019 = MockVehicle<Version::v2019>;

TEST_F(MockHead, LogsInGetsTheMapAndBothDataRates) {
  Runner runner(car.context, car.executor, Version::head);
  const auto r = runner.run("connect\nwait-data\nwait 2s\n", Version::head);
  ASSERT_EQ(r.size(), 3u);
  EXPECT_TRUE(runner.all_ok) << r[0].detail << " / " << r[1].detail;
  const auto& core = runner.session().core();
  EXPECT_TRUE(core.map());
  EXPECT_TRUE(core.high_freq());
  EXPECT_TRUE(core.low_freq());
  EXPECT_FALSE(core.stale(DataStream::high_freq));
  for (const auto& [t, e] : runner.events)
    EXPECT_FALSE(std::holds_alternative<ParseErrorEvent>(e)) << describe(e);
}

TEST_F(Mock2019, LogsInAndAForwardCompletes) {
  Runner runner(car.context, car.executor, Version::v2019);
  const auto r = runner.run("connect\nforward 10\n", Version::v2019);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_TRUE(runner.all_ok) << r[0].detail << " / " << r[1].detail;
  for (const auto& [t, e] : runner.events)
    EXPECT_FALSE(std::holds_alternative<ParseErrorEvent>(e)) << describe(e);
}

}  // namespace
}  // namespace hil::client::wr8
