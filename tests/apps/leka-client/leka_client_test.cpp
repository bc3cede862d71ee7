// leka-client run as a user runs it: against `hil mock leka` on a real pty
// in a temporary folder, checking the program's output and exit code and
// what the robot received (the mock's wire log). Waits are bounded.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/apps/client_program_support.hpp"

namespace {

using namespace hil::test;

// The "delivered to the car" records of the mock's wire log file.
std::vector<std::string> delivered_to_car_of(const std::string& wire_log) {
  return delivered_to_car(read_file(wire_log));
}

// Every byte the car was delivered, in order, as "2A 2B ..": the link
// passes the client's writes through as the serial line cut them, so a
// frame may span records. A record gives its bytes as "hex", or as "text"
// when they are all printable.
std::string delivered_bytes_of(const std::string& wire_log) {
  std::string out;
  const auto add = [&](unsigned char byte) {
    char hex[4];
    std::snprintf(hex, sizeof hex, "%s%02X", out.empty() ? "" : " ", byte);
    out += hex;
  };
  for (const auto& line : delivered_to_car_of(wire_log)) {
    const auto record = nlohmann::json::parse(line);
    if (record.contains("hex")) {
      std::istringstream hex(record["hex"].get<std::string>());
      for (unsigned byte = 0; hex >> std::hex >> byte;)
        add(static_cast<unsigned char>(byte));
    } else {
      for (const char c : record["text"].get<std::string>())
        add(static_cast<unsigned char>(c));
    }
  }
  return out;
}

bool any_contains(const std::vector<std::string>& lines, const std::string& text) {
  for (const auto& l : lines)
    if (l.find(text) != std::string::npos) return true;
  return false;
}

// `hil mock leka` on a pty in `dir`, its wire log beside it.
struct MockLeka {
  explicit MockLeka(const TempDir& dir, std::vector<std::string> extra = {})
      : device(dir.file("leka0")),
        wire_log(dir.file("wire.ndjson")),
        car(mock_on_pty_args("leka", device, with_log(wire_log, std::move(extra))),
            "as a serial port at 115200 baud"),
        process(&car.process()),
        ready(car.ready()) {}
  static std::vector<std::string> with_log(const std::string& log, std::vector<std::string> extra) {
    extra.insert(extra.begin(), {"--log", log});
    return extra;
  }
  std::string device;
  std::string wire_log;
  MockCar car;
  HilProcess* process;
  bool ready = false;
};

const std::string kInfoTimeout = "--info-timeout-ms=5000";  // a loaded machine cannot miss it

TEST(LekaClientBatch, GroupsSetLedsAndMotorsAndTheInfoIsPrinted) {
  TempDir dir("hil-leka-client");
  MockLeka mock(dir);
  ASSERT_TRUE(mock.ready) << mock.process->output();
  HilProcess client(LEKA_CLIENT_BINARY,
                    {"--port", mock.device, kInfoTimeout, "--log", dir.file("run.csv"),
                     "ear all 255 0 0; belt range 0 9 0 0 255; motor duo 1 200 0 200", "info"});
  const auto code = client.wait_exit(std::chrono::seconds(20));
  ASSERT_EQ(code, 0) << client.output();
  EXPECT_NE(client.output().find("arg:1: ok, 3 commands, 1 frame, 21 bytes sent"),
            std::string::npos)
      << client.output();
  EXPECT_NE(client.output().find(
                "arg:2: ok, 1 command, 1 frame, 7 bytes sent; info name=leka firmware=1.0.0 "
                "buffer=128 state=ok"),
            std::string::npos)
      << client.output();
  // What the robot received: the group whole, then the info.
  const auto received = delivered_to_car_of(mock.wire_log);
  EXPECT_TRUE(contains(delivered_bytes_of(mock.wire_log),
                       "2A 2B 2C 2D 0F 11 FF 00 00 14 00 09 00 00 FF 22 01 C8 00 "
                       "C8 40"))
      << read_file(mock.wire_log);
  EXPECT_TRUE(any_contains(received, "motor.duo left=backward/200 right=forward/200"));
  EXPECT_TRUE(contains(delivered_bytes_of(mock.wire_log), "2A 2B 2C 2D 01 70 70"));
  // The client's own log holds both directions.
  const std::string log = read_file(dir.file("run.csv"));
  EXPECT_EQ(log.rfind("utc_us,direction,note,hex\n", 0), 0u) << log;
  EXPECT_NE(log.find(",RX,LEKA name=leka"), std::string::npos) << log;
  EXPECT_EQ(mock.car.stop(), 0);
}

TEST(LekaClientBatch, TheExampleShowScriptRunsAgainstTheMock) {
  TempDir dir("hil-leka-client");
  MockLeka mock(dir);
  ASSERT_TRUE(mock.ready) << mock.process->output();
  HilProcess client(LEKA_CLIENT_BINARY, {"--port", "pty://" + mock.device, kInfoTimeout, "--script",
                                         "scenarios/clients/leka-client/show.leka"});
  ASSERT_EQ(client.wait_exit(std::chrono::seconds(20)), 0) << client.output();
  const std::string out = client.output();
  EXPECT_NE(out.find("show.leka:7: ok, waited 300 ms"), std::string::npos) << out;
  EXPECT_NE(out.find("show.leka:10: ok, 1 command, 1 frame, 7 bytes sent; info name=leka"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("show.leka:12: ok"), std::string::npos) << out;
  const auto received = delivered_to_car_of(mock.wire_log);
  EXPECT_TRUE(any_contains(received, "stop.robot + led.belt.single led=0 rgb=(255,255,255)"))
      << read_file(mock.wire_log);
  EXPECT_EQ(mock.car.stop(), 0);
}

TEST(LekaClientBatch, TheInfoReportsTheRobotsFaultState) {
  TempDir dir("hil-leka-client");
  MockLeka mock(dir, {"--commands"});
  ASSERT_TRUE(mock.ready) << mock.process->output();
  ASSERT_TRUE(mock.process->wait_for_line("type 'help' for desk commands"));
  ASSERT_TRUE(mock.process->write_stdin("fault\n"));
  ASSERT_TRUE(mock.process->wait_for_line("car0: fault state")) << mock.process->output();
  HilProcess client(LEKA_CLIENT_BINARY, {"--port", mock.device, kInfoTimeout, "info"});
  ASSERT_EQ(client.wait_exit(std::chrono::seconds(20)), 0) << client.output();
  EXPECT_NE(client.output().find("state=fault"), std::string::npos) << client.output();
  EXPECT_EQ(mock.car.stop(), 0);
}

TEST(LekaClientBatch, ScriptFromStdinAndAnInterruptSendsStopRobot) {
  TempDir dir("hil-leka-client");
  MockLeka mock(dir);
  ASSERT_TRUE(mock.ready) << mock.process->output();
  HilProcess client(LEKA_CLIENT_BINARY, {"--port", mock.device, kInfoTimeout, "--script", "-"});
  ASSERT_TRUE(client.write_stdin("motor all 0 150\nwait 60s\nmotor all 0 10\n"));
  client.close_stdin();
  ASSERT_TRUE(client.wait_for_line("stdin:1: ok")) << client.output();
  EXPECT_EQ(client.interrupt(std::chrono::seconds(10)), 130) << client.output();
  EXPECT_NE(client.output().find("interrupted; stop robot sent"), std::string::npos)
      << client.output();
  // The robot got the stop (it is written before the port closes).
  bool stopped = false;
  for (int i = 0; i < 100 && !stopped; ++i) {
    stopped = contains(delivered_bytes_of(mock.wire_log), "2A 2B 2C 2D 01 FF FF");
    if (!stopped) ::usleep(100'000);
  }
  EXPECT_TRUE(stopped) << read_file(mock.wire_log);
  EXPECT_FALSE(contains(delivered_bytes_of(mock.wire_log), "2A 2B 2C 2D 03 21 00 0A"));
  EXPECT_EQ(mock.car.stop(), 0);
}

// Both ends in profile comspecs-v3: the client sends the spec's YAML ids
// with the 8-bit checksum, the mock runs them and answers info; the wire
// log records the profile. The README's client against that mock gets no
// answer to its info.
TEST(LekaClientBatch, TheComspecsProfileOnBothEndsTalks) {
  TempDir dir("hil-leka-client");
  MockLeka mock(dir, {"--profile", "comspecs-v3"});
  ASSERT_TRUE(mock.ready) << mock.process->output();
  HilProcess client(LEKA_CLIENT_BINARY, {"--port", mock.device, kInfoTimeout, "--profile",
                                         "comspecs-v3", "belt single 0x12 100 150 200", "info"});
  ASSERT_EQ(client.wait_exit(std::chrono::seconds(20)), 0) << client.output();
  EXPECT_NE(client.output().find("arg:2: ok, 1 command, 1 frame, 7 bytes sent; info name=leka"),
            std::string::npos)
      << client.output();
  const auto received = delivered_to_car_of(mock.wire_log);
  EXPECT_TRUE(contains(delivered_bytes_of(mock.wire_log), "2A 2B 2C 2D 05 16 12 64 96 C8 77"))
      << read_file(mock.wire_log);
  EXPECT_TRUE(any_contains(received, "led.belt.single led=18 rgb=(100,150,200)"));
  EXPECT_TRUE(contains(delivered_bytes_of(mock.wire_log), "2A 2B 2C 2D 01 70 F0"));
  EXPECT_NE(read_file(mock.wire_log).find("\"profile\":\"comspecs-v3\""), std::string::npos)
      << read_file(mock.wire_log);

  HilProcess readme(LEKA_CLIENT_BINARY, {"--port", mock.device, "--info-timeout-ms=500", "info"});
  EXPECT_EQ(readme.wait_exit(std::chrono::seconds(20)), 1) << readme.output();
  EXPECT_EQ(mock.car.stop(), 0);
}

TEST(LekaClientBatch, AnUnknownProfileIsAUsageErrorListingTheValidOnes) {
  HilProcess client(LEKA_CLIENT_BINARY, {"--dry-run", "--profile", "yaml", "info"});
  EXPECT_EQ(client.wait_exit(), 2);
  EXPECT_NE(
      client.output().find(
          "leka has no profile 'yaml'; its profiles are readme (the default) and comspecs-v3"),
      std::string::npos)
      << client.output();
}

TEST(LekaClientBatch, DryRunPrintsTheSeedsExampleFramesByteForByte) {
  HilProcess client(LEKA_CLIENT_BINARY, {"--dry-run", "--frame-bytes", "128", "--script",
                                         "scenarios/clients/leka-client/seed-examples.leka"});
  ASSERT_EQ(client.wait_exit(), 0) << client.output();
  const std::string out = client.output();
  EXPECT_NE(out.find("\n  2A 2B 2C 2D 05 15 00 FF 00 00 41\n"), std::string::npos) << out;
  EXPECT_NE(out.find("\n  2A 2B 2C 2D 01 70 70\n"), std::string::npos) << out;
  EXPECT_NE(out.find("\n  2A 2B 2C 2D 64 15 00 33 00 00 15 01 66 00 00 15 02 99 00 00 15 03 CC 00 "
                     "00 15 04 FF 00 00 15 05 00 00 00 15 06 00 33 00 15 07 00 66 00 15 08 00 99 "
                     "00 15 09 00 CC 00 15 0A 00 FF 00 15 0B 00 00 00 15 0C 00 00 33 15 0D 00 00 "
                     "66 15 0E 00 00 99 15 0F 00 00 CC 15 10 FF 00 00 15 11 00 FF 00 15 12 00 00 "
                     "FF 15 13 FF FF FF A8\n"),
            std::string::npos)
      << out;
}

TEST(LekaClientBatch, DryRunWithDefaultFramesSplitsTheBigGroup) {
  HilProcess client(LEKA_CLIENT_BINARY,
                    {"--dry-run", "--script", "scenarios/clients/leka-client/seed-examples.leka"});
  ASSERT_EQ(client.wait_exit(), 0) << client.output();
  const std::string out = client.output();
  EXPECT_NE(out.find("\n  2A 2B 2C 2D 37 15 00 33 00 00"), std::string::npos) << out;
  EXPECT_NE(out.find("\n  2A 2B 2C 2D 2D 15 0B 00 00 00"), std::string::npos) << out;
}

TEST(LekaClientBatch, ARangeErrorInAScriptIsExit2WithFileLineColumn) {
  TempDir dir("hil-leka-client");
  const std::string script = dir.file("bad.leka");
  std::ofstream(script) << "# lights\near all 255 0 0\nbelt single 20 0 0 255\n";
  // Nothing is opened: the script is checked first.
  HilProcess client(LEKA_CLIENT_BINARY, {"--port", dir.file("nothing-here"), "--script", script});
  ASSERT_EQ(client.wait_exit(), 2) << client.output();
  EXPECT_NE(client.output().find(script + ":3:13: belt single: led must be 0..19, got 20"),
            std::string::npos)
      << client.output();
}

TEST(LekaClientBatch, EveryBadLineOfAScriptIsReportedInOrder) {
  TempDir dir("hil-leka-client");
  const std::string script = dir.file("bad.leka");
  std::ofstream(script) << "ear all 255 0 0\nbelt single 20 0 0 255\ninfo\nmotor all 2 100\n";
  HilProcess client(LEKA_CLIENT_BINARY, {"--port", dir.file("nothing-here"), "--script", script});
  ASSERT_EQ(client.wait_exit(), 2) << client.output();
  const std::string expected =
      script + ":2:13: belt single: led must be 0..19, got 20\n" + script +
      ":4:11: motor all: direction must be 0 (forward) or 1 (backward), got 2\n";
  EXPECT_EQ(client.output(), expected);
}

TEST(LekaClientBatch, AMissingDeviceIsAClearErrorAndExit1) {
  TempDir dir("hil-leka-client");
  HilProcess client(LEKA_CLIENT_BINARY, {"--port", dir.file("no-robot"), "info"});
  ASSERT_EQ(client.wait_exit(), 1) << client.output();
  EXPECT_NE(
      client.output().find("cannot open " + dir.file("no-robot") + ": No such file or directory"),
      std::string::npos)
      << client.output();
}

TEST(LekaClientBatch, BadUsageIsExit2) {
  HilProcess nothing(LEKA_CLIENT_BINARY, {"--port", "/tmp/x"});
  EXPECT_EQ(nothing.wait_exit(), 2);
  EXPECT_NE(nothing.output().find("nothing to send"), std::string::npos) << nothing.output();
  HilProcess no_port(LEKA_CLIENT_BINARY, {"info"});
  EXPECT_EQ(no_port.wait_exit(), 2);
  HilProcess bad_log(LEKA_CLIENT_BINARY, {"--dry-run", "--log", "run.log", "info"});
  EXPECT_EQ(bad_log.wait_exit(), 2);
  EXPECT_NE(bad_log.output().find(".txt, .csv or .ndjson"), std::string::npos);
  HilProcess bad_group(LEKA_CLIENT_BINARY, {"--dry-run", "info", "motor all 0 300"});
  EXPECT_EQ(bad_group.wait_exit(), 2);
  EXPECT_NE(bad_group.output().find("arg:2:13: motor all: speed must be 0..255, got 300"),
            std::string::npos)
      << bad_group.output();
}

}  // namespace
