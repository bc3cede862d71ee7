// leka-client's pieces without a port: the endpoint for --port, the log
// format by file name, the line printed per result and the dry-run text.

#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "apps/leka-client/app.hpp"
#include "tests/apps/client_program_support.hpp"

namespace hil::apps::leka_client {
namespace {

namespace leka = client::leka;

leka::Script script_of(const std::string& text) {
  auto parsed = leka::parse_script(text, "demo.leka");
  EXPECT_TRUE(parsed.ok()) << parsed.errors.front().to_string();
  return parsed;
}

TEST(LekaClientApp, APathIsASerialDeviceAndAUriKeepsItsOwnBaud) {
  using hil::test::serial_endpoint;
  EXPECT_EQ(endpoint_for_port("/dev/ttyUSB0", 115200), serial_endpoint("/dev/ttyUSB0", 115200));
  EXPECT_EQ(endpoint_for_port("pty:///tmp/hil-leka0", 57600),
            serial_endpoint("/tmp/hil-leka0", 57600));
  EXPECT_EQ(endpoint_for_port("pty:///tmp/hil-leka0?baud=9600", 57600),
            serial_endpoint("/tmp/hil-leka0", 9600));
  EXPECT_THROW(endpoint_for_port("bogus://x", 115200), link::EndpointError);
}

TEST(LekaClientApp, TheLogFormatFollowsTheExtension) {
  EXPECT_EQ(log_format_for("run.txt"), leka::LogFormat::txt);
  EXPECT_EQ(log_format_for("a/run.csv"), leka::LogFormat::csv);
  EXPECT_EQ(log_format_for("run.ndjson"), leka::LogFormat::ndjson);
  EXPECT_FALSE(log_format_for("run.json").has_value());
}

TEST(LekaClientApp, OneLinePerResult) {
  const auto script = script_of("ear all 1 2 3; info\nwait 1.5s\n");
  leka::LineResult group;
  group.number = 1;
  group.frames = 2;
  group.bytes = 17;
  leka::InfoReply reply;
  reply.fields = {
      {"name", "leka"}, {"state", "ok"}, {"buffer", "128"}, {"firmware", "1.0.0"}, {"extra", "1"}};
  group.infos.push_back(reply);
  EXPECT_EQ(format_result("demo.leka", group, script.lines[0].line),
            "demo.leka:1: ok, 2 commands, 2 frames, 17 bytes sent; info name=leka "
            "firmware=1.0.0 buffer=128 state=ok extra=1");
  leka::LineResult wait;
  wait.number = 2;
  EXPECT_EQ(format_result("demo.leka", wait, script.lines[1].line),
            "demo.leka:2: ok, waited 1500 ms");
  leka::LineResult failed;
  failed.number = 1;
  failed.ok = false;
  failed.error = "info: no answer within 200 ms";
  EXPECT_EQ(format_result("demo.leka", failed, script.lines[0].line),
            "demo.leka:1: FAILED: info: no answer within 200 ms");
}

TEST(LekaClientApp, DryRunShowsEachLineAndItsFrames) {
  const auto script = script_of("# x\nbelt single 0 255 0 0 # red\nwait 1s\ninfo\n");
  EXPECT_EQ(dry_run_text(script, {}),
            "demo.leka:2: belt single 0 255 0 0\n"
            "  2A 2B 2C 2D 05 15 00 FF 00 00 41\n"
            "demo.leka:3: wait 1s\n"
            "demo.leka:4: info\n"
            "  2A 2B 2C 2D 01 70 70\n");
}

TEST(LekaClientApp, ArgumentsOrAScriptFromStdin) {
  AppOptions options;
  options.groups = {"info", "stop robot"};
  std::istringstream none;
  const auto from_args = load_script(options, none);
  ASSERT_TRUE(from_args.ok());
  EXPECT_EQ(from_args.source, "arg");
  EXPECT_EQ(from_args.lines.size(), 2u);
  options.groups.clear();
  options.script = "-";
  std::istringstream in("info\near single 2 0 0 0\n");
  const auto from_stdin = load_script(options, in);
  ASSERT_EQ(from_stdin.errors.size(), 1u);
  EXPECT_EQ(from_stdin.errors[0].to_string(), "stdin:2:12: ear single: led must be 0..1, got 2");
}

TEST(LekaClientApp, FrameBytesSetsTheFrameSizeAndThePace) {
  AppOptions options;
  options.frame_bytes = 128;
  options.info_timeout_ms = 750;
  const auto config = config_for(options);
  EXPECT_EQ(config.max_frame_bytes, 128u);
  EXPECT_EQ(config.bytes_per_period, 128u);
  EXPECT_EQ(config.info_timeout, link::milliseconds(750));
}

}  // namespace
}  // namespace hil::apps::leka_client
