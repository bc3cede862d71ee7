// The Leka operator language: every command and its ranges, errors with
// their columns, scripts with file:line:col, the frames a line makes (the
// seed's worked examples), and the script runner against the mock robot in
// virtual time with exact times.

#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "client/leka/operator.hpp"
#include "link/executor.hpp"
#include "link/transport.hpp"
#include "mocks/leka.hpp"
#include "mocks/server.hpp"
#include "protocol/common/bytes.hpp"
#include "sim/presets.hpp"
#include "sim/world.hpp"
#include "tests/client/client_test_support.hpp"
#include "tests/client/operator_test_support.hpp"

namespace hil::client::leka {
namespace {

using link::milliseconds;

Time at_ms(int ms) {
  return Time(milliseconds(ms));
}

OperatorLine parse_ok(const std::string& text) {
  auto parsed = parse_operator_line(text);
  if (parsed.error) {
    ADD_FAILURE() << text << " -> col " << parsed.error->column << ": " << parsed.error->message;
    return {};
  }
  if (!parsed.action) {
    ADD_FAILURE() << text << " -> no action";
    return {};
  }
  return *parsed.action;
}

OperatorError parse_error(const std::string& text) {
  auto parsed = parse_operator_line(text);
  if (parsed.error) return *parsed.error;
  ADD_FAILURE() << text << " parsed, an error was expected";
  return {};
}

// A blank line or a comment: neither an action nor an error.
void expect_nothing(const std::string& text) {
  const auto parsed = parse_operator_line(text);
  EXPECT_TRUE(parsed.ok()) << text << ": " << parsed.error->message;
  EXPECT_FALSE(parsed.action.has_value()) << text;
}

// Every command of the line, across its parts (infos included).
proto::CommandGroup commands_of(const OperatorLine& line) {
  proto::CommandGroup all;
  for (const auto& part : line.parts) {
    if (const auto* b = std::get_if<GroupBuilder>(&part)) {
      for (const auto& c : b->group().commands)
        all.commands.push_back(c);
    } else {
      all.commands.push_back(proto::Info{});
    }
  }
  return all;
}

// "2A 2B ..." as bytes.
Bytes hex(const std::string& text) {
  Bytes out;
  std::istringstream in(text);
  std::string word;
  while (in >> word)
    out.push_back(static_cast<std::uint8_t>(std::stoi(word, nullptr, 16)));
  return out;
}

TEST(LekaOperatorLine, EveryCommandBecomesTheBuildersCommand) {
  const auto line = parse_ok(
      "stop led; stop motor; stop robot; ear all 255 0 0; ear single 1 0 255 0; "
      "belt all 0 0 255; belt range 0 9 1 2 3; belt single 19 4 5 6; motor all 1 200; "
      "motor duo 0 100 1 80; motor left 1 10; motor right 0 20; motivator 0x51; guidance 0x4F");
  GroupBuilder b;
  b.stop_led()
      .stop_motor()
      .stop_robot()
      .ear_all({255, 0, 0})
      .ear_single(1, {0, 255, 0})
      .belt_all({0, 0, 255})
      .belt_range(0, 9, {1, 2, 3})
      .belt_single(19, {4, 5, 6})
      .motor_all(1, 200)
      .motor_duo(0, 100, 1, 80)
      .motor_left(1, 10)
      .motor_right(0, 20)
      .motivator(0x51)
      .guidance(0x4F);
  EXPECT_EQ(line.kind, OperatorLine::Kind::group);
  EXPECT_EQ(line.commands, 14u);
  ASSERT_EQ(line.parts.size(), 1u) << "no info: the line is one group";
  EXPECT_EQ(commands_of(line), b.group());
}

TEST(LekaOperatorLine, TheTablesDottedNamesAndWordsForSpinsAreAccepted) {
  EXPECT_EQ(commands_of(parse_ok("led.belt.single 0 255 0 0")),
            commands_of(parse_ok("belt single 0 255 0 0")));
  EXPECT_EQ(commands_of(parse_ok("led ear all 1 2 3")), commands_of(parse_ok("ear all 1 2 3")));
  EXPECT_EQ(commands_of(parse_ok("stop.robot; motor.duo 0 1 1 2")),
            commands_of(parse_ok("stop robot; motor duo 0 1 1 2")));
  EXPECT_EQ(commands_of(parse_ok("motor duo forward 9 backward 9")),
            commands_of(parse_ok("motor duo 0 9 1 9")));
  EXPECT_EQ(commands_of(parse_ok("motor all 0x01 0xFF")), commands_of(parse_ok("motor all 1 255")));
}

TEST(LekaOperatorLine, InfoSplitsTheLineIntoPartsInTheOrderWritten) {
  const auto line = parse_ok("ear all 255 0 0; info; motor all 0 100; belt all 0 0 1");
  ASSERT_EQ(line.parts.size(), 3u);
  EXPECT_EQ(std::get<GroupBuilder>(line.parts[0]).group().commands.size(), 1u);
  EXPECT_EQ(std::get<InfoPart>(line.parts[1]).column, 18u);
  EXPECT_EQ(std::get<GroupBuilder>(line.parts[2]).group().commands.size(), 2u);
  EXPECT_EQ(line.commands, 4u);
}

TEST(LekaOperatorLine, WaitsCommentsAndBlankLines) {
  EXPECT_EQ(parse_ok("wait 500ms").wait, milliseconds(500));
  EXPECT_EQ(parse_ok("wait 1s").wait, link::seconds(1));
  EXPECT_EQ(parse_ok("  wait 1.5s  # half a second more").wait, milliseconds(1500));
  EXPECT_EQ(parse_ok("wait 1s").kind, OperatorLine::Kind::wait);
  expect_nothing("");
  expect_nothing("   \t ");
  expect_nothing("# lights only");
  const auto line = parse_ok("ear all 1 2 3 # red-ish");
  EXPECT_EQ(line.commands, 1u);
}

TEST(LekaOperatorLine, EveryRangeErrorNamesTheFieldAndItsColumn) {
  const std::vector<test::SyntaxErrorCase> cases = {
      {"ear all 256 0 0", 9, "ear all: red must be 0..255, got 256"},
      {"ear all 0 300 0", 11, "ear all: green must be 0..255, got 300"},
      {"ear all 0 0 999", 13, "ear all: blue must be 0..255, got 999"},
      {"ear single 2 0 0 255", 12, "ear single: led must be 0..1, got 2"},
      {"belt all 1 2 -1", 14, "belt all: blue must be 0..255, got -1"},
      {"belt single 20 255 0 0", 13, "belt single: led must be 0..19, got 20"},
      {"belt range 20 20 0 0 0", 12, "belt range: first must be 0..19, got 20"},
      {"belt range 5 20 0 0 0", 14, "belt range: last must be 5..19, got 20"},
      {"belt range 5 4 0 0 0", 14, "belt range: last must be 5..19, got 4"},
      {"motor all 2 10", 11, "motor all: direction must be 0 (forward) or 1 (backward), got 2"},
      {"motor all 0 256", 13, "motor all: speed must be 0..255, got 256"},
      {"motor duo 3 0 0 0", 11, "motor duo: left_spin must be 0 (forward) or 1 (backward), got 3"},
      {"motor duo 0 256 0 0", 13, "motor duo: left_speed must be 0..255, got 256"},
      {"motor duo 0 0 2 0", 15, "motor duo: right_spin must be 0 (forward) or 1 (backward), got 2"},
      {"motor duo 0 0 0 300", 17, "motor duo: right_speed must be 0..255, got 300"},
      {"motor left 5 0", 12, "motor left: spin must be 0 (forward) or 1 (backward), got 5"},
      {"motor left 0 1000", 14, "motor left: speed must be 0..255, got 1000"},
      {"motor right 0x02 0", 13, "motor right: spin must be 0 (forward) or 1 (backward), got 0x02"},
      {"motor right 0 257", 15, "motor right: speed must be 0..255, got 257"},
      {"motivator 0x50", 11, "motivator: id must be 0x51..0x55, got 0x50"},
      {"motivator 86", 11, "motivator: id must be 0x51..0x55, got 86"},
      {"guidance 0x40", 10, "guidance: id must be 0x41..0x4F, got 0x40"},
      {"guidance 0x50", 10, "guidance: id must be 0x41..0x4F, got 0x50"},
      // The column is the command's own, later in the line.
      {"ear all 1 2 3; belt single 25 0 0 0", 28, "belt single: led must be 0..19, got 25"},
  };
  test::expect_syntax_errors(cases, test::MessageMatch::whole, parse_error);
}

TEST(LekaOperatorLine, SyntaxErrorsSayWhatWasExpectedWhere) {
  const std::vector<test::SyntaxErrorCase> cases = {
      {"blink 1", 1,
       "unknown command 'blink' (expected info, stop, ear, belt, motor, motivator, guidance or "
       "wait)"},
      {"stop", 5, "stop: expected led, motor or robot"},
      {"stop all", 6, "stop: expected led, motor or robot, got 'all'"},
      {"ear", 4, "ear: expected all or single"},
      {"belt middle 1", 6, "belt: expected all, range or single, got 'middle'"},
      {"motor up 1 2", 7, "motor: expected all, duo, left or right, got 'up'"},
      {"led", 4, "led: expected ear or belt"},
      {"led motor all 0 1", 5, "led: expected ear or belt, got 'motor'"},
      {"ear all 1 2", 12, "ear all: expected blue (0..255); it takes red green blue"},
      {"belt single", 12, "belt single: expected led (0..19); it takes led red green blue"},
      {"motor all 1 2 3", 15, "motor all: unexpected '3'; it takes direction speed"},
      {"info now", 6, "info: unexpected 'now'; it takes nothing"},
      {"stop led 1", 10, "stop led: unexpected '1'; it takes nothing"},
      {"ear all red 0 0", 9, "ear all: red must be a number 0..255, got 'red'"},
      {"motor all sideways 1", 11,
       "motor all: direction must be a number 0 (forward) or 1 (backward), got 'sideways'"},
      {"info;; info", 6, "expected a command before ';'"},
      {"info;", 6, "expected a command after ';'"},
      {"wait", 5, "wait: expected a duration such as 500ms or 1s"},
      {"wait soon", 6, "wait: expected a duration such as 500ms or 1s (at most 3600s), got 'soon'"},
      {"wait 500", 6, "wait: expected a duration such as 500ms or 1s (at most 3600s), got '500'"},
      {"wait 2h", 6, "wait: expected a duration such as 500ms or 1s (at most 3600s), got '2h'"},
      {"wait 1s 2s", 9, "wait: unexpected '2s'; it takes one duration such as 500ms or 1s"},
      {"info; wait 1s", 7, "wait must be alone on its line"},
  };
  test::expect_syntax_errors(cases, test::MessageMatch::whole, parse_error);
}

TEST(LekaOperatorLine, TheBeltLimitFollowsTheValueLimits) {
  proto::ValueLimits wide;
  wide.max_belt_led_id = 0x19;
  auto parsed = parse_operator_line("belt single 25 1 1 1", wide);
  ASSERT_TRUE(parsed.ok());
  ASSERT_TRUE(parsed.action.has_value());
  parsed = parse_operator_line("belt single 26 1 1 1", wide);
  ASSERT_TRUE(parsed.error.has_value());
  EXPECT_FALSE(parsed.action.has_value());
  EXPECT_EQ(parsed.error->message, "belt single: led must be 0..25, got 26");
}

TEST(LekaOperatorScript, ErrorsAreFileLineColumnAndBlankLinesCount) {
  const std::string text =
      "# demo\n"
      "ear all 255 0 0\n"
      "\n"
      "wait 500ms\n"
      "motor all 0 100; belt single 20 0 0 255\n"
      "info\n";
  const auto parsed = parse_script(text, "demo.leka");
  ASSERT_EQ(parsed.errors.size(), 1u);
  EXPECT_EQ(parsed.errors[0].to_string(), "demo.leka:5:30: belt single: led must be 0..19, got 20");
}

TEST(LekaOperatorScript, EveryWrongLineIsAnErrorInOrder) {
  const auto parsed = parse_script("ear all 256 0 0\ninfo\nblink\n\nwait 1\n", "show.leka");
  EXPECT_FALSE(parsed.ok());
  ASSERT_EQ(parsed.errors.size(), 3u);
  EXPECT_EQ(parsed.errors[0].to_string(), "show.leka:1:9: ear all: red must be 0..255, got 256");
  EXPECT_EQ(parsed.errors[1].line, 3u);
  EXPECT_EQ(parsed.errors[1].column, 1u);
  EXPECT_EQ(parsed.errors[1].to_string().rfind("show.leka:3:1: unknown command 'blink'", 0), 0u)
      << parsed.errors[1].to_string();
  EXPECT_EQ(parsed.errors[2].to_string().rfind("show.leka:5:6: wait: expected a duration", 0), 0u)
      << parsed.errors[2].to_string();
  ASSERT_EQ(parsed.lines.size(), 1u) << "the lines that parse are still read";
  EXPECT_EQ(parsed.lines[0].number, 2u);
}

TEST(LekaOperatorScript, KeepsTheLinesThatDoSomethingWithTheirNumbers) {
  const auto script =
      parse_script("# demo\r\near all 255 0 0\r\n\nwait 1s\ninfo   # ask", "demo.leka");
  ASSERT_TRUE(script.ok()) << script.errors.front().to_string();
  EXPECT_EQ(script.source, "demo.leka");
  ASSERT_EQ(script.lines.size(), 3u);
  EXPECT_EQ(script.lines[0].number, 2u);
  EXPECT_EQ(script.lines[0].text, "ear all 255 0 0");
  EXPECT_EQ(script.lines[1].number, 4u);
  EXPECT_EQ(script.lines[2].number, 5u);
  EXPECT_EQ(script.lines[2].text, "info") << "shown without its comment";
  const auto args = parse_lines({"info", "motor all 2 0"}, "arg");
  ASSERT_EQ(args.errors.size(), 1u);
  EXPECT_EQ(args.errors[0].to_string(),
            "arg:2:11: motor all: direction must be 0 (forward) or 1 (backward), got 2");
}

TEST(LekaOperatorFrames, TheSeedsWorkedExamplesByteForByte) {
  EXPECT_EQ(frames_of(parse_ok("belt single 0 255 0 0"), {}),
            std::vector<Bytes>{hex("2A 2B 2C 2D 05 15 00 FF 00 00 41")});
  EXPECT_EQ(frames_of(parse_ok("info"), {}), std::vector<Bytes>{hex("2A 2B 2C 2D 01 70 70")});
  const std::string twenty =
      "belt single 0 0x33 0 0; belt single 1 0x66 0 0; belt single 2 0x99 0 0; "
      "belt single 3 0xCC 0 0; belt single 4 0xFF 0 0; belt single 5 0 0 0; "
      "belt single 6 0 0x33 0; belt single 7 0 0x66 0; belt single 8 0 0x99 0; "
      "belt single 9 0 0xCC 0; belt single 10 0 0xFF 0; belt single 11 0 0 0; "
      "belt single 12 0 0 0x33; belt single 13 0 0 0x66; belt single 14 0 0 0x99; "
      "belt single 15 0 0 0xCC; belt single 16 0xFF 0 0; belt single 17 0 0xFF 0; "
      "belt single 18 0 0 0xFF; belt single 19 0xFF 0xFF 0xFF";
  // With 128-byte frames the 20 commands fit one frame: the seed's 106 bytes.
  ClientConfig whole;
  whole.max_frame_bytes = 128;
  whole.bytes_per_period = 128;
  const auto one = frames_of(parse_ok(twenty), whole);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0], hex("2A 2B 2C 2D 64 15 00 33 00 00 15 01 66 00 00 15 02 99 00 00 15 03 CC 00 "
                        "00 15 04 FF 00 00 15 05 00 00 00 15 06 00 33 00 15 07 00 66 00 15 08 00 "
                        "99 00 15 09 00 CC 00 15 0A 00 FF 00 15 0B 00 00 00 15 0C 00 00 33 15 0D "
                        "00 00 66 15 0E 00 00 99 15 0F 00 00 CC 15 10 FF 00 00 15 11 00 FF 00 15 "
                        "12 00 00 FF 15 13 FF FF FF A8"));
  // With the default 64-byte frames: 11 commands (61 bytes), then 9 (51 bytes).
  const auto split = frames_of(parse_ok(twenty), {});
  ASSERT_EQ(split.size(), 2u);
  EXPECT_EQ(split[0].size(), 61u);
  EXPECT_EQ(split[1].size(), 51u);
}

TEST(LekaOperatorFrames, AnInfoIsItsOwnFrameInItsPlace) {
  const auto frames = frames_of(parse_ok("ear all 255 0 0; info; stop motor"), {});
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0][5], 0x11);
  EXPECT_EQ(frames[1], hex("2A 2B 2C 2D 01 70 70"));
  EXPECT_EQ(frames[2][5], 0xFE);
  EXPECT_TRUE(frames_of(parse_ok("wait 1s"), {}).empty());
}

// ------------------------------------------------------------ the runner

struct LekaOperatorRunner : ::testing::Test, test::VirtualCar<mocks::LekaFirmware> {
  void SetUp() override {
    start_car(sim::leka_robot(), test::on_mem("leka"));
    session = std::make_unique<LekaSession>(context, link::MemEndpoint{"leka"});
    session->set_wall_clock([this] { return executor.now().count() / 1000; });
    session->open();
    executor.run_for(Duration::zero());
    ASSERT_TRUE(session->is_open());
    runner = std::make_unique<OperatorRunner>(executor, *session);
  }

  Script script(const std::string& text) {
    auto parsed = parse_script(text, "test.leka");
    for (const auto& e : parsed.errors)
      ADD_FAILURE() << e.to_string();
    return parsed;
  }

  void run(const std::string& text) {
    runner->run(
        script(text), [this](const LineResult& r) { results.push_back(r); },
        [this](bool ok) {
          done = ok;
          done_at = executor.now();
        });
  }

  std::vector<std::pair<std::int64_t, std::size_t>> tx_times() {
    std::vector<std::pair<std::int64_t, std::size_t>> out;
    for (const auto& e : session->log().entries())
      if (e.kind == LogKind::tx) out.push_back({e.utc_us / 1000, e.raw.size()});
    return out;
  }

  std::unique_ptr<LekaSession> session;
  std::unique_ptr<OperatorRunner> runner;
  std::vector<LineResult> results;
  std::optional<bool> done;
  Time done_at{0};
};

TEST_F(LekaOperatorRunner, AGroupOverSixtyFourBytesGoesOutInTwoFrames10msApart) {
  executor.run_until(at_ms(3));
  // 13 belt commands: 65 group bytes, more than one 64-byte frame holds.
  std::string line;
  for (int i = 0; i < 13; ++i)
    line += (i ? "; " : "") + std::string("belt single ") + std::to_string(i) + " 0 0 255";
  run(line);
  executor.run_until(at_ms(100));
  ASSERT_EQ(results.size(), 1u);
  EXPECT_TRUE(results[0].ok) << results[0].error;
  EXPECT_EQ(results[0].frames, 2u);
  EXPECT_EQ(results[0].bytes, 61u + 16u);
  EXPECT_EQ(results[0].started, at_ms(3));
  EXPECT_EQ(results[0].finished, at_ms(13)) << "finished when the second frame went out";
  EXPECT_EQ(tx_times(), (std::vector<std::pair<std::int64_t, std::size_t>>{{3, 61}, {13, 16}}));
  EXPECT_EQ(done, true);
  EXPECT_EQ(firmware->state().belt[12], (proto::Rgb{0, 0, 255}));
  EXPECT_EQ(firmware->state().counters.bytes_lost, 0u);
}

TEST_F(LekaOperatorRunner, AWaitEndsExactlyItsDurationAfterThePreviousLine) {
  executor.run_until(at_ms(3));
  run("motor all 0 100\nwait 1s\nmotor all 0 0\n");
  executor.run_until(at_ms(2000));
  ASSERT_EQ(results.size(), 3u);
  EXPECT_EQ(results[0].finished, at_ms(3));
  EXPECT_EQ(results[1].started, at_ms(3));
  EXPECT_EQ(results[1].finished, at_ms(1003));
  EXPECT_EQ(results[2].started, at_ms(1003));
  EXPECT_EQ(tx_times(), (std::vector<std::pair<std::int64_t, std::size_t>>{{3, 9}, {1003, 9}}));
  EXPECT_EQ(done, true);
  EXPECT_EQ(done_at, at_ms(1003));
  EXPECT_EQ(firmware->state().left, (mocks::LekaMotor{0, 0}));
}

TEST_F(LekaOperatorRunner, InfoReturnsTheMocksInfoAfterTheLinesCommandsRan) {
  executor.run_until(at_ms(4));
  run("ear all 255 0 0; motor duo 0 100 1 80; info\n");
  executor.run_until(at_ms(100));
  ASSERT_EQ(results.size(), 1u);
  ASSERT_TRUE(results[0].ok) << results[0].error;
  EXPECT_EQ(results[0].frames, 2u);
  EXPECT_EQ(results[0].bytes, 15u + 7u);
  EXPECT_EQ(results[0].finished, at_ms(10)) << "answered at the robot's 10 ms pass";
  ASSERT_EQ(results[0].infos.size(), 1u);
  EXPECT_EQ(results[0].infos[0].name, "leka");
  EXPECT_EQ(results[0].infos[0].firmware, "1.0.0");
  EXPECT_EQ(results[0].infos[0].buffer_bytes, 128);
  EXPECT_EQ(results[0].infos[0].state, "ok");
  EXPECT_EQ(firmware->state().ears[0], (proto::Rgb{255, 0, 0}));
  EXPECT_EQ(firmware->state().right, (mocks::LekaMotor{1, 80}));
}

TEST_F(LekaOperatorRunner, TwoInfosInALineAreBothAnswered) {
  executor.run_until(at_ms(4));
  run("info; stop robot; info\n");
  executor.run_until(at_ms(100));
  ASSERT_EQ(results.size(), 1u);
  ASSERT_TRUE(results[0].ok) << results[0].error;
  EXPECT_EQ(results[0].infos.size(), 2u);
  EXPECT_EQ(results[0].frames, 3u);
}

TEST_F(LekaOperatorRunner, AnUnansweredInfoFailsAt200msAndStopsTheScript) {
  firmware->arm(mocks::Behaviour{"", mocks::When{}, mocks::Ignore{"info", 1, std::nullopt}});
  executor.run_until(at_ms(5));
  run("belt all 0 0 255\ninfo\nmotor all 0 200\n");
  executor.run_until(at_ms(1000));
  ASSERT_EQ(results.size(), 2u) << "the line after the failure never ran";
  EXPECT_TRUE(results[0].ok);
  EXPECT_FALSE(results[1].ok);
  EXPECT_EQ(results[1].number, 2u);
  EXPECT_EQ(results[1].error, "info: no answer within 200 ms");
  EXPECT_EQ(results[1].finished, at_ms(205));
  EXPECT_EQ(done, false);
  EXPECT_EQ(done_at, at_ms(205));
  EXPECT_EQ(firmware->state().left.speed, 0) << "motor all never went out";
}

TEST_F(LekaOperatorRunner, APortThatClosesFailsTheLine) {
  executor.run_until(at_ms(5));
  run("wait 100ms\nbelt all 1 1 1\n");
  executor.run_until(at_ms(50));
  server->close();
  executor.run_until(at_ms(500));
  ASSERT_EQ(results.size(), 1u);
  EXPECT_FALSE(results[0].ok);
  EXPECT_EQ(results[0].error, "the port closed");
  EXPECT_EQ(done, false);
}

TEST_F(LekaOperatorRunner, CancelStopsWithoutAnotherReport) {
  executor.run_until(at_ms(5));
  run("wait 100ms\nbelt all 1 1 1\n");
  executor.run_until(at_ms(50));
  runner->cancel();
  executor.run_until(at_ms(500));
  EXPECT_TRUE(results.empty());
  EXPECT_FALSE(done.has_value());
  EXPECT_FALSE(runner->running());
}

}  // namespace
}  // namespace hil::client::leka
