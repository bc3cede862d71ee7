// logi-client --stdin-actions as hil runs it: actions written to its stdin
// one at a time against `hil mock logi` over real TCP, one result line
// each, the contract's event lines, and the way out when stdin closes.
// Every wait is bounded.

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "apps/logi-client/stdin_actions.hpp"
#include "tests/apps/logi-client/logi_client_support.hpp"

namespace hil::test {
namespace {

using namespace std::chrono_literals;
namespace lc = hil::apps::logi_client;
namespace logi = hil::client::logi;

HilProcess stdin_client(const std::string& port, std::vector<std::string> extra = {}) {
  std::vector<std::string> args{"--stdin-actions", "--host", "127.0.0.1", "--port", port};
  args.insert(args.end(), extra.begin(), extra.end());
  return HilProcess(LOGI_CLIENT_BINARY, args);
}

/// Closes the client's stdin, as hil does at the end of a scenario: it
/// exits 0.
void expect_exit_0_at_end_of_input(HilProcess& client) {
  client.close_stdin();
  EXPECT_EQ(client.wait_exit(10s), 0) << client.output();
}

/// Lines written to the client's stdin at once, and the lines it answers
/// them with, in order, each within `limit`.
struct Exchange {
  std::string input;
  std::vector<std::string> answers;
  std::chrono::milliseconds limit = 10s;
};

/// Each exchange in turn: its input written once the answers to the one
/// before have come.
void converse(HilProcess& client, const std::vector<Exchange>& exchanges) {
  for (const Exchange& e : exchanges) {
    if (!e.input.empty()) ASSERT_TRUE(client.write_stdin(e.input));
    expect_lines(client, e.answers, e.limit);
  }
}

// ---- the pieces, without a car ----

TEST(LogiClientStdinActionLines, EventLinesNameStatesAsHilsReferenceClientRecordsThem) {
  using logi::ConnectionState;
  EXPECT_EQ(lc::contract_event_line(logi::ConnectionEvent{ConnectionState::connecting, 0}),
            "event connection connecting");
  EXPECT_EQ(lc::contract_event_line(logi::ConnectionEvent{ConnectionState::connected, 0}),
            "event connection connected");
  EXPECT_EQ(lc::contract_event_line(logi::ConnectionEvent{ConnectionState::reconnecting, 2}),
            "event connection reconnecting");
  EXPECT_EQ(lc::contract_event_line(logi::ConnectionEvent{ConnectionState::disconnected, 0}),
            "event connection disconnected");
  logi::CommandEvent sent{7, protocol::logi::SetSpeed{50}, logi::CommandState::sent, 1, false};
  EXPECT_EQ(lc::contract_event_line(sent), "event command SP sent");
  logi::CommandEvent move{8, protocol::logi::Move{protocol::logi::Direction::fwd},
                          logi::CommandState::uncertain, 1, false};
  EXPECT_EQ(lc::contract_event_line(move), "event command MV:FWD uncertain");
  EXPECT_EQ(lc::contract_event_line(logi::StaleEvent{true}), "event stale");
  EXPECT_EQ(lc::contract_event_line(logi::StaleEvent{false}), "event fresh");
  EXPECT_EQ(lc::contract_event_line(logi::NoticeEvent{"Not in manual mode,\nswitching to MAN"}),
            "event notice Not in manual mode, switching to MAN");
  protocol::DecodeError bad;
  bad.kind = protocol::ErrorKind::bad_checksum;
  bad.detail = "expected 35, got 00";
  EXPECT_EQ(
      lc::contract_event_line(logi::ParseErrorEvent{bad}),
      "event parse_error " + std::string(protocol::to_string(bad.kind)) + ": expected 35, got 00");
  EXPECT_EQ(lc::contract_event_line(logi::MovementEvent{false, "not connected"}),
            "event movement disabled not connected");
  EXPECT_EQ(lc::contract_event_line(logi::MovementEvent{true, ""}), "event movement enabled");
  // Telemetry is on the wire; hil needs no line for it.
  EXPECT_EQ(lc::contract_event_line(logi::StatusEvent{}), std::nullopt);
}

TEST(LogiClientStdinActionLines, ALineIsAnActionABlankOrCommentOrAnErrorWithItsColumn) {
  const auto action = lc::parse_action_line(3, "  speed 50   # slow\r");
  ASSERT_TRUE(action.step);
  EXPECT_EQ(action.step->line, 3);
  EXPECT_EQ(action.step->text, "speed 50");
  EXPECT_EQ(action.step->action, logi::OperatorAction{logi::op::Speed{50}});
  EXPECT_TRUE(action.error.empty());

  const auto comment = lc::parse_action_line(4, "   # nothing to do");
  EXPECT_FALSE(comment.step);
  EXPECT_TRUE(comment.error.empty());

  const auto typo = lc::parse_action_line(5, "press FORWARD");
  EXPECT_FALSE(typo.step);
  EXPECT_EQ(typo.text, "press FORWARD");
  EXPECT_EQ(typo.error,
            "column 7: expected a direction (STOP, FWD, BWD, LEFT, RIGHT, LF, RF, LB, RB, CW, "
            "CCW), got 'FORWARD'");
}

// ---- against the mock car ----

struct LogiClientStdinActions : LogiClientTest {
  LogiClientStdinActions() : LogiClientTest("logi-client-stdin") {}
};

TEST_F(LogiClientStdinActions, AnswersEachActionAsItArrivesAndStopsTheCarWhenStdinCloses) {
  const std::string wire = temp.file("wire.ndjson");
  ASSERT_NO_FATAL_FAILURE(start_car({"--log", wire}));
  auto client = stdin_client(port);

  // Each result comes while stdin is still open, before the next action
  // is written: the actions are run as they arrive, not read to the end.
  ASSERT_NO_FATAL_FAILURE(converse(
      client,
      {{"connect\n",
        {"event connection connecting", "event connection connected", "] ok   connect"}},
       {"speed 50\n", {"event command SP sent", "event command SP accepted", "] ok   speed 50"}},
       {"mode MAN\n", {"] ok   mode MAN"}},
       {"press FWD\n", {"event command MV:FWD accepted", "] ok   press FWD"}}}));

  // hil closes stdin at the end of a scenario; the car is still moving.
  client.close_stdin();
  expect_lines(client, {"emergency stop: MV:STOP", "event command MV:STOP accepted",
                        "event connection disconnected"});
  EXPECT_EQ(client.wait_exit(10s), 0) << client.output();

  ASSERT_EQ(mock->stop(), 0) << mock->output();
  const auto frames = delivered_to_car(read_file(wire));
  ASSERT_FALSE(frames.empty());
  EXPECT_TRUE(contains(frames.back(), "LOGI:MV:STOP:88#")) << frames.back();
}

TEST_F(LogiClientStdinActions, AMoveTheCarRefusedIsNoReasonForAStopAtTheEnd) {
  const std::string wire = temp.file("wire.ndjson");
  ASSERT_NO_FATAL_FAILURE(start_car(
      {"--behaviours", "scenarios/clients/logi-client/car-refuses-moves.yaml", "--log", wire}));
  auto client = stdin_client(port);
  ASSERT_TRUE(client.write_stdin("connect\nspeed 50\nmode MAN\npress FWD\n"));
  expect_lines(client, {"] FAIL press FWD: rejected by the car (FB:MV:0)"});
  expect_exit_0_at_end_of_input(client);
  EXPECT_FALSE(contains(client.output(), "emergency stop")) << client.output();
  ASSERT_EQ(mock->stop(), 0) << mock->output();
  for (const auto& frame : delivered_to_car(read_file(wire)))
    EXPECT_FALSE(contains(frame, "MV:STOP")) << frame;
}

TEST_F(LogiClientStdinActions, ABadLineOrARefusedActionFailsThatLineOnlyAndTheExitIsStill0) {
  ASSERT_NO_FATAL_FAILURE(start_car());
  auto client = stdin_client(port);
  // All at once: the answers still come one per action line, in order.
  ASSERT_TRUE(
      client.write_stdin("connect\n"
                         "press FORWARD\n"
                         "\n"
                         "# a comment is not an action\n"
                         "station 7\n"
                         "press FWD\n"
                         "speed 30\n"
                         "disconnect\n"));
  expect_lines(client, {"] ok   connect", "] FAIL press FORWARD: column 7: expected a direction",
                        "] FAIL station 7: rejected by the car (FB:GS:0)",
                        "] FAIL press FWD: refused: movement needs a 'mode' and a 'speed' on "
                        "this connection first",
                        "] ok   speed 30", "] ok   disconnect"});
  expect_exit_0_at_end_of_input(client);

  // Six action lines, six results: the blank and the comment line get none.
  const std::string& out = client.output();
  int results = 0;
  for (const char* verdict : {"] ok   ", "] FAIL "})
    for (std::size_t at = out.find(verdict); at != std::string::npos;
         at = out.find(verdict, at + 1))
      ++results;
  EXPECT_EQ(results, 6) << out;
}

TEST_F(LogiClientStdinActions, ConfirmSendsAgainTheRunWhoseFeedbackWasLost) {
  ASSERT_NO_FATAL_FAILURE(start_car_with_faults(
      "lost.yaml", "rules:\n  - {kind: drop, direction: to_client, match: \"FB:ST\", first: 1}\n"));
  auto client = stdin_client(port);
  // Each action has its own runner; `confirm` still knows what went unanswered.
  ASSERT_NO_FATAL_FAILURE(
      converse(client, {{"connect\nspeed 50\nmode AUTO\nstation 2\nrun\n",
                         {"event command ST:RUN uncertain", "] FAIL run: no feedback to ST:RUN"}},
                        {"confirm\n", {"event command ST:RUN accepted", "] ok   confirm"}},
                        {"stop\n", {"] ok   stop"}}}));
  expect_exit_0_at_end_of_input(client);
}

TEST_F(LogiClientStdinActions, AnEmergencyStopGoesOutAtOnceBesideAnActionAwaitingFeedback) {
  ASSERT_NO_FATAL_FAILURE(start_car_with_faults(
      "lost-sp.yaml", "rules:\n  - {kind: drop, direction: to_car, match: \"SP\", first: 1}\n"));
  auto client = stdin_client(port);
  // The SP never reached the car: it is sent again only after 800 ms. The
  // stop does not wait for that, but its result line keeps its place after
  // the speed's.
  ASSERT_NO_FATAL_FAILURE(
      converse(client, {{"connect\nmode MAN\nspeed 60\n", {"event command SP sent"}},
                        {"estop\n",
                         {"event command MV:STOP accepted", "event command SP sent",
                          "] ok   speed 60", "] ok   estop"}}}));
  expect_exit_0_at_end_of_input(client);
}

TEST_F(LogiClientStdinActions, TheStaleWarningAndItsEndAreEventLines) {
  ASSERT_NO_FATAL_FAILURE(start_car_with_faults(
      "mute.yaml", "rules:\n  - {kind: stall, direction: to_client, at: 1s, for: 3s}\n"));
  auto client = stdin_client(port);
  ASSERT_NO_FATAL_FAILURE(converse(
      client, {{"connect\n", {"] ok   connect"}}, {"", {"event stale", "event fresh"}, 15s}}));
  expect_exit_0_at_end_of_input(client);
}

TEST_F(LogiClientStdinActions, NoCarMeansAFailedConnectWithReconnectingEventsAndAStill0Exit) {
  const ClosedPort closed;
  auto client = stdin_client(closed.port(), {"--connect-timeout", "1500ms"});
  ASSERT_TRUE(client.write_stdin("connect\n"));
  expect_lines(client,
               {"event connection reconnecting", "] FAIL connect: not connected after 1.5s"});
  expect_exit_0_at_end_of_input(client);
}

TEST_F(LogiClientStdinActions, CtrlCCancelsTheActionUnderWayAndExits130) {
  ASSERT_NO_FATAL_FAILURE(start_car());
  auto client = stdin_client(port);
  ASSERT_TRUE(client.write_stdin("connect\nwait 1m\n"));
  expect_lines(client, {"] ok   connect"});
  EXPECT_EQ(client.interrupt(10s), 130) << client.output();
  expect_contains(client.output(), {"] FAIL wait 1m: cancelled", "event connection disconnected"});
}

// Ctrl-C can come at any moment: while an action runs, between two actions,
// or after an action was taken but before its first turn. Every line taken
// still gets exactly one result line.
TEST_F(LogiClientStdinActions, CtrlCAtAnyMomentAnswersEveryLineOnce) {
  ASSERT_NO_FATAL_FAILURE(start_car());
  for (int round = 0; round < 5; ++round) {
    auto client = stdin_client(port);
    ASSERT_TRUE(client.write_stdin("connect\nwait 1m\nwait 2m\n"));
    expect_lines(client, {round % 2 == 0 ? "event connection connecting" : "] ok   connect"});
    EXPECT_EQ(client.interrupt(10s), 130) << client.output();
    const std::string& out = client.output();
    const int connect_results = static_cast<int>(contains(out, "] ok   connect")) +
                                static_cast<int>(contains(out, "] FAIL connect: cancelled"));
    EXPECT_EQ(connect_results, 1) << out;
    expect_contains(out, {"] FAIL wait 1m: cancelled", "] FAIL wait 2m: cancelled"});
  }
}

TEST_F(LogiClientStdinActions, StdinActionsWithAScriptOrActionsIsAUsageError) {
  const auto result = run_to_exit(LOGI_CLIENT_BINARY, {"--stdin-actions", "connect"});
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_TRUE(contains(result.output, "--stdin-actions reads the actions from stdin"))
      << result.output;
}

}  // namespace
}  // namespace hil::test
