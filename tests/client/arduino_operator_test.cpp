// The Arduino operator language (every command, every error with its column,
// scripts with file:line:col) and the runner that carries commands out on a
// session against the robot on mem:// in virtual time, with exact times, on
// both boards (the behavioural mock and hil's test sketch on the emulated
// ATmega328P, tests/client/arduino_board.hpp).

#include <unistd.h>

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "client/arduino/operator.hpp"
#include "link/executor.hpp"
#include "link/transport.hpp"
#include "mocks/arduino.hpp"
#include "mocks/server.hpp"
#include "sim/presets.hpp"
#include "sim/world.hpp"
#include "tests/client/arduino_board.hpp"
#include "tests/client/client_test_support.hpp"
#include "tests/client/operator_test_support.hpp"

namespace hil::client::arduino {
namespace {

namespace proto = protocol::arduino;
using link::milliseconds;
using link::seconds;

OperatorCommand command_of(std::string_view line) {
  const auto parsed = parse_operator_line(line);
  EXPECT_TRUE(parsed.ok()) << line << ": " << parsed.error->message;
  EXPECT_TRUE(parsed.action.has_value()) << line;
  return parsed.action.value_or(QuitCommand{});
}

OperatorParseError error_of(std::string_view line) {
  const auto parsed = parse_operator_line(line);
  EXPECT_FALSE(parsed.ok()) << line << " parsed";
  return parsed.error.value_or(OperatorParseError{});
}

// ---- parsing ----

TEST(ArduinoOperatorParse, RawTokensAndTheirAliasesGiveTheSameRequests) {
  const std::vector<std::pair<std::vector<std::string>, proto::Body>> cases = {
      {{"PING", "ping", "Ping", "PING:"}, proto::Ping{}},
      {{"STATUS", "status"}, proto::StatusRequest{}},
      {{"V 160", "v 160", "V:160", "v:160", "  V   160  "}, proto::SetSpeed{160}},
      {{"V 0", "V:+0"}, proto::SetSpeed{0}},
      {{"V 255"}, proto::SetSpeed{255}},
      {{"M 20", "m 20", "M:20", "M +20"}, proto::Move{20}},
      {{"M -20", "m:-20"}, proto::Move{-20}},
      {{"M -32768"}, proto::Move{-32768}},
      {{"R -90", "r -90", "R:-90"}, proto::Rotate{-90}},
      {{"R 32767"}, proto::Rotate{32767}},
      {{"S", "s"}, proto::Stop{}},
      {{"B", "b"}, proto::SonarRead{}},
      {{"I", "i"}, proto::IrRead{}},
      {{"HELP", "help"}, proto::Help{}},
  };
  for (const auto& [lines, body] : cases) {
    for (const auto& line : lines) {
      EXPECT_EQ(command_of(line), OperatorCommand(RobotRequest{body})) << line;
    }
  }
}

TEST(ArduinoOperatorParse, ClientSideCommandsAndWaits) {
  EXPECT_EQ(command_of("history"), OperatorCommand(HistoryCommand{}));
  EXPECT_EQ(command_of("HISTORY"), OperatorCommand(HistoryCommand{}));
  EXPECT_EQ(command_of("save-log run.csv"), OperatorCommand(SaveLogCommand{"run.csv"}));
  EXPECT_EQ(command_of("save-log  my logs/run 1.ndjson  # the path may hold spaces"),
            OperatorCommand(SaveLogCommand{"my logs/run 1.ndjson"}));
  EXPECT_EQ(command_of("reconnect"), OperatorCommand(ReconnectCommand{}));
  EXPECT_EQ(command_of("quit"), OperatorCommand(QuitCommand{}));
  EXPECT_EQ(command_of("exit"), OperatorCommand(QuitCommand{}));
  EXPECT_EQ(command_of("wait 500ms"), OperatorCommand(WaitCommand{milliseconds(500)}));
  EXPECT_EQ(command_of("wait 1s"), OperatorCommand(WaitCommand{seconds(1)}));
  EXPECT_EQ(command_of("wait 1.5s"), OperatorCommand(WaitCommand{milliseconds(1500)}));
  EXPECT_EQ(command_of("wait 0ms"), OperatorCommand(WaitCommand{milliseconds(0)}));
}

TEST(ArduinoOperatorParse, BlankLinesAndCommentsAreNoCommand) {
  for (const std::string line : {"", "   ", "\t", "# a comment", "   # indented"}) {
    const auto parsed = parse_operator_line(line);
    EXPECT_TRUE(parsed.ok()) << line;
    EXPECT_FALSE(parsed.action) << line;
  }
  EXPECT_EQ(command_of("PING # is it there?"), OperatorCommand(RobotRequest{proto::Ping{}}));
  EXPECT_EQ(command_of("V 160# no space"), OperatorCommand(RobotRequest{proto::SetSpeed{160}}));
}

TEST(ArduinoOperatorParse, ErrorsSayTheColumnAndWhatWasExpected) {
  const std::vector<test::SyntaxErrorCase> cases = {
      {"V 999", 3, "V needs a number 0..255, not '999'"},
      {"V -1", 3, "V needs a number 0..255, not '-1'"},
      {"V", 2, "V needs a number 0..255"},
      {"  v 1.5", 5, "V needs a number 0..255, not '1.5'"},
      {"V 160 200", 7, "unexpected '200' after V 160"},
      {"M 40000", 3, "M needs a distance in cm, a whole number -32768..32767, not '40000'"},
      {"M", 2, "M needs a distance in cm, a whole number -32768..32767"},
      {"R left", 3, "R needs an angle in degrees, a whole number -32768..32767, not 'left'"},
      {"PING now", 6, "PING takes no argument, got 'now'"},
      {"status 2", 8, "STATUS takes no argument, got '2'"},
      {"s 1", 3, "S takes no argument, got '1'"},
      {"history all", 9, "history takes no argument, got 'all'"},
      {"quit now", 6, "quit takes no argument, got 'now'"},
      {"save-log", 9, "save-log needs a file path (.txt, .csv, .json)"},
      {"wait", 5, "wait needs a duration such as 500ms or 1s"},
      {"wait 5", 6, "wait needs a duration such as 500ms or 1s, not '5'"},
      {"wait -1s", 6, "wait needs a duration such as 500ms or 1s, not '-1s'"},
      {"wait 1s 2s", 9, "unexpected '2s' after wait"},
      {"  jump 3", 3,
       "unknown command 'jump' (expected PING, STATUS, V, M, R, S, B, I, HELP, history, "
       "save-log, reconnect, wait or quit)"},
  };
  test::expect_syntax_errors(cases, test::MessageMatch::whole, error_of);
}

// One word in the raw form CMD:PAYLOAD that hil would not type goes to the
// robot as given, as the robot's own CLI sends it; the spaced form is checked.
TEST(ArduinoOperatorParse, ARawTokenHilWouldRefuseIsSentAsGiven) {
  for (const std::string token : {"V:999", "V:fast", "V:", "PING:x", "reconnect:1", "x:1"}) {
    const auto parsed = parse_operator_line(token);
    ASSERT_TRUE(parsed.ok()) << token << ": " << parsed.error->message;
    const auto* request = std::get_if<RobotRequest>(&*parsed.action);
    ASSERT_NE(request, nullptr) << token;
    EXPECT_EQ(request->raw, token);
    EXPECT_EQ(to_text(*parsed.action), token);
  }
  EXPECT_EQ(error_of("V 999").message, "V needs a number 0..255, not '999'");
  EXPECT_EQ(error_of("V:999 now").message, "V needs a number 0..255, not '999'");
  EXPECT_EQ(error_of(":1").column, 1u);
  EXPECT_EQ(error_of("V:1|2").column, 3u);
}

RC_GTEST_PROP(ArduinoOperatorParse, EveryCommandReadsBackFromItsCanonicalText, ()) {
  const auto pick = *rc::gen::inRange(0, 8);
  OperatorCommand command;
  switch (pick) {
    case 0:
      command = RobotRequest{proto::SetSpeed{*rc::gen::inRange(0, 256)}};
      break;
    case 1:
      command = RobotRequest{proto::Move{*rc::gen::inRange(-32768, 32768)}};
      break;
    case 2:
      command = RobotRequest{proto::Rotate{*rc::gen::inRange(-32768, 32768)}};
      break;
    case 3:
      command = WaitCommand{milliseconds(*rc::gen::inRange(0, 100'000))};
      break;
    case 4:
      command = RobotRequest{proto::StatusRequest{}};
      break;
    case 5:
      command = HistoryCommand{};
      break;
    case 6:
      command = SaveLogCommand{"log " + std::to_string(*rc::gen::inRange(0, 99)) + ".csv"};
      break;
    default:
      command = ReconnectCommand{};
      break;
  }
  const auto parsed = parse_operator_line(to_text(command));
  RC_ASSERT(parsed.ok());
  RC_ASSERT(parsed.action == std::optional<OperatorCommand>(command));
}

TEST(ArduinoOperatorScript, StepsKeepTheirLineNumbers) {
  const auto script =
      parse_script("# square\nping\n\nV 160\r\n  M 20  # forward\nwait 1s\nstatus", "sq.txt");
  ASSERT_TRUE(script.ok());
  ASSERT_EQ(script.steps.size(), 5u);
  EXPECT_EQ(script.steps[0].line, 2u);
  EXPECT_EQ(script.steps[1].line, 4u);
  EXPECT_EQ(script.steps[1].command, OperatorCommand(RobotRequest{proto::SetSpeed{160}}));
  EXPECT_EQ(script.steps[2].line, 5u);
  EXPECT_EQ(script.steps[4].line, 7u);
  EXPECT_EQ(script.commands().size(), 5u);
}

TEST(ArduinoOperatorScript, EveryBadLineIsReportedAsFileLineColumn) {
  const auto script = parse_script("ping\nV 999\nstatus\n  wiat 1s\n", "cmds.txt");
  EXPECT_FALSE(script.ok());
  ASSERT_EQ(script.errors.size(), 2u);
  EXPECT_EQ(script.errors[0].to_string(), "cmds.txt:2:3: V needs a number 0..255, not '999'");
  EXPECT_EQ(script.errors[1].line, 4u);
  EXPECT_EQ(script.errors[1].column, 3u);
  EXPECT_EQ(script.errors[1].to_string().rfind("cmds.txt:4:3: unknown command 'wiat'", 0), 0u);
}

TEST(ArduinoOperatorScript, AMissingFileIsOneError) {
  const auto script = load_script("/nonexistent/hil/cmds.txt");
  ASSERT_EQ(script.errors.size(), 1u);
  EXPECT_EQ(script.errors[0].to_string(), "/nonexistent/hil/cmds.txt: cannot read the script");
}

TEST(ArduinoOperatorScript, TheExampleScriptsParse) {
  const std::filesystem::path dir =
      std::filesystem::path(HIL_SOURCE_DIR) / "scenarios/clients/arduino-client";
  std::size_t scripts = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".txt") continue;
    ++scripts;
    const auto script = load_script(entry.path().string());
    EXPECT_TRUE(script.ok()) << (script.errors.empty() ? "" : script.errors[0].to_string());
    EXPECT_FALSE(script.steps.empty()) << entry.path();
  }
  EXPECT_GE(scripts, 2u);
}

TEST(ArduinoOperatorDescribe, ResultsReadAsAPersonWouldSayThem) {
  Result ok;
  ok.info = "160";
  EXPECT_EQ(describe_result(ok), "ACK 160");
  Result empty;
  EXPECT_EQ(describe_result(empty), "ACK");
  Result nack;
  nack.code = ResultCode::nack;
  nack.nack = proto::Nack{proto::NackCode::bad_v};
  EXPECT_EQ(describe_result(nack), "NACK BAD_V");
  nack.nack = proto::Nack{std::string("BUSY")};
  EXPECT_EQ(describe_result(nack), "NACK BUSY");
  Result timeout;
  timeout.code = ResultCode::timeout;
  timeout.attempts = 4;
  EXPECT_EQ(describe_result(timeout), "TIMEOUT (no answer after 4 attempts)");
  CommandOutcome outcome;
  outcome.command = RobotRequest{proto::SetSpeed{160}};
  outcome.text = "ACK 160";
  EXPECT_EQ(describe_outcome(outcome), "V 160 -> ACK 160");
}

// ---- the runner, against the robot in virtual time ----

using test::Board;

struct ArduinoOperatorRunner : ::testing::TestWithParam<Board>, test::BoardCar {
  /// The robot (the board of the test's parameter) on mem://arduino, once it
  /// listens (the emulated board resets as the port opens,
  /// test::BoardCar::wait_until_listening()); `bytes_per_second` paces both
  /// directions.
  void start(std::optional<std::uint64_t> bytes_per_second = std::nullopt,
             OperatorRunner::Options options = {}) {
    mocks::ServerOptions server_options = test::on_mem("arduino");
    if (bytes_per_second) {
      link::FaultRule rule;
      rule.action = link::Bandwidth{*bytes_per_second};
      server_options.faults.rules.push_back(rule);
    }
    start_board(GetParam(), std::move(server_options));
    connect("arduino", options);
    ASSERT_TRUE(wait_until_listening()) << "the sketch never turned its UART on";
  }

  void connect(const std::string& name, OperatorRunner::Options options = {}) {
    session = std::make_unique<ArduinoSession>(context, link::MemEndpoint{name});
    session->set_wall_clock([this] { return executor.now().count() / 1000; });
    runner = std::make_unique<OperatorRunner>(*session, executor, options);
    runner->set_outcome_handler([this](const CommandOutcome& o) { outcomes.push_back(o); });
    runner->set_idle_handler([this] { ++idle_calls; });
    runner->set_event_handler([this](const Event& e) {
      if (auto* l = std::get_if<LinkChanged>(&e)) changes.push_back(*l);
    });
    session->open();
    executor.run_for(Duration::zero());
  }

  /// Runs the executor until the runner is idle (or `limit` of virtual time).
  void run_to_idle(Duration limit = seconds(60)) {
    test::run_until_done(
        executor, [this] { return runner->idle(); }, limit);
  }

  void run_script(std::string_view text) {
    const auto script = parse_script(text, "test.txt");
    ASSERT_TRUE(script.ok()) << script.errors[0].to_string();
    runner->add(script.commands());
    run_to_idle();
    ASSERT_TRUE(runner->idle());
  }

  std::vector<std::string> lines() const {
    std::vector<std::string> out;
    for (const auto& o : outcomes)
      out.push_back(describe_outcome(o));
    return out;
  }

  std::unique_ptr<ArduinoSession> session;
  std::unique_ptr<OperatorRunner> runner;
  std::vector<CommandOutcome> outcomes;
  std::vector<LinkChanged> changes;
  int idle_calls = 0;
};

/// The same, for the tests that need a behaviour only the mock honours.
struct ArduinoMockOperatorRunner : ArduinoOperatorRunner {};

TEST_P(ArduinoOperatorRunner, PingWaitStatusEndsAtTheTimeTheLinePacingGives) {
  // 1000 bytes per second: every byte is 1 ms on the line, each way.
  start(1000);
  const Time t0 = executor.now();
  run_script("ping\nwait 1s\nstatus\n");
  ASSERT_EQ(outcomes.size(), 3u);
  // The real sketch's dialect: "^00|PING| *30$" is 14 bytes out,
  // "^00|ACK|PONG*5F$" 16 bytes back.
  EXPECT_EQ(outcomes[0].text, "ACK PONG");
  const auto& status = outcomes[2];
  ASSERT_TRUE(status.ok) << status.text;
  const std::string info = status.result->info;
  EXPECT_EQ(info, "STATUS:V=140,DIR=stop,MOT:IDLE");
  // "^01|STATUS| *..$" is 16 bytes; the answer is the text plus 12 bytes
  // of frame.
  const std::size_t status_out = 16, status_back = info.size() + 12;
  if (GetParam() == Board::mock) {
    EXPECT_EQ(outcomes[0].finished - t0, milliseconds(30));
    EXPECT_EQ(outcomes[1].started - t0, milliseconds(30));
    EXPECT_EQ(outcomes[1].finished - t0, milliseconds(1030));
    // The robot reads STATUS at 1046 ms and answers at once.
    EXPECT_EQ(status.finished - t0, milliseconds(1030) + milliseconds(status_out + status_back));
  } else {
    // The link paces each whole frame (1 ms a byte), and the board's UART
    // takes its own 9,600-baud time to read the request and to write the
    // answer: both, one after the other.
    const auto exchange = [](std::size_t out, std::size_t back) {
      return milliseconds(out + back) + test::sketch_frames_time(out, back);
    };
    const Duration ping = outcomes[0].finished - t0;
    EXPECT_GE(ping, exchange(14, 16));
    EXPECT_LE(ping, exchange(14, 16) + test::kSketchSlack);
    EXPECT_EQ(outcomes[1].started - t0, ping);
    EXPECT_EQ(outcomes[1].finished - t0, ping + seconds(1));
    const Duration answered = status.finished - outcomes[1].finished;
    EXPECT_GE(answered, exchange(status_out, status_back));
    EXPECT_LE(answered, exchange(status_out, status_back) + test::kSketchSlack);
  }
  EXPECT_EQ(runner->failures(), 0u);
  EXPECT_EQ(runner->completed(), 3u);
  EXPECT_GE(idle_calls, 1);
}

TEST_P(ArduinoOperatorRunner, EveryRequestIsCarriedOutAndAnswered) {
  start();
  run_script("PING\nV 160\nM 20\nstatus\nS\nR -90\nB\nI\nHELP\n");
  const auto out = lines();
  ASSERT_EQ(out.size(), 9u);
  // The real sketch's answers (the default profile).
  EXPECT_EQ(out[0], "PING -> ACK PONG");
  EXPECT_EQ(out[1], "V 160 -> ACK OK");
  EXPECT_EQ(out[2], "M 20 -> ACK ACCEPTED");
  EXPECT_EQ(out[3].rfind("STATUS -> ACK STATUS:V=160,DIR=fwd,MOT:MOVE,tleft:", 0), 0u) << out[3];
  EXPECT_EQ(out[4], "S -> ACK STOPPED");
  EXPECT_EQ(out[5], "R -90 -> ACK ACCEPTED");
  EXPECT_EQ(out[6].rfind("B -> ACK B:", 0), 0u) << out[6];
  EXPECT_EQ(out[7].rfind("I -> ACK I:AL=", 0), 0u) << out[7];
  EXPECT_EQ(out[8], "HELP -> ACK CMDS:PING,HELP,STATUS,V,M,R,S,B,I");
  if (auto* m = mock()) EXPECT_EQ(m->state().pwm, 160);
}

TEST_P(ArduinoOperatorRunner, AMoveScriptDrivesTheRobotForItsTimedDuration) {
  start();
  if (GetParam() == Board::mock) {
    // M 50 runs 900 ms: polled at 899 ms it still moves, at 900 ms it is idle.
    run_script("M 50\nwait 899ms\nSTATUS\nwait 1ms\nSTATUS\n");
    ASSERT_EQ(outcomes.size(), 5u);
    EXPECT_EQ(outcomes[2].result->info.rfind("STATUS:V=140,DIR=fwd,MOT:MOVE,tleft:", 0), 0u)
        << outcomes[2].result->info;
    EXPECT_EQ(outcomes[4].result->info, "STATUS:V=140,DIR=stop,MOT:IDLE");
    return;
  }
  // The sketch times the 900 ms from the moment it read M, which the client
  // hears of only after the ACK's 20 bytes at 9,600 baud; the STATUS it is
  // polled with takes its 16 bytes to reach it. So polled 840 ms after the
  // ACK it has run 840 ms plus those 36 bytes' time, and says how much is
  // left; polled after that answer it is idle.
  run_script("M 50\nwait 840ms\nSTATUS\nSTATUS\n");
  ASSERT_EQ(outcomes.size(), 4u);
  const std::string moving = outcomes[2].result->info;
  const std::string prefix = "STATUS:V=140,DIR=fwd,MOT:MOVE,tleft:";
  ASSERT_EQ(moving.rfind(prefix, 0), 0u) << moving;
  const Duration ran = milliseconds(840) + test::sketch_frames_time(20, 16);
  const Duration left = milliseconds(std::stoi(moving.substr(prefix.size())));
  // millis() on the board advances in steps of 1.024 ms: it may lag by one.
  EXPECT_LE(left, milliseconds(900) - ran + std::chrono::microseconds(1024)) << moving;
  EXPECT_GE(left, milliseconds(900) - ran - test::kSketchSlack) << moving;
  EXPECT_EQ(outcomes[3].result->info, "STATUS:V=140,DIR=stop,MOT:IDLE");
}

// Mock only: the sketch never refuses a V it can take (a scripted Reject
// does not act on the emulated board).
TEST_P(ArduinoMockOperatorRunner, TheRunStopsAtTheFirstFailure) {
  start();
  firmware->arm(test::reject_next("V"));
  run_script("ping\nV 160\nstatus\n");
  ASSERT_EQ(outcomes.size(), 2u);
  EXPECT_EQ(describe_outcome(outcomes[1]), "V 160 -> NACK BUSY");
  EXPECT_FALSE(outcomes[1].ok);
  EXPECT_TRUE(runner->halted());
  EXPECT_EQ(runner->failures(), 1u);
  EXPECT_EQ(session->log().size(), 4u) << "STATUS never went out";
  runner->add(RobotRequest{proto::Ping{}});
  EXPECT_EQ(session->log().size(), 4u) << "a halted runner takes no more";
}

// Mock only: a scripted Reject, which does not act on the emulated board.
TEST_P(ArduinoMockOperatorRunner, KeepGoingRunsEveryCommandAndCountsTheFailures) {
  start(std::nullopt, {.keep_going = true});
  firmware->arm(test::reject_next("V"));
  run_script("V 160\nV 170\nstatus\n");
  EXPECT_EQ(lines(), (std::vector<std::string>{"V 160 -> NACK BUSY", "V 170 -> ACK OK",
                                               "STATUS -> ACK STATUS:V=170,DIR=stop,MOT:IDLE"}));
  EXPECT_EQ(runner->failures(), 1u);
  EXPECT_FALSE(runner->halted());
}

TEST_P(ArduinoOperatorRunner, HistoryAndSaveLogShowTheFramesSoFar) {
  start();
  const auto dir = std::filesystem::temp_directory_path() /
                   ("hil-arduino-operator-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto csv = (dir / "run.csv").string();
  run_script("ping\nhistory\nsave-log " + csv + "\nsave-log /nonexistent/dir/run.txt\n");
  ASSERT_EQ(outcomes.size(), 4u);
  EXPECT_NE(outcomes[1].text.find(" TX seq=00 ^00|PING| *30$"), std::string::npos)
      << outcomes[1].text;
  EXPECT_NE(outcomes[1].text.find(" RX seq=00 ^00|ACK|PONG*5F$"), std::string::npos)
      << outcomes[1].text;
  EXPECT_EQ(outcomes[2].text, "saved 2 frame(s) to " + csv + " (csv)");
  std::ifstream in(csv);
  std::stringstream content;
  content << in.rdbuf();
  EXPECT_EQ(content.str().rfind("time,direction,seq,raw,hex\n", 0), 0u) << content.str();
  EXPECT_NE(content.str().find(",TX,00,^00|PING| *30$,"), std::string::npos) << content.str();
  EXPECT_FALSE(outcomes[3].ok);
  EXPECT_EQ(outcomes[3].text, "cannot write /nonexistent/dir/run.txt");
  EXPECT_TRUE(runner->halted());
  std::filesystem::remove_all(dir);
}

TEST_P(ArduinoOperatorRunner, ReconnectReopensThePortAndTheRobotBootsAgain) {
  start();
  const auto boots_before = boots();
  run_script("V 200\nreconnect\nstatus\n");
  ASSERT_EQ(outcomes.size(), 3u);
  EXPECT_TRUE(outcomes[1].ok);
  EXPECT_EQ(outcomes[1].text, "reconnected, link OPEN");
  EXPECT_EQ(outcomes[1].finished - outcomes[1].started, milliseconds(500))
      << "closed for the session's reconnect_base_delay";
  EXPECT_EQ(outcomes[2].result->info, "STATUS:V=140,DIR=stop,MOT:IDLE")
      << "the board reset when the port opened: " << outcomes[2].result->info;
  EXPECT_EQ(boots(), boots_before + 1);
  ASSERT_GE(changes.size(), 2u);
  EXPECT_EQ(changes[changes.size() - 2].to, ConnectionState::connecting);
  EXPECT_EQ(changes.back().to, ConnectionState::connected);
}

TEST_P(ArduinoOperatorRunner, QuitDropsWhatComesAfterIt) {
  start();
  run_script("ping\nquit\nV 100\n");
  ASSERT_EQ(outcomes.size(), 2u);
  EXPECT_TRUE(runner->quit_requested());
  EXPECT_TRUE(runner->halted());
  EXPECT_EQ(runner->failures(), 0u);
  EXPECT_EQ(session->log().size(), 2u) << "V 100 never went out";
  if (auto* m = mock()) EXPECT_EQ(m->state().pwm, 140);
}

// No board answers here: run once, on the mock's fixture.
TEST_P(ArduinoMockOperatorRunner, APortThatDoesNotOpenFailsTheRequestAndReconnect) {
  connect("nobody-listens");
  EXPECT_EQ(session->state(), ConnectionState::down);
  runner->add(RobotRequest{proto::Ping{}});
  run_to_idle();
  ASSERT_EQ(outcomes.size(), 1u);
  EXPECT_FALSE(outcomes[0].ok);
  EXPECT_EQ(outcomes[0].text.rfind("LINK DOWN (", 0), 0u) << outcomes[0].text;
}

TEST_P(ArduinoOperatorRunner, ARequestQueuedWhileAWaitRunsGoesOutAfterIt) {
  start();
  runner->add(WaitCommand{milliseconds(300)});
  const Time t0 = executor.now();
  executor.run_for(milliseconds(100));
  runner->add(RobotRequest{proto::StatusRequest{}});
  EXPECT_EQ(session->log().size(), 0u) << "nothing goes out while the wait runs";
  run_to_idle();
  ASSERT_EQ(outcomes.size(), 2u);
  EXPECT_EQ(outcomes[1].started - t0, milliseconds(300));
  if (GetParam() == Board::mock) {
    EXPECT_EQ(outcomes[1].finished - t0, milliseconds(300));
  } else {
    // The board reads the 16-byte STATUS and writes its 43-byte answer at
    // 9,600 baud.
    const Duration took = outcomes[1].finished - outcomes[1].started;
    EXPECT_GE(took, test::sketch_frames_time(16, 43));
    EXPECT_LE(took, test::sketch_frames_time(16, 43) + test::kSketchSlack);
  }
}

INSTANTIATE_TEST_SUITE_P(Boards, ArduinoOperatorRunner, test::both_boards(),
                         test::board_param_name);
INSTANTIATE_TEST_SUITE_P(Boards, ArduinoMockOperatorRunner, ::testing::Values(Board::mock),
                         test::board_param_name);

}  // namespace
}  // namespace hil::client::arduino
