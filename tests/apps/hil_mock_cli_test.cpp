// hil mock as a desk user runs it: in the background, talked to over real
// TCP and a real pty, stopped with Ctrl-C.

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <ctime>
#include <filesystem>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include "tests/apps/hil_cli_support.hpp"

namespace hil::test {
namespace {

using namespace std::chrono_literals;

// A file descriptor the test reads with bounded waits.
class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  bool ok() const { return fd_ >= 0; }
  void send(const std::string& text) {
    ASSERT_EQ(::write(fd_, text.data(), text.size()), static_cast<ssize_t>(text.size()));
  }
  /// Reads until `text` has arrived (true) or `limit` passed or the peer closed.
  bool read_until(const std::string& text, std::chrono::milliseconds limit = 10s) {
    const auto deadline = std::chrono::steady_clock::now() + limit;
    while (received.find(text) == std::string::npos) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) return false;
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) return false;
      char buf[512];
      const ssize_t n = ::read(fd_, buf, sizeof buf);
      if (n <= 0) return false;
      received.append(buf, static_cast<std::size_t>(n));
    }
    return true;
  }
  std::string received;

 private:
  int fd_;
};

int port_in(const std::string& line) {
  std::smatch m;
  if (!std::regex_search(line, m, std::regex(R"(tcp://127\.0\.0\.1:(\d+))"))) return -1;
  return std::stoi(m[1]);
}

TEST(HilMock, LogiCarAnswersOverTcpAndStopsCleanlyOnCtrlC) {
  HilProcess mock({"mock", "logi", "--port", "0", "--seed", "7"});
  ASSERT_TRUE(mock.started());
  const auto line = mock.wait_for_line("connect to tcp://");
  ASSERT_TRUE(line) << mock.output();
  EXPECT_NE(mock.output().find("seed 7 (replay with --seed 7)"), std::string::npos);
  Fd client(connect_loopback(port_in(*line)));
  ASSERT_TRUE(client.ok());
  client.send("LOGI:SP:050:D7#");
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
  const auto first = mock.wait_for_line("car0 connect to");
  const auto second = mock.wait_for_line("car1 connect to");
  ASSERT_TRUE(first && second) << mock.output();
  ASSERT_NE(port_in(*first), port_in(*second));
  Fd a(connect_loopback(port_in(*first)));
  Fd b(connect_loopback(port_in(*second)));
  a.send("LOGI:MD:MAN:0C#");
  b.send("LOGI:MD:MAN:0C#");
  EXPECT_TRUE(a.read_until("FB:MD:1"));
  EXPECT_TRUE(b.read_until("FB:MD:1"));
  Fd extra(connect_loopback(port_in(*first)));
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
        port(listening ? ::open(path.c_str(), O_RDWR | O_NOCTTY) : -1) {}
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

  std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("hil-mock-ard-" + std::to_string(::getpid()));
  std::string path;
  HilProcess mock;
  std::optional<std::string> listening;
  Fd port;
};

TEST(HilMock, ArduinoRobotAnswersOnAPty) {
  ArduinoOnPty robot({});
  ASSERT_TRUE(robot.listening) << robot.mock.output();
  EXPECT_NE(robot.listening->find(robot.path), std::string::npos);
  ASSERT_TRUE(robot.port.ok());
  // The real client's PING (one space for no argument), answered as the
  // real sketch answers it: the default profile is the board people own.
  robot.port.send("^01|PING| *31$");
  EXPECT_TRUE(robot.port.read_until("^01|ACK|PONG*")) << robot.port.received;
  EXPECT_EQ(robot.mock.interrupt(), 0);
}

// --profile firmware plays the real sketch: the README's empty-payload PING
// is refused as the board refuses it, and the real client's one-space PING
// is answered PONG (arduino.ino at 8dcfab0); --profile readme takes it.
TEST(HilMock, ArduinoFirmwareProfileAnswersAsTheRealSketch) {
  ArduinoOnPty robot({"--profile", "firmware"});
  ASSERT_TRUE(robot.listening) << robot.mock.output();
  ASSERT_TRUE(robot.port.ok());
  robot.port.send("^01|PING|*11$");
  EXPECT_TRUE(robot.port.read_until("^01|NACK|BAD_FMT*41$")) << robot.port.received;
  robot.port.send("^02|PING| *32$");
  EXPECT_TRUE(robot.port.read_until("^02|ACK|PONG*5D$")) << robot.port.received;
  EXPECT_EQ(robot.mock.interrupt(), 0);
}

TEST(HilMock, ArduinoReadmeProfileAnswersTheReadmesFrames) {
  ArduinoOnPty robot({"--profile", "readme"});
  ASSERT_TRUE(robot.listening) << robot.mock.output();
  ASSERT_TRUE(robot.port.ok());
  robot.port.send("^01|PING|*11$");
  EXPECT_TRUE(robot.port.read_until("^01|ACK|OK*4C$")) << robot.port.received;
  EXPECT_EQ(robot.mock.interrupt(), 0);
}

// --reply-latency holds each answer back by the firmware's processing
// time; real time, so only the lower bound is checked.
TEST(HilMock, AReplyLatencyHoldsTheAnswerBackAtLeastThatLong) {
  ArduinoOnPty robot({"--reply-latency", "300ms"});
  ASSERT_TRUE(robot.listening) << robot.mock.output();
  ASSERT_TRUE(robot.port.ok());
  const auto sent = std::chrono::steady_clock::now();
  robot.port.send("^01|PING| *31$");
  ASSERT_TRUE(robot.port.read_until("^01|ACK|PONG*5E$")) << robot.port.received;
  EXPECT_GE(std::chrono::steady_clock::now() - sent, std::chrono::milliseconds(300));
  EXPECT_EQ(robot.mock.interrupt(), 0);
}

TEST(HilMock, AReplyLatencyWithoutAUnitIsRefused) {
  HilProcess mock({"mock", "arduino", "--reply-latency", "20", "--pty", "/tmp/hil-unused-ard"});
  EXPECT_EQ(mock.wait_exit(), 2) << mock.output();
  EXPECT_NE(mock.output().find("--reply-latency must be a duration with a unit (20ms, 1.5s), got "
                               "'20'"),
            std::string::npos)
      << mock.output();
}

TEST(HilMock, AnUnknownProfileIsRefusedWithTheCarsProfiles) {
  HilProcess mock({"mock", "leka", "--profile", "firmware", "--pty", "/tmp/hil-unused-leka"});
  EXPECT_EQ(mock.wait_exit(), 2) << mock.output();
  EXPECT_NE(mock.output().find("leka has no profile 'firmware'; its profiles are readme (the "
                               "default)"),
            std::string::npos)
      << mock.output();
}

TEST(HilMock, Wr8VehicleAuthenticatesWithTheConfiguredString) {
  HilProcess mock({"mock", "wr8", "--port", "0", "--auth", "0123456789"});
  const auto line = mock.wait_for_line("connect to tcp://");
  ASSERT_TRUE(line) << mock.output();
  Fd client(connect_loopback(port_in(*line)));
  client.send(std::string("\x01") + "0123456789");
  ASSERT_TRUE(client.read_until(std::string("\x02", 1))) << client.received.size();
  EXPECT_EQ(mock.interrupt(), 0);
}

TEST(HilMock, Wr8SvguiHeadStreamsDataStampedWithTheTimeOfDayAndAnswersTheRealGuisLogin) {
  HilProcess mock({"mock", "wr8", "--profile", "svgui-head", "--port", "0"});
  const auto line = mock.wait_for_line("connect to tcp://");
  ASSERT_TRUE(line) << mock.output();
  Fd client(connect_loopback(port_in(*line)));
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
  client.send(std::string("\x0C\x01konnichiwa", 12) + std::string(1, '\0'));
  EXPECT_TRUE(client.read_until(std::string("\x04\x02\x01\x02\x03", 5))) << client.received.size();
  EXPECT_EQ(mock.interrupt(), 0);
}

TEST(HilMock, Wr8SvguiHeadKeepsItsDataRates) {
  const auto r = run_hil("mock wr8 --profile svgui-head --data-hz 5");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("svgui-head vehicle sends HIGH-FREQ DATA every 50 ms"), std::string::npos)
      << r.output;
}

TEST(HilMock, DeskCommandsDropAParcelThatLocksTheCarAndTakeItAway) {
  HilProcess mock({"mock", "logi", "--port", "0", "--commands"});
  const auto line = mock.wait_for_line("connect to tcp://");
  ASSERT_TRUE(line) << mock.output();
  ASSERT_TRUE(mock.wait_for_line("type 'help' for desk commands"));
  Fd client(connect_loopback(port_in(*line)));
  client.send("LOGI:MD:MAN:0C#LOGI:MV:FWD:23#");
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
  const auto world = run_hil("mock logi --world tests/apps/data/bad-world.yaml");
  EXPECT_EQ(world.exit_code, 1);
  EXPECT_NE(world.output.find("hil mock: tests/apps/data/bad-world.yaml:"), std::string::npos)
      << world.output;
  const auto auth = run_hil("mock wr8 --auth short");
  EXPECT_EQ(auth.exit_code, 2);
  EXPECT_NE(auth.output.find("--auth must be exactly 10 characters, got 5"), std::string::npos)
      << auth.output;
  const auto car = run_hil("mock tesla");
  EXPECT_EQ(car.exit_code, 2);
  const auto behaviours = run_hil("mock logi --behaviours /nonexistent.yaml");
  EXPECT_EQ(behaviours.exit_code, 1);
  EXPECT_NE(behaviours.output.find("/nonexistent.yaml: cannot read the file"), std::string::npos)
      << behaviours.output;
}

TEST(HilMock, APortInUseIsReportedWithTheFix) {
  HilProcess first({"mock", "logi", "--port", "0"});
  const auto line = first.wait_for_line("connect to tcp://");
  ASSERT_TRUE(line) << first.output();
  const auto second = run_hil("mock logi --port " + std::to_string(port_in(*line)));
  EXPECT_EQ(second.exit_code, 1);
  EXPECT_NE(
      second.output.find("cannot listen on tcp://127.0.0.1:" + std::to_string(port_in(*line))),
      std::string::npos)
      << second.output;
  EXPECT_NE(second.output.find("choose another --port"), std::string::npos);
  EXPECT_EQ(first.interrupt(), 0);
}

}  // namespace
}  // namespace hil::test
