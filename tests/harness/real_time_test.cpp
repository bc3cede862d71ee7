// The runner under the real-time driver: the reference client over real
// sockets agreeing with its virtual-time run, and external programs driven
// by the contract in docs/client-contract.md (stdin actions, result and
// event lines, placeholders, the end of the run). Times here are real, so
// the tests check order and content, never exact times.

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "harness/runner.hpp"
#include "harness/scenario_yaml.hpp"
#include "tests/harness/runner_test_support.hpp"
#include "tests/harness/scratch_dir.hpp"

namespace hil::harness {
namespace {

// The scenario pieces and the times they are given in.
using namespace test;

Scenario exec_scenario(mocks::CarKind kind, std::string command, std::vector<Step> steps) {
  Scenario s;
  s.name = "exec";
  s.car = kind;
  s.seed = 3;
  s.client = ExecClient{std::move(command), seconds(10)};
  s.steps = std::move(steps);
  s.settle = milliseconds(100);
  s.timeout = seconds(20);
  return s;
}

std::vector<std::string> lines_of(const ScenarioOutcome& o) {
  std::vector<std::string> out;
  for (const auto& r : of(o, ClientKind::output))
    out.push_back(r.data["line"].get<std::string>());
  return out;
}

// The frames the car decoded, in order: what the client made it do.
std::vector<std::string> received(const ScenarioOutcome& o) {
  std::vector<std::string> out;
  for (const auto& r : of(o, WireKind::frame))
    if (r.data["dir"] == "to_car" && r.data["stage"] == "delivered" && r.data["valid"] == true)
      out.push_back(r.data["frame"].get<std::string>());
  return out;
}

std::string summary(const ScenarioOutcome& o) {
  std::string s = o.error + "\n";
  for (const auto& st : o.steps)
    s += st.phase + " '" + st.text + "' ok=" + (st.ok ? "1" : "0") + " " + st.reason + "\n";
  for (const auto& e : o.expectations)
    s += std::string(e.passed ? "met   " : "UNMET ") + e.label + ": " + e.message + "\n";
  for (const auto& l : lines_of(o))
    s += "output: " + l + "\n";
  return s;
}

// The verdict on the clean exit every external program owes.
const ExpectationOutcome* exit_verdict(const ScenarioOutcome& o) {
  for (const auto& e : o.expectations)
    if (e.label == "the client exited with code 0 after its input closed") return &e;
  return nullptr;
}

// A client in four lines of shell: answers every action with `ok`, and
// exits when its input closes.
constexpr const char* kEchoClient = R"(while read -r line; do echo "ok $line"; done)";

TEST(ExternalClient, EachActionLineGetsItsResultAndAFailGivesItsReason) {
  const std::string client = R"(while read -r line; do
    case "$line" in
      press*) echo "[   2.0000000] FAIL $line: Not in manual mode" ;;
      *) echo "[   1.0000000] ok   $line" ;;
    esac
  done)";
  Scenario s = exec_scenario(mocks::CarKind::logi, client,
                             {action("speed 50"), action("press FWD"), action("release")});
  const ScenarioOutcome o = run_scenario(s);
  ASSERT_TRUE(o.error.empty()) << o.error;
  EXPECT_TRUE(o.real_time);
  ASSERT_EQ(o.steps.size(), 3u);
  EXPECT_TRUE(o.steps[0].ok) << summary(o);
  EXPECT_FALSE(o.steps[1].ok);
  EXPECT_EQ(o.steps[1].reason, "Not in manual mode");
  EXPECT_FALSE(o.steps[2].ran) << "the sequence stops at the failed step";
  EXPECT_FALSE(o.passed());

  const auto exits = of(o, ClientKind::exit);
  ASSERT_EQ(exits.size(), 1u) << summary(o);
  EXPECT_EQ(exits[0].data["code"], 0);
  ASSERT_NE(exit_verdict(o), nullptr);
  EXPECT_TRUE(exit_verdict(o)->passed);
}

TEST(ExternalClient, EventLinesAndOtherOutputAreRecordedForExpectations) {
  const std::string client = R"(echo "event connection connecting"
    echo "event connection connected"
    while read -r line; do
      echo "event command SP accepted"
      echo "a line of its own"
      echo "to stderr" >&2
      echo "ok $line"
    done
    echo "event connection disconnected")";
  Scenario s = exec_scenario(mocks::CarKind::logi, client, {action("speed 50")});
  s.expectations.push_back(
      expectation("the client said it connected",
                  client_record(ClientKind::connection, "state", "connected", "connected")));
  const ScenarioOutcome o = run_scenario(s);
  ASSERT_TRUE(o.passed()) << summary(o);

  const auto states = of(o, ClientKind::connection);
  ASSERT_EQ(states.size(), 3u);
  EXPECT_EQ(states[0].data["state"], "connecting");
  EXPECT_EQ(states[1].data["state"], "connected");
  EXPECT_EQ(states[2].data["state"], "disconnected");
  const auto commands = of(o, ClientKind::command);
  ASSERT_EQ(commands.size(), 1u);
  EXPECT_EQ(commands[0].data["command"], "SP");
  EXPECT_EQ(commands[0].data["state"], "accepted");
  const auto outputs = of(o, ClientKind::output);
  ASSERT_EQ(outputs.size(), 2u) << summary(o);
  for (const auto& r : outputs) {
    if (r.data["stream"] == "stdout")
      EXPECT_EQ(r.data["line"], "a line of its own");
    else
      EXPECT_EQ(r.data["line"], "to stderr");
  }
  EXPECT_LT(states[2].at, of(o, ClientKind::exit).at(0).at + milliseconds(1))
      << "what it printed on the way out is part of the run";
}

TEST(ExternalClient, PlaceholdersAndEnvironmentGiveTheCarsRealAddress) {
  // Connects to the car with the placeholders, reports the environment's
  // copy, and hangs up when its input ends.
  const std::string client =
      R"(python3 -c '
import os, socket, sys
s = socket.create_connection((sys.argv[1], int(sys.argv[2])))
print("env", os.environ["HIL_HOST"], os.environ["HIL_PORT"], os.environ["HIL_ENDPOINT"], flush=True)
print("arg", sys.argv[1], sys.argv[2], flush=True)
for line in sys.stdin:
    print("ok", line.strip(), flush=True)
s.close()
' {host} {port})";
  Scenario s =
      exec_scenario(mocks::CarKind::logi, client, {action("connect"), wait(milliseconds(200))});
  const ScenarioOutcome o = run_scenario(s);
  ASSERT_TRUE(o.passed()) << summary(o);
  const auto lines = lines_of(o);
  ASSERT_EQ(lines.size(), 2u) << summary(o);
  const auto opens = of(o, WireKind::open);
  ASSERT_EQ(opens.size(), 1u) << "the program reached the mock car";
  // "arg 127.0.0.1 PORT": a real port, and the same in the environment.
  ASSERT_EQ(lines[1].rfind("arg 127.0.0.1 ", 0), 0u) << lines[1];
  const std::string port = lines[1].substr(std::string("arg 127.0.0.1 ").size());
  EXPECT_GT(std::stoi(port), 0);
  EXPECT_EQ(lines[0], "env 127.0.0.1 " + port + " tcp://127.0.0.1:" + port);
  EXPECT_EQ(of(o, WireKind::close).size(), 1u);
}

TEST(ExternalClient, ASerialCarGivesThePathOfItsPty) {
  const std::string client = R"sh(while read -r line; do
    if [ -c "$(readlink -f {pty})" ];
  then echo "ok $line";
  else echo "fail $line: no pty at {pty}"; fi
  done)sh";
  Scenario s = exec_scenario(mocks::CarKind::arduino, client, {action("V")});
  // It never opens the port: its first action comes after its startup
  // timeout, and it has that long again to answer it.
  s.client = ExecClient{client, seconds(1)};
  const ScenarioOutcome o = run_scenario(s);
  EXPECT_TRUE(o.passed()) << summary(o);
  ASSERT_EQ(o.steps.size(), 1u);
  EXPECT_GE(o.steps[0].started, seconds(1)) << "handed over at the startup timeout";
}

TEST(ExternalClient, ASerialCarsStepsBeginWhenTheProgramOpensThePort) {
  // Starts slowly (as an interpreter may), then holds the port open.
  const std::string client = R"sh(sleep 0.5; exec 3<>{pty}
  while read -r line; do echo "ok $line"; done)sh";
  Scenario s = exec_scenario(mocks::CarKind::arduino, client, {action("PING")});
  const ScenarioOutcome o = run_scenario(s);
  EXPECT_TRUE(o.passed()) << summary(o);
  const auto opens = of(o, WireKind::open);
  ASSERT_FALSE(opens.empty()) << summary(o);
  ASSERT_EQ(o.steps.size(), 1u);
  EXPECT_GE(opens[0].at, milliseconds(500)) << "the program slept first";
  EXPECT_GE(o.steps[0].started, opens[0].at) << "the step waited for the port";
  EXPECT_LT(o.steps[0].started, opens[0].at + milliseconds(500))
      << "and began once it was open (a generous bound for a loaded machine)";
}

TEST(ExternalClient, AProgramThatExitsBeforeItsFirstContactFailsItsStepAtOnce) {
  Scenario s = exec_scenario(mocks::CarKind::leka, "exit 4", {action("info")});
  const ScenarioOutcome o = run_scenario(s);
  EXPECT_FALSE(o.passed());
  ASSERT_EQ(o.steps.size(), 1u);
  EXPECT_FALSE(o.steps[0].ok);
  EXPECT_LT(o.steps[0].started, seconds(5))
      << "the exit is a sign: the steps do not wait out the 10 s startup timeout";
}

TEST(ExternalClient, AProgramThatExitsEarlyFailsTheActionsItOwes) {
  Scenario s = exec_scenario(mocks::CarKind::logi, "read -r line; exit 3",
                             {action("speed 50"), action("speed 80")});
  const ScenarioOutcome o = run_scenario(s);
  ASSERT_TRUE(o.error.empty()) << o.error;
  EXPECT_FALSE(o.passed());
  ASSERT_EQ(o.steps.size(), 2u);
  EXPECT_FALSE(o.steps[0].ok);
  EXPECT_EQ(o.steps[0].reason, "the client exited with code 3 before answering");
  const auto exits = of(o, ClientKind::exit);
  ASSERT_EQ(exits.size(), 1u);
  EXPECT_EQ(exits[0].data["code"], 3);
  ASSERT_NE(exit_verdict(o), nullptr);
  EXPECT_FALSE(exit_verdict(o)->passed) << "exit code 3 is not a clean exit";
}

TEST(ExternalClient, AProgramThatWillNotEndIsKilledAndFailsTheRun) {
  // Ignores SIGTERM (so do the sleeps it starts) and never exits.
  const std::string client =
      R"(trap "" TERM; while read -r line; do echo "ok $line"; done; while :; do sleep 0.05; done)";
  Scenario s = exec_scenario(mocks::CarKind::logi, client, {action("speed 50")});
  const ScenarioOutcome o = run_scenario(s);
  ASSERT_TRUE(o.error.empty()) << o.error;
  EXPECT_TRUE(o.steps[0].ok);
  EXPECT_FALSE(o.passed());
  const auto exits = of(o, ClientKind::exit);
  ASSERT_EQ(exits.size(), 1u) << summary(o);
  EXPECT_EQ(exits[0].data["signal"], 9);
  EXPECT_EQ(exits[0].data["killed"], true);
  const auto notices = of(o, ClientKind::notice);
  ASSERT_EQ(notices.size(), 2u);
  EXPECT_EQ(notices[0].data["text"],
            "the client did not exit within 5 s of its input closing: sent SIGTERM");
  EXPECT_EQ(notices[1].data["text"], "the client ignored SIGTERM for 2 s: sent SIGKILL");
  ASSERT_NE(exit_verdict(o), nullptr);
  EXPECT_FALSE(exit_verdict(o)->passed);
}

TEST(ExternalClient, TheProgramInheritsNoSocketOrFileOfHils) {
  // The car's listener is open in hil while the program starts; a program
  // holding it (or another run's connection, under hil run -j) would keep
  // connections alive that the scenario closes.
  // The shell's own descriptors, listed by a child so listing opens none.
  const std::string client = R"sh(python3 -c '
import os
fds = "/proc/%d/fd" % os.getppid()
for n in sorted(os.listdir(fds), key=int):
    if int(n) > 2:
        print("extra fd", n, "->", os.readlink(fds + "/" + n))
'
  while read -r line; do echo "ok"; done)sh";
  Scenario s = exec_scenario(mocks::CarKind::logi, client, {action("speed 50")});
  const ScenarioOutcome o = run_scenario(s);
  EXPECT_TRUE(o.passed()) << summary(o);
  EXPECT_EQ(lines_of(o), std::vector<std::string>{}) << summary(o);
}

TEST(ExternalClient, AnOkResultHasNoReason) {
  Scenario s = exec_scenario(mocks::CarKind::logi, kEchoClient, {action("speed 50")});
  const ScenarioOutcome o = run_scenario(s);
  ASSERT_TRUE(o.passed()) << summary(o);
  const auto actions = of(o, ClientKind::action);
  ASSERT_EQ(actions.size(), 1u);
  EXPECT_EQ(actions[0].data["reason"], "");
}

TEST(ExternalClient, WhatTheProgramDoesAfterItsInputClosedIsNotJudgedByTheScenario) {
  // A last frame-like output after the end: the scenario's "never" does
  // not see it; the clean exit is still required.
  const std::string client =
      R"sh(while read -r line; do echo "ok"; done; echo "event command ST:STOP accepted")sh";
  Scenario s = exec_scenario(mocks::CarKind::logi, client, {action("speed 50")});
  s.expectations.push_back(expectation(
      "no ST:STOP during the session",
      client_record(ClientKind::command, "command", "ST:STOP", "ST:STOP"), Quantifier::never));
  const ScenarioOutcome o = run_scenario(s);
  EXPECT_TRUE(o.passed()) << summary(o);
  EXPECT_EQ(of(o, ClientKind::command).size(), 1u) << "still in the timeline";
  EXPECT_EQ(o.expectations.size(), 3u) << "the scenario's, the clean exit, the car at rest";
}

TEST(ExternalClient, ACommandThatDoesNotExistSaysSo) {
  Scenario s =
      exec_scenario(mocks::CarKind::logi, "./no-such-client {host} {port}", {action("connect")});
  const ScenarioOutcome o = run_scenario(s);
  EXPECT_FALSE(o.passed());
  EXPECT_EQ(o.steps[0].reason,
            "the client exited with code 127 (the shell found no such command) before answering");
  const auto lines = lines_of(o);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("no-such-client"), std::string::npos) << "the shell's own words";
}

TEST(ExternalClient, AnExpectationOnTheExitCodeReplacesTheCleanExitRule) {
  Scenario s =
      exec_scenario(mocks::CarKind::logi, R"(while read -r line; do echo "ok $line"; done; exit 4)",
                    {action("speed 50")});
  s.expectations.push_back(
      expectation("exits with 4", client_record(ClientKind::exit, "code", 4, "exit 4")));
  const ScenarioOutcome o = run_scenario(s);
  EXPECT_TRUE(o.passed()) << summary(o);
  EXPECT_EQ(exit_verdict(o), nullptr);
  EXPECT_EQ(o.expectations.size(), 2u) << "the scenario's, the car at rest";
}

TEST(ExternalClient, AnUnknownPlaceholderIsAnErrorBeforeAnythingStarts) {
  Scenario s = exec_scenario(mocks::CarKind::logi, kEchoClient, {action("speed 50")});
  RunOptions options;
  options.client_exec = "client --host {hots}";
  const ScenarioOutcome o = run_scenario(s, options);
  EXPECT_EQ(o.error,
            "the client command 'client --host {hots}': column 15: unknown placeholder '{hots}' "
            "(known: {host}, {port}, {endpoint}, {pty}, {actions}, {scenario}, {profile})");
  EXPECT_FALSE(o.passed());
}

TEST(ExternalClient, TheActionsFileHoldsEveryActionInScenarioOrder) {
  Scenario s = exec_scenario(mocks::CarKind::logi,
                             R"(while read -r line; do echo "ok $line"; done; cat {actions})",
                             {action("speed 50"), wait(milliseconds(10)), action("mode MAN")});
  s.setup = {action("connect")};
  s.teardown = {action("disconnect")};
  const ScenarioOutcome o = run_scenario(s);
  ASSERT_TRUE(o.passed()) << summary(o);
  EXPECT_EQ(lines_of(o),
            (std::vector<std::string>{"connect", "speed 50", "mode MAN", "disconnect"}));
}

// ------------------------------------------------ the origin and the end

// A LOGI client in Python's standard library: `connect` opens the car's
// TCP port, the MAN actions become their frames, every action is answered
// `ok`. With "stop" as its argument it sends MV:STOP when its input ends,
// as the contract asks, and waits for the car's answer; without, it walks
// away from a moving car.
constexpr const char* kPythonLogiClient = R"py(
import os, socket, sys
def frame(payload):
    body = ("LOGI:" + payload).encode()
    return body + b":%02X#" % (sum(body) & 0xFF)
FRAMES = {"mode MAN": "MD:MAN", "speed 50": "SP:050", "press FWD": "MV:FWD"}
car = None
for line in sys.stdin:
    action = line.strip()
    if action == "connect":
        car = socket.create_connection((os.environ["HIL_HOST"], int(os.environ["HIL_PORT"])))
        print("event connection connected", flush=True)
    elif action in FRAMES:
        car.sendall(frame(FRAMES[action]))
    print("ok", flush=True)
if car is not None and sys.argv[1:] == ["stop"]:
    car.sendall(frame("MV:STOP"))
    # Exit only once the car has answered the stop (its second FB:MV; the
    # first answered FWD): closing with bytes unread sends a reset, which
    # can discard the stop before hil has read it.
    seen = b""
    while seen.count(b"FB:MV") < 2:
        chunk = car.recv(4096)
        if not chunk:
            break
        seen += chunk
)py";

/// The Python client above, in `dir`, started after `delay` of its own.
std::string python_client(const hil::test::ScratchDir& dir, const std::string& delay,
                          const std::string& args = "") {
  const auto script = dir.path() / "client.py";
  std::ofstream(script) << kPythonLogiClient;
  return "sleep " + delay + "; exec python3 " + script.string() + " " + args;
}

TEST(ExternalClientOrigin, AClientThatTakes2sToStartStillMeetsAWindowFromTheStart) {
  const hil::test::ScratchDir dir("hil-origin");
  Scenario s = exec_scenario(mocks::CarKind::logi, python_client(dir, "2"),
                             {action("connect"), wait(milliseconds(600))});
  // "connected within 500 ms of the start": the start is the program's
  // first connection, 2 s and more after hil started it.
  Expectation connected = expectation(
      "connected within 500 ms", client_record(ClientKind::connection, "state", "connected", "c"));
  connected.window.within = milliseconds(500);
  s.expectations.push_back(connected);
  s.schedule.push_back(ScheduledStep{Anchor{std::nullopt, 1, milliseconds(300)},
                                     step_of("wait 1ms", WaitStep{milliseconds(1)})});
  // The car hangs up 400 ms into the run: 400 ms after the origin.
  link::FaultRule hang_up;
  hang_up.trigger.at = Time(milliseconds(400));
  hang_up.action = link::Reset{};
  s.faults.rules.push_back(hang_up);
  const ScenarioOutcome o = run_scenario(s);
  ASSERT_TRUE(o.passed()) << summary(o);

  const auto origins = of(o, ClientKind::origin);
  ASSERT_EQ(origins.size(), 1u) << summary(o);
  EXPECT_EQ(origins[0].data["cause"], "connection");
  const auto opens = of(o, WireKind::open);
  ASSERT_FALSE(opens.empty());
  EXPECT_EQ(origins[0].at, opens[0].at) << "the car accepting the connection";
  EXPECT_GE(origins[0].at, seconds(2)) << "the program slept 2 s first";
  const std::string text = origins[0].data["text"];
  EXPECT_EQ(text.rfind("origin: the client's first connection at +2.", 0), 0u) << text;
  // The step scheduled `at: 300ms` counts from there too.
  const StepOutcome& scheduled = o.steps.back();
  EXPECT_EQ(scheduled.phase, "schedule");
  EXPECT_TRUE(scheduled.ran);
  EXPECT_GE(scheduled.started, origins[0].at + milliseconds(300));
  const auto resets = of(o, link::FaultKind::reset);
  ASSERT_EQ(resets.size(), 1u) << summary(o);
  EXPECT_GE(resets[0].at, origins[0].at + milliseconds(400));
  const auto closes = of(o, WireKind::close);
  ASSERT_FALSE(closes.empty());
  EXPECT_LT(closes[0].at, o.session_end) << "the hang-up came during the session";
}

// A client that answers its first action before it connects, and takes
// 300 ms to connect: its origin is that first result line.
constexpr const char* kAnswersBeforeConnecting = R"py(
import os, socket, sys, time
car = None
for line in sys.stdin:
    if line.strip() == "connect":
        time.sleep(0.3)
        car = socket.create_connection((os.environ["HIL_HOST"], int(os.environ["HIL_PORT"])))
        print("event connection connected", flush=True)
    print("ok", flush=True)
)py";

TEST(ExternalClientOrigin, TheCarsClockCountsFromAFirstResultLineThatCameBeforeTheConnection) {
  const hil::test::ScratchDir dir("hil-origin-result");
  const auto script = dir.path() / "client.py";
  std::ofstream(script) << kAnswersBeforeConnecting;
  Scenario s = exec_scenario(mocks::CarKind::logi, "exec python3 " + script.string(),
                             {action("mode MAN"), action("connect"), wait(milliseconds(1300))});
  const ScenarioOutcome o = run_scenario(s);
  ASSERT_TRUE(o.passed()) << summary(o);
  const auto origins = of(o, ClientKind::origin);
  ASSERT_EQ(origins.size(), 1u) << summary(o);
  EXPECT_EQ(origins[0].data["cause"], "result") << origins[0].data.dump();
  const auto opens = of(o, WireKind::open);
  ASSERT_FALSE(opens.empty());
  EXPECT_GE(opens[0].at, origins[0].at + milliseconds(300)) << "connected 300 ms after";
  // The car's STATs are on its 500 ms grid from the origin, as they are
  // from time 0 with the reference client: the first at +505 ms (its
  // 5 ms reply latency), not 500 ms after the connection (+805 ms and
  // later). Real time: within 100 ms.
  std::optional<Time> first_stat;
  for (const auto& r : of(o, WireKind::frame)) {
    if (r.data["dir"] == "to_client" && r.data["frame"].get<std::string>().starts_with("STAT")) {
      first_stat = r.at;
      break;
    }
  }
  ASSERT_TRUE(first_stat.has_value()) << summary(o);
  const auto after_origin = *first_stat - origins[0].at;
  EXPECT_GE(after_origin, milliseconds(505)) << link::format_ms(*first_stat);
  EXPECT_LT(after_origin, milliseconds(605)) << link::format_ms(*first_stat);
}

TEST(ExternalClientEnd, AProgramThatExitsLeavingTheCarMovingFailsTheRun) {
  const hil::test::ScratchDir dir("hil-end");
  const std::vector<Step> drive = {action("connect"), action("mode MAN"), action("speed 50"),
                                   action("press FWD"), wait(milliseconds(500))};
  Scenario s = exec_scenario(mocks::CarKind::logi, python_client(dir, "0"), drive);
  const ScenarioOutcome walked_away = run_scenario(s);
  EXPECT_FALSE(walked_away.passed());
  const auto& end = walked_away.expectations.back();
  EXPECT_FALSE(end.passed) << summary(walked_away);
  EXPECT_EQ(end.message.rfind("the car was still moving 1.0 s after the client exited (", 0), 0u)
      << end.message;
  EXPECT_NE(end.message.find("): a client stops the car when its input ends "
                             "(docs/client-contract.md, section 4)"),
            std::string::npos)
      << end.message;
  ASSERT_NE(exit_verdict(walked_away), nullptr);
  EXPECT_TRUE(exit_verdict(walked_away)->passed) << "its exit itself was clean";

  s.at_end = AtEnd::moving;
  const ScenarioOutcome on_purpose = run_scenario(s);
  EXPECT_TRUE(on_purpose.passed()) << summary(on_purpose);

  s.at_end = AtEnd::at_rest;
  s.client = ExecClient{python_client(dir, "0", "stop"), seconds(10)};
  const ScenarioOutcome stopped = run_scenario(s);
  EXPECT_TRUE(stopped.passed()) << summary(stopped);
  EXPECT_EQ(stopped.expectations.back().message,
            "the car was at rest 1.0 s after the client exited");
}

// One scenario, both drivers: the reference client makes the car do the
// same things in the same order over real TCP as over mem:// in virtual time.
TEST(RealTimeReference, AgreesWithTheVirtualTimeRunOfTheSameScenario) {
  Scenario s = load_scenario(std::string(HIL_SOURCE_DIR) + "/scenarios/logi/logi-buttons.yaml");
  const ScenarioOutcome virtual_run = run_scenario(s);
  ASSERT_TRUE(virtual_run.passed()) << summary(virtual_run);
  EXPECT_FALSE(virtual_run.real_time);

  s.client = ReferenceClient{true};
  const ScenarioOutcome real_run = run_scenario(s);
  ASSERT_TRUE(real_run.passed()) << summary(real_run);
  EXPECT_TRUE(real_run.real_time);

  EXPECT_EQ(received(real_run), received(virtual_run));
  EXPECT_EQ(received(real_run).size(), 20u) << "the twenty buttons";
  // Each step ran, in both, and real time took at least the waits' 2 s.
  ASSERT_EQ(real_run.steps.size(), virtual_run.steps.size());
  for (std::size_t i = 0; i < real_run.steps.size(); ++i)
    EXPECT_EQ(real_run.steps[i].ok, virtual_run.steps[i].ok) << real_run.steps[i].text;
  EXPECT_GE(real_run.run_time, seconds(2));
  EXPECT_GE(real_run.wall_seconds, 2.0);
}

}  // namespace
}  // namespace hil::harness
