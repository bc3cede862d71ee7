// logi-client --stdin-actions as hil runs it: actions written to its stdin
// one at a time against `hil mock logi` over real TCP, one result line
// each, the contract's event lines, and the way out when stdin closes.
// Every wait is bounded.

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "apps/logi-client/stdin_actions.hpp"
#include "tests/apps/client_program_support.hpp"

namespace hil::test {
namespace {

using namespace std::chrono_literals;
namespace lc = hil::apps::logi_client;
namespace logi = hil::client::logi;

struct MockLogi : MockCar {
  explicit MockLogi(std::vector<std::string> extra = {})
      : MockCar(mock_on_tcp_args("logi", with_seed(std::move(extra))), kTcpReady) {}
  static std::vector<std::string> with_seed(std::vector<std::string> extra) {
    extra.insert(extra.begin(), {"--seed", "1"});
    return extra;
  }
};

HilProcess stdin_client(const std::string& port, std::vector<std::string> extra = {}) {
  std::vector<std::string> args{"--stdin-actions", "--host", "127.0.0.1", "--port", port};
  args.insert(args.end(), extra.begin(), extra.end());
  return HilProcess(LOGI_CLIENT_BINARY, args);
}

// ---- the pieces, without a car ----

TEST(LogiClientStdinActions, EventLinesNameStatesAsHilsReferenceClientRecordsThem) {
  using logi::ConnectionState;
  EXPECT_EQ(lc::contract_event_line(logi::ConnectionEvent{ConnectionState::connecting, 0}),
            "event connection connecting");
  EXPECT_EQ(lc::contract_event_line(logi::ConnectionEvent{ConnectionState::connected, 0}),
            "event connection connected");
  EXPECT_EQ(
      lc::contract_event_line(logi::ConnectionEvent{ConnectionState::reconnecting, 2}),
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

TEST(LogiClientStdinActions, ALineIsAnActionABlankOrCommentOrAnErrorWithItsColumn) {
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

TEST(LogiClientStdinActions, AnswersEachActionAsItArrivesAndStopsTheCarWhenStdinCloses) {
  const TempDir temp("logi-client-stdin");
  const std::string wire = temp.file("wire.ndjson");
  MockLogi car({"--log", wire});
  ASSERT_FALSE(car.port().empty()) << car.output();
  auto client = stdin_client(car.port());

  // Each result comes while stdin is still open, before the next action
  // is written: the actions are run as they arrive, not read to the end.
  ASSERT_TRUE(client.write_stdin("connect\n"));
  EXPECT_TRUE(client.wait_for_line("event connection connecting")) << client.output();
  EXPECT_TRUE(client.wait_for_line("event connection connected")) << client.output();
  EXPECT_TRUE(client.wait_for_line("] ok   connect")) << client.output();

  ASSERT_TRUE(client.write_stdin("speed 50\n"));
  EXPECT_TRUE(client.wait_for_line("event command SP sent")) << client.output();
  EXPECT_TRUE(client.wait_for_line("event command SP accepted")) << client.output();
  EXPECT_TRUE(client.wait_for_line("] ok   speed 50")) << client.output();

  ASSERT_TRUE(client.write_stdin("mode MAN\n"));
  EXPECT_TRUE(client.wait_for_line("] ok   mode MAN")) << client.output();
  ASSERT_TRUE(client.write_stdin("press FWD\n"));
  EXPECT_TRUE(client.wait_for_line("event command MV:FWD accepted")) << client.output();
  EXPECT_TRUE(client.wait_for_line("] ok   press FWD")) << client.output();

  // hil closes stdin at the end of a scenario; the car is still moving.
  client.close_stdin();
  EXPECT_TRUE(client.wait_for_line("emergency stop: MV:STOP")) << client.output();
  EXPECT_TRUE(client.wait_for_line("event command MV:STOP accepted")) << client.output();
  EXPECT_TRUE(client.wait_for_line("event connection disconnected")) << client.output();
  EXPECT_EQ(client.wait_exit(10s), 0) << client.output();

  ASSERT_EQ(car.stop(), 0) << car.output();
  const auto frames = delivered_to_car(read_file(wire));
  ASSERT_FALSE(frames.empty());
  EXPECT_TRUE(contains(frames.back(), "LOGI:MV:STOP:88#")) << frames.back();
}

TEST(LogiClientStdinActions, AMoveTheCarRefusedIsNoReasonForAStopAtTheEnd) {
  const TempDir temp("logi-client-stdin-refused");
  const std::string wire = temp.file("wire.ndjson");
  MockLogi car(
      {"--behaviours", "scenarios/clients/logi-client/car-refuses-moves.yaml", "--log", wire});
  ASSERT_FALSE(car.port().empty()) << car.output();
  auto client = stdin_client(car.port());
  ASSERT_TRUE(client.write_stdin("connect\nspeed 50\nmode MAN\npress FWD\n"));
  EXPECT_TRUE(client.wait_for_line("] FAIL press FWD: rejected by the car (FB:MV:0)"))
      << client.output();
  client.close_stdin();
  EXPECT_EQ(client.wait_exit(10s), 0) << client.output();
  EXPECT_FALSE(contains(client.output(), "emergency stop")) << client.output();
  ASSERT_EQ(car.stop(), 0) << car.output();
  for (const auto& frame : delivered_to_car(read_file(wire)))
    EXPECT_FALSE(contains(frame, "MV:STOP")) << frame;
}

TEST(LogiClientStdinActions, ABadLineOrARefusedActionFailsThatLineOnlyAndTheExitIsStill0) {
  MockLogi car;
  ASSERT_FALSE(car.port().empty()) << car.output();
  auto client = stdin_client(car.port());
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
  EXPECT_TRUE(client.wait_for_line("] ok   connect")) << client.output();
  EXPECT_TRUE(client.wait_for_line("] FAIL press FORWARD: column 7: expected a direction"))
      << client.output();
  EXPECT_TRUE(client.wait_for_line("] FAIL station 7: rejected by the car (FB:GS:0)"))
      << client.output();
  EXPECT_TRUE(client.wait_for_line(
      "] FAIL press FWD: refused: movement needs a 'mode' and a 'speed' on this connection first"))
      << client.output();
  EXPECT_TRUE(client.wait_for_line("] ok   speed 30")) << client.output();
  EXPECT_TRUE(client.wait_for_line("] ok   disconnect")) << client.output();
  client.close_stdin();
  EXPECT_EQ(client.wait_exit(10s), 0) << client.output();

  // Six action lines, six results: the blank and the comment line get none.
  const std::string& out = client.output();
  int results = 0;
  for (std::size_t at = out.find("] ok   "); at != std::string::npos;
       at = out.find("] ok   ", at + 1))
    ++results;
  for (std::size_t at = out.find("] FAIL "); at != std::string::npos;
       at = out.find("] FAIL ", at + 1))
    ++results;
  EXPECT_EQ(results, 6) << out;
}

TEST(LogiClientStdinActions, ConfirmSendsAgainTheRunWhoseFeedbackWasLost) {
  const TempDir temp("logi-client-stdin-confirm");
  const auto faults = temp.write(
      "lost.yaml", "rules:\n  - {kind: drop, direction: to_client, match: \"FB:ST\", first: 1}\n");
  MockLogi car({"--faults", faults.string()});
  ASSERT_FALSE(car.port().empty()) << car.output();
  auto client = stdin_client(car.port());
  ASSERT_TRUE(client.write_stdin("connect\nspeed 50\nmode AUTO\nstation 2\nrun\n"));
  EXPECT_TRUE(client.wait_for_line("event command ST:RUN uncertain")) << client.output();
  EXPECT_TRUE(client.wait_for_line("] FAIL run: no feedback to ST:RUN")) << client.output();
  // Each action has its own runner; `confirm` still knows what went unanswered.
  ASSERT_TRUE(client.write_stdin("confirm\n"));
  EXPECT_TRUE(client.wait_for_line("event command ST:RUN accepted")) << client.output();
  EXPECT_TRUE(client.wait_for_line("] ok   confirm")) << client.output();
  ASSERT_TRUE(client.write_stdin("stop\n"));
  EXPECT_TRUE(client.wait_for_line("] ok   stop")) << client.output();
  client.close_stdin();
  EXPECT_EQ(client.wait_exit(10s), 0) << client.output();
}

TEST(LogiClientStdinActions, AnEmergencyStopGoesOutAtOnceBesideAnActionAwaitingFeedback) {
  const TempDir temp("logi-client-stdin-estop");
  const auto faults = temp.write(
      "lost-sp.yaml", "rules:\n  - {kind: drop, direction: to_car, match: \"SP\", first: 1}\n");
  MockLogi car({"--faults", faults.string()});
  ASSERT_FALSE(car.port().empty()) << car.output();
  auto client = stdin_client(car.port());
  ASSERT_TRUE(client.write_stdin("connect\nmode MAN\nspeed 60\n"));
  EXPECT_TRUE(client.wait_for_line("event command SP sent")) << client.output();
  // The SP never reached the car: it is sent again only after 800 ms. The
  // stop does not wait for that ...
  ASSERT_TRUE(client.write_stdin("estop\n"));
  EXPECT_TRUE(client.wait_for_line("event command MV:STOP accepted")) << client.output();
  EXPECT_TRUE(client.wait_for_line("event command SP sent")) << client.output();
  // ... but its result line keeps its place after the speed's.
  EXPECT_TRUE(client.wait_for_line("] ok   speed 60")) << client.output();
  EXPECT_TRUE(client.wait_for_line("] ok   estop")) << client.output();
  client.close_stdin();
  EXPECT_EQ(client.wait_exit(10s), 0) << client.output();
}

TEST(LogiClientStdinActions, TheStaleWarningAndItsEndAreEventLines) {
  const TempDir temp("logi-client-stdin-stale");
  const auto faults =
      temp.write("mute.yaml", "rules:\n  - {kind: stall, direction: to_client, at: 1s, for: 3s}\n");
  MockLogi car({"--faults", faults.string()});
  ASSERT_FALSE(car.port().empty()) << car.output();
  auto client = stdin_client(car.port());
  ASSERT_TRUE(client.write_stdin("connect\n"));
  EXPECT_TRUE(client.wait_for_line("] ok   connect")) << client.output();
  EXPECT_TRUE(client.wait_for_line("event stale", 15s)) << client.output();
  EXPECT_TRUE(client.wait_for_line("event fresh", 15s)) << client.output();
  client.close_stdin();
  EXPECT_EQ(client.wait_exit(10s), 0) << client.output();
}

TEST(LogiClientStdinActions, NoCarMeansAFailedConnectWithReconnectingEventsAndAStill0Exit) {
  auto client = stdin_client(free_tcp_port(), {"--connect-timeout", "1500ms"});
  ASSERT_TRUE(client.write_stdin("connect\n"));
  EXPECT_TRUE(client.wait_for_line("event connection reconnecting")) << client.output();
  EXPECT_TRUE(client.wait_for_line("] FAIL connect: not connected after 1.5s")) << client.output();
  client.close_stdin();
  EXPECT_EQ(client.wait_exit(10s), 0) << client.output();
}

TEST(LogiClientStdinActions, CtrlCCancelsTheActionUnderWayAndExits130) {
  MockLogi car;
  ASSERT_FALSE(car.port().empty()) << car.output();
  auto client = stdin_client(car.port());
  ASSERT_TRUE(client.write_stdin("connect\nwait 1m\n"));
  EXPECT_TRUE(client.wait_for_line("] ok   connect")) << client.output();
  EXPECT_EQ(client.interrupt(10s), 130) << client.output();
  EXPECT_TRUE(contains(client.output(), "] FAIL wait 1m: cancelled")) << client.output();
  EXPECT_TRUE(contains(client.output(), "event connection disconnected")) << client.output();
}

// Ctrl-C can come at any moment: while an action runs, between two actions,
// or after an action was taken but before its first turn. Every line taken
// still gets exactly one result line.
TEST(LogiClientStdinActions, CtrlCAtAnyMomentAnswersEveryLineOnce) {
  MockLogi car;
  ASSERT_FALSE(car.port().empty()) << car.output();
  for (int round = 0; round < 5; ++round) {
    auto client = stdin_client(car.port());
    ASSERT_TRUE(client.write_stdin("connect\nwait 1m\nwait 2m\n"));
    if (round % 2 == 0) {
      EXPECT_TRUE(client.wait_for_line("event connection connecting")) << client.output();
    } else {
      EXPECT_TRUE(client.wait_for_line("] ok   connect")) << client.output();
    }
    EXPECT_EQ(client.interrupt(10s), 130) << client.output();
    const std::string& out = client.output();
    const int connect_results = static_cast<int>(contains(out, "] ok   connect")) +
                                static_cast<int>(contains(out, "] FAIL connect: cancelled"));
    EXPECT_EQ(connect_results, 1) << out;
    EXPECT_TRUE(contains(out, "] FAIL wait 1m: cancelled")) << out;
    EXPECT_TRUE(contains(out, "] FAIL wait 2m: cancelled")) << out;
  }
}

TEST(LogiClientStdinActions, StdinActionsWithAScriptOrActionsIsAUsageError) {
  const auto result = run_to_exit(LOGI_CLIENT_BINARY, {"--stdin-actions", "connect"});
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_TRUE(contains(result.output, "--stdin-actions reads the actions from stdin"))
      << result.output;
}

}  // namespace
}  // namespace hil::test
