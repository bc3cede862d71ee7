// hil mock as a desk user runs it: in the background, talked to over real
// TCP and a real pty, stopped with Ctrl-C.

#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include "tests/apps/hil_cli_support.hpp"
#include "tests/support/connection.hpp"

namespace hil::test {
namespace {

using namespace std::chrono_literals;

TEST(HilMock, LogiCarAnswersOverTcpAndStopsCleanlyOnCtrlC) {
  HilProcess mock({"mock", "logi", "--port", "0", "--seed", "7"});
  ASSERT_TRUE(mock.started());
  int port = -1;
  ASSERT_NO_FATAL_FAILURE(wait_for_port(mock, port));
  EXPECT_NE(mock.output().find("seed 7 (replay with --seed 7)"), std::string::npos);
  Conn client = tcp_connect(port);
  ASSERT_TRUE(client.ok());
  ASSERT_TRUE(client.send("LOGI:SP:050:D7#"));
  EXPECT_TRUE(client.read_until("FB:SP:1")) << client.received;
  EXPECT_TRUE(client.read_until("STAT:SP:050")) << client.received;
  EXPECT_TRUE(mock.wait_for_line("client connected")) << mock.output();
  const auto status = mock.interrupt();
  ASSERT_TRUE(status) << mock.output();
  EXPECT_EQ(*status, 0);
  EXPECT_NE(mock.output().find("stopping (1 client(s) served)"), std::string::npos)
      << mock.output();
  // Not a terminal: no status line in the output.
  EXPECT_EQ(mock.output().find("\033[K"), std::string::npos);
}

TEST(HilMock, CountRunsIndependentCarsAndASecondClientIsTurnedAway) {
  HilProcess mock({"mock", "logi", "--port", "0", "--count", "2"});
  int first = -1;
  int second = -1;
  ASSERT_NO_FATAL_FAILURE(wait_for_port(mock, first, "car0 connect to"));
  ASSERT_NO_FATAL_FAILURE(wait_for_port(mock, second, "car1 connect to"));
  ASSERT_NE(first, second);
  Conn a = tcp_connect(first);
  Conn b = tcp_connect(second);
  ASSERT_TRUE(a.send("LOGI:MD:MAN:0C#"));
  ASSERT_TRUE(b.send("LOGI:MD:MAN:0C#"));
  EXPECT_TRUE(a.read_until("FB:MD:1"));
  EXPECT_TRUE(b.read_until("FB:MD:1"));
  Conn extra = tcp_connect(first);
  ASSERT_TRUE(extra.ok());
  EXPECT_FALSE(extra.read_until("LOGI", 3s));  // closed by the car with no byte
  EXPECT_TRUE(extra.received.empty());
  EXPECT_TRUE(mock.wait_for_line("turned away a second client")) << mock.output();
  EXPECT_EQ(mock.interrupt(), 0);
}

/// `hil mock arduino ARGS --pty <a temp folder>/robot0`, listening, and
/// the port opened as a serial program opens it.
struct ArduinoOnPty {
  explicit ArduinoOnPty(const std::vector<std::string>& args)
      : path(make_dir(dir) + "/robot0"),
        mock(command(args, path)),
        listening(mock.wait_for_line("as a serial port at 9600 baud")),
        port(listening ? pty_open(path) : Conn()) {}
  ~ArduinoOnPty() { std::filesystem::remove_all(dir); }
  ArduinoOnPty(const ArduinoOnPty&) = delete;
  ArduinoOnPty& operator=(const ArduinoOnPty&) = delete;

  static std::string make_dir(const std::filesystem::path& d) {
    std::filesystem::create_directories(d);
    return d.string();
  }
  static std::vector<std::string> command(const std::vector<std::string>& args,
                                          const std::string& path) {
    std::vector<std::string> all{"mock", "arduino"};
    all.insert(all.end(), args.begin(), args.end());
    all.insert(all.end(), {"--pty", path});
    return all;
  }

  /// The robot said where it listens and its port is open.
  void expect_ready() {
    ASSERT_TRUE(listening) << mock.output();
    EXPECT_NE(listening->find(path), std::string::npos);
    ASSERT_TRUE(port.ok());
  }

  std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("hil-mock-ard-" + std::to_string(::getpid()));
  std::string path;
  HilProcess mock;
  std::optional<std::string> listening;
  Conn port;
};

/// A profile of the robot and how it answers: each request sent in turn
/// and the answer waited for.
struct ArduinoAnswers {
  const char* name;
  std::vector<std::string> args;
  std::vector<std::pair<std::string, std::string>> exchanges;
};

class HilMockArduino : public ::testing::TestWithParam<ArduinoAnswers> {};

TEST_P(HilMockArduino, RobotAnswersOnAPty) {
  ArduinoOnPty robot(GetParam().args);
  ASSERT_NO_FATAL_FAILURE(robot.expect_ready());
  for (const auto& [request, answer] : GetParam().exchanges) {
    ASSERT_TRUE(robot.port.send(request));
    EXPECT_TRUE(robot.port.read_until(answer)) << request << ": " << robot.port.received;
  }
  EXPECT_EQ(robot.mock.interrupt(), 0);
}

INSTANTIATE_TEST_SUITE_P(
    Profiles, HilMockArduino,
    ::testing::Values(
        // The real client's PING (one space for no argument), answered as the
        // real sketch answers it: the default profile is the board people own.
        ArduinoAnswers{"Default", {}, {{"^01|PING| *31$", "^01|ACK|PONG*"}}},
        // --profile firmware plays the real sketch: the README's
        // empty-payload PING is refused as the board refuses it, and the
        // real client's one-space PING is answered PONG (arduino.ino at
        // 8dcfab0).
        ArduinoAnswers{
            "Firmware",
            {"--profile", "firmware"},
            {{"^01|PING|*11$", "^01|NACK|BAD_FMT*41$"}, {"^02|PING| *32$", "^02|ACK|PONG*5D$"}}},
        // --profile readme takes the README's PING.
        ArduinoAnswers{"Readme", {"--profile", "readme"}, {{"^01|PING|*11$", "^01|ACK|OK*4C$"}}}),
    [](const ::testing::TestParamInfo<ArduinoAnswers>& info) { return info.param.name; });

// --reply-latency holds each answer back by the firmware's processing
// time; real time, so only the lower bound is checked.
TEST(HilMock, AReplyLatencyHoldsTheAnswerBackAtLeastThatLong) {
  ArduinoOnPty robot({"--reply-latency", "300ms"});
  ASSERT_NO_FATAL_FAILURE(robot.expect_ready());
  const auto sent = std::chrono::steady_clock::now();
  ASSERT_TRUE(robot.port.send("^01|PING| *31$"));
  ASSERT_TRUE(robot.port.read_until("^01|ACK|PONG*5E$")) << robot.port.received;
  EXPECT_GE(std::chrono::steady_clock::now() - sent, std::chrono::milliseconds(300));
  EXPECT_EQ(robot.mock.interrupt(), 0);
}

/// `hil mock ARGS` refuses to start: exit 2, saying `says`.
void expect_refused(const std::vector<std::string>& args, const std::string& says) {
  HilProcess mock(args);
  EXPECT_EQ(mock.wait_exit(), 2) << mock.output();
  EXPECT_NE(mock.output().find(says), std::string::npos) << mock.output();
}

TEST(HilMock, AReplyLatencyWithoutAUnitIsRefused) {
  expect_refused({"mock", "arduino", "--reply-latency", "20", "--pty", "/tmp/hil-unused-ard"},
                 "--reply-latency must be a duration with a unit (20ms, 1.5s), got '20'");
}

TEST(HilMock, AnUnknownProfileIsRefusedWithTheCarsProfiles) {
  expect_refused({"mock", "leka", "--profile", "firmware", "--pty", "/tmp/hil-unused-leka"},
                 "leka has no profile 'firmware'; its profiles are readme (the default)");
}

TEST(HilMock, Wr8VehicleAuthenticatesWithTheConfiguredString) {
  HilProcess mock({"mock", "wr8", "--port", "0", "--auth", "0123456789"});
  int port = -1;
  ASSERT_NO_FATAL_FAILURE(wait_for_port(mock, port));
  Conn client = tcp_connect(port);
  ASSERT_TRUE(client.send(std::string("\x01") + "0123456789"));
  ASSERT_TRUE(client.read_until(std::string("\x02", 1))) << client.received.size();
  EXPECT_EQ(mock.interrupt(), 0);
}

TEST(HilMock, Wr8SvguiHeadStreamsDataStampedWithTheTimeOfDayAndAnswersTheRealGuisLogin) {
  HilProcess mock({"mock", "wr8", "--profile", "svgui-head", "--port", "0"});
  int port = -1;
  ASSERT_NO_FATAL_FAILURE(wait_for_port(mock, port));
  Conn client = tcp_connect(port);
  // HIGH-FREQ DATA flows before any login: length byte 0x41, code 9, then
  // the big-endian milliseconds since local midnight.
  const std::string high_freq("\x41\x09", 2);
  ASSERT_TRUE(client.read_until(high_freq)) << client.received.size();
  const auto at = client.received.find(high_freq);
  // LOW-FREQ (0x22, code 8) follows within a second: by then the first
  // HIGH-FREQ is whole.
  ASSERT_TRUE(client.read_until(std::string("\x22\x08", 2))) << client.received.size();
  ASSERT_GE(client.received.size(), at + 6);
  std::uint32_t stamp = 0;
  for (std::size_t k = 0; k < 4; ++k)
    stamp = (stamp << 8) | static_cast<std::uint8_t>(client.received[at + 2 + k]);
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  localtime_r(&now, &local);
  const std::int64_t day_ms = 86'400'000;
  const std::int64_t local_ms = (local.tm_hour * 3600 + local.tm_min * 60 + local.tm_sec) * 1000LL;
  const std::int64_t off =
      ((static_cast<std::int64_t>(stamp) - local_ms) % day_ms + day_ms) % day_ms;
  EXPECT_LT(std::min(off, day_ms - off), 10'000) << stamp << " vs " << local_ms;
  // The head GUI's AUTH is answered with the fixed AUTH-REPLY.
  client.received.clear();
  ASSERT_TRUE(client.send(std::string("\x0C\x01konnichiwa", 12) + std::string(1, '\0')));
  EXPECT_TRUE(client.read_until(std::string("\x04\x02\x01\x02\x03", 5))) << client.received.size();
  EXPECT_EQ(mock.interrupt(), 0);
}

TEST(HilMock, Wr8SvguiHeadKeepsItsDataRates) {
  expect_run(says("mock wr8 --profile svgui-head --data-hz 5", 2,
                  {"svgui-head vehicle sends HIGH-FREQ DATA every 50 ms"}));
}

TEST(HilMock, DeskCommandsDropAParcelThatLocksTheCarAndTakeItAway) {
  HilProcess mock({"mock", "logi", "--port", "0", "--commands"});
  int port = -1;
  ASSERT_NO_FATAL_FAILURE(wait_for_port(mock, port));
  ASSERT_TRUE(mock.wait_for_line("type 'help' for desk commands"));
  Conn client = tcp_connect(port);
  ASSERT_TRUE(client.send("LOGI:MD:MAN:0C#LOGI:MV:FWD:23#"));
  ASSERT_TRUE(client.read_until("FB:MV:1")) << client.received;
  ASSERT_TRUE(mock.write_stdin("obstacle 10\n"));
  EXPECT_TRUE(mock.wait_for_line("car0: parcel dropped 10 cm ahead")) << mock.output();
  EXPECT_TRUE(client.read_until("OBS:1")) << client.received;
  ASSERT_TRUE(mock.write_stdin("clear\n"));
  EXPECT_TRUE(mock.wait_for_line("car0: 1 parcel(s) taken away")) << mock.output();
  client.received.clear();
  EXPECT_TRUE(client.read_until("OBS:0")) << client.received;
  ASSERT_TRUE(mock.write_stdin("teleport\n"));
  EXPECT_TRUE(mock.wait_for_line("unknown command 'teleport'")) << mock.output();
  ASSERT_TRUE(mock.write_stdin("hangup\n"));
  EXPECT_TRUE(mock.wait_for_line("car0: closing the client's connection")) << mock.output();
  client.read_until("never", 5s);  // reads until the car closes the connection
  EXPECT_TRUE(mock.wait_for_line("client gone")) << mock.output();
  EXPECT_EQ(mock.interrupt(), 0);
}

TEST(HilMock, BadInputIsAClearError) {
  for (const CliRun& run : {
           says("mock logi --world tests/apps/data/bad-world.yaml", 1,
                {"hil mock: tests/apps/data/bad-world.yaml:"}),
           says("mock wr8 --auth short", 2, {"--auth must be exactly 10 characters, got 5"}),
           says("mock tesla", 2, {}),
           says("mock logi --behaviours /nonexistent.yaml", 1,
                {"/nonexistent.yaml: cannot read the file"}),
       })
    expect_run(run);
}

TEST(HilMock, APortInUseIsReportedWithTheFix) {
  HilProcess first({"mock", "logi", "--port", "0"});
  int port = -1;
  ASSERT_NO_FATAL_FAILURE(wait_for_port(first, port));
  const auto second = run_hil("mock logi --port " + std::to_string(port));
  EXPECT_EQ(second.exit_code, 1);
  EXPECT_NE(second.output.find("cannot listen on tcp://127.0.0.1:" + std::to_string(port)),
            std::string::npos)
      << second.output;
  EXPECT_NE(second.output.find("choose another --port"), std::string::npos);
  EXPECT_EQ(first.interrupt(), 0);
}

// ---------------------------------------------------------------- --replay

/// A LOGI capture as `hil conform probe` writes one, in a temporary file:
/// the car refused MD:MAN (FB:MD:0, which the mock would accept) and sent
/// STAT with DIS 777 every 100 ms.
class ReplayCapture {
 public:
  ReplayCapture()
      : path_(std::filesystem::temp_directory_path() /
              ("hil-replay-cli-" + std::to_string(::getpid()) + ".ndjson")) {
    std::ofstream out(path_);
    out << R"({"event":"probe","t_ms":0,"probe":"logi-probe/1","car":"logi","profile":"guide","target":"tcp://car:9000"})"
        << "\n"
        << R"({"event":"exchange","t_ms":0,"index":0,"name":"connect","kind":"connect","what":"open"})"
        << "\n"
        << R"({"event":"open","t_ms":0,"client":"probe","car":"tcp://car:9000"})"
        << "\n"
        << R"({"event":"exchange_end","t_ms":100,"index":0})"
        << "\n"
        << R"({"event":"exchange","t_ms":100,"index":1,"name":"manual","kind":"command","what":"MD:MAN"})"
        << "\n"
        << R"({"event":"sent","t_ms":110,"dir":"to_car","text":"LOGI:MD:MAN:0C#"})"
        << "\n"
        << R"({"event":"delivered","t_ms":130,"dir":"to_client","text":"LOGI:FB:MD:0:22#"})"
        << "\n"
        << R"({"event":"exchange_end","t_ms":200,"index":1})"
        << "\n"
        << R"({"event":"exchange","t_ms":200,"index":2,"name":"telemetry","kind":"telemetry","what":"STAT"})"
        << "\n";
    for (int ms = 250; ms < 1000; ms += 100) {
      out << R"({"event":"delivered","t_ms":)" << ms
          << R"(,"dir":"to_client","text":"LOGI:STAT:SP:050,STA:000,RUN:0,MODE:AUTO,MAN:STOP,DIS:777,TRK:0000,DEV:0,OBS:0,RPM:0:0:0:0:B6#"})"
          << "\n";
    }
    out << R"({"event":"exchange_end","t_ms":1000,"index":2})"
        << "\n";
  }
  ~ReplayCapture() {
    std::error_code ignored;
    std::filesystem::remove(path_, ignored);
  }
  std::string path() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

TEST(HilMock, ReplayPlaysTheRecordedCarAndTheMockAnswersTheRest) {
  const ReplayCapture capture;
  const auto wire_log = std::filesystem::temp_directory_path() /
                        ("hil-replay-cli-wire-" + std::to_string(::getpid()) + ".ndjson");
  HilProcess mock(
      {"mock", "logi", "--replay", capture.path(), "--port", "0", "--log", wire_log.string()});
  int port = -1;
  ASSERT_NO_FATAL_FAILURE(wait_for_port(mock, port));
  EXPECT_TRUE(mock.wait_for_line("replaying " + capture.path())) << mock.output();
  EXPECT_NE(mock.output().find("1 recorded request)"), std::string::npos) << mock.output();
  Conn client = tcp_connect(port);
  ASSERT_TRUE(client.ok());
  // The recorded telemetry, not the mock's (DIS 232 on the warehouse).
  EXPECT_TRUE(client.read_until("DIS:777")) << client.received;
  // The recorded refusal, where the mock accepts.
  ASSERT_TRUE(client.send("LOGI:MD:MAN:0C#"));
  EXPECT_TRUE(client.read_until("LOGI:FB:MD:0:22#")) << client.received;
  // No recording of GS: the guide mock answers, and the desk says so.
  ASSERT_TRUE(client.send("LOGI:GS:001:CA#"));
  EXPECT_TRUE(client.read_until("LOGI:FB:GS:1:2C#")) << client.received;
  EXPECT_TRUE(mock.wait_for_line("no recording for LOGI:GS:001:CA#")) << mock.output();
  EXPECT_EQ(client.received.find("DIS:232"), std::string::npos) << client.received;
  EXPECT_EQ(mock.interrupt(), 0) << mock.output();
  // --log works as for any mock: the recorded answer is in the wire log.
  std::ifstream log(wire_log);
  const std::string logged((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  EXPECT_NE(logged.find("LOGI:FB:MD:0:22#"), std::string::npos);
  std::filesystem::remove(wire_log);
}

TEST(HilMock, ReplaySilentLeavesUnrecordedRequestsUnanswered) {
  const ReplayCapture capture;
  HilProcess mock(
      {"mock", "logi", "--replay", capture.path(), "--unmatched", "silent", "--port", "0"});
  int port = -1;
  ASSERT_NO_FATAL_FAILURE(wait_for_port(mock, port));
  Conn client = tcp_connect(port);
  ASSERT_TRUE(client.send("LOGI:GS:001:CA#"));
  EXPECT_TRUE(mock.wait_for_line("left unanswered")) << mock.output();
  EXPECT_FALSE(client.read_until("FB:GS", 1s)) << client.received;
  EXPECT_EQ(mock.interrupt(), 0);
}

TEST(HilMock, ReplayTakesFaultsLikeAnyMock) {
  const ReplayCapture capture;
  const auto faults = std::filesystem::temp_directory_path() /
                      ("hil-replay-cli-faults-" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(faults) << "rules:\n  - kind: drop\n    direction: to_client\n"
                           "    match: \"FB:MD\"\n";
  HilProcess mock(
      {"mock", "logi", "--replay", capture.path(), "--faults", faults.string(), "--port", "0"});
  int port = -1;
  ASSERT_NO_FATAL_FAILURE(wait_for_port(mock, port));
  Conn client = tcp_connect(port);
  ASSERT_TRUE(client.ok());
  EXPECT_TRUE(client.read_until("DIS:777")) << client.received;
  // The recorded answer is dropped on its way to the client.
  ASSERT_TRUE(client.send("LOGI:MD:MAN:0C#"));
  EXPECT_TRUE(mock.wait_for_line("drop")) << mock.output();
  EXPECT_EQ(client.received.find("FB:MD"), std::string::npos) << client.received;
  EXPECT_EQ(mock.interrupt(), 0) << mock.output();
  std::filesystem::remove(faults);
}

TEST(HilMock, AReplayThatCannotBePlayedIsRefused) {
  const ReplayCapture capture;
  expect_refused({"mock", "wr8", "--replay", capture.path(), "--port", "0"},
                 "is a capture of a logi car, not of a wr8 car");
  expect_refused(
      {"mock", "logi", "--replay", capture.path(), "--profile", "firmware", "--port", "0"},
      "was recorded in profile guide");
  expect_refused({"mock", "logi", "--replay", capture.path(), "--profile", "nope", "--port", "0"},
                 "--profile: logi has no profile 'nope'");
  expect_refused({"mock", "logi", "--replay", "/nonexistent/car.ndjson", "--port", "0"},
                 "--replay: /nonexistent/car.ndjson: cannot open");
  expect_refused(
      {"mock", "logi", "--replay", HIL_SOURCE_DIR "/tests/apps/data/bad-world.yaml", "--port", "0"},
      "bad-world.yaml:1: ");
  expect_refused({"mock", "logi", "--unmatched", "silent", "--port", "0"},
                 "--unmatched requires --replay");
}

}  // namespace
}  // namespace hil::test
