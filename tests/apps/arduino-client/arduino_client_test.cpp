// arduino-client run as a user runs it, against `hil mock arduino` on a real
// pty at 9600 baud: raw tokens, scripts, the REPL through a pipe, failures
// and their exit codes. Waits are bounded and generous.

#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "apps/arduino-client/app.hpp"
#include "tests/apps/client_program_support.hpp"

namespace hil::test {
namespace {

using namespace std::chrono_literals;

/// A temp dir with the mock robot on a pty in it.
struct ArduinoClientCli : ClientProgramTest {
  ArduinoClientCli() : ClientProgramTest(ARDUINO_CLIENT_BINARY, "hil-arduino-client") {
    port = temp.file("robot0");
  }

  void start_mock(std::vector<std::string> extra = {}) {
    ClientProgramTest::start_mock(mock_on_pty_args("arduino", port, std::move(extra)),
                                  "as a serial port at 9600 baud");
  }
};

TEST_F(ArduinoClientCli, RawTokensRunOnceEachAndTheStatusShowsTheSpeedSet) {
  start_mock();
  const auto r = client({"PING", "V 160", "STATUS"});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  expect_contains(r.output, {"PING -> ACK PONG\n", "V 160 -> ACK OK\n",
                             "STATUS -> ACK STATUS:V=160,DIR=stop,MOT:IDLE"});
  // The seed CLI's raw form works too, and the robot moves.
  const auto move = client({"v:200", "M:20", "status"});
  EXPECT_EQ(move.exit_code, 0) << move.output;
  EXPECT_TRUE(contains(move.output, "STATUS -> ACK STATUS:V=200,DIR=fwd,MOT:MOVE,tleft:"))
      << move.output;
}

// The real CLI's own command line (CLI.py at 8dcfab0) against the mock
// playing the real sketch: every command is answered as the board answers
// it, and V:999 goes out as typed and comes back NACK BAD_V.
TEST_F(ArduinoClientCli, TheRealClisCommandsAgainstTheSketchProfile) {
  start_mock({"--profile", "firmware"});
  const auto r = client({"--profile", "firmware", "--keep-going", "PING", "V:160", "M:20", "B", "I",
                         "STATUS", "S", "V:999", "HELP"});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  expect_contains(r.output, {"PING -> ACK PONG\n", "V 160 -> ACK OK\n", "M 20 -> ACK ACCEPTED\n",
                             "B -> ACK B:", "I -> ACK I:AL="});
  // (Moving or done by then, depending on the machine: 20 cm take 360 ms.)
  expect_contains(r.output,
                  {"STATUS -> ACK STATUS:V=160,DIR=", "S -> ACK STOPPED\n", "V:999 -> NACK BAD_V\n",
                   "HELP -> ACK CMDS:PING,HELP,STATUS,V,M,R,S,B,I\n"});
}

TEST_F(ArduinoClientCli, AnUnknownProfileIsRefusedWithTheValidNames) {
  const auto r = client({"--profile", "sketch", "PING"});
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output,
                       "arduino has no profile 'sketch'; its profiles are firmware (the "
                       "default) and readme"))
      << r.output;
}

TEST_F(ArduinoClientCli, AScriptRunsAndItsFrameLogIsWritten) {
  start_mock();
  const auto script = write("cmds.txt", "# speed, then look\nping\nV 120\n\nB\nstatus\n");
  const auto log = dir / "run.csv";
  const auto r = client({"--script", script.string(), "--log", log.string()});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  expect_contains(
      r.output, {"V 120 -> ACK OK\n", "B -> ACK ", "STATUS -> ACK STATUS:V=120,DIR=stop,MOT:IDLE"});
  const auto csv = read_file(log);
  EXPECT_EQ(csv.rfind("time,direction,seq,raw,hex\n", 0), 0u) << csv;
  expect_contains(csv, {",TX,01,^01|V|120*", ",RX,01,^01|ACK|OK*"});
}

TEST_F(ArduinoClientCli, TheExampleScriptsRunAgainstTheMock) {
  start_mock();
  const std::filesystem::path examples =
      std::filesystem::path(HIL_SOURCE_DIR) / "scenarios/clients/arduino-client";
  for (const auto& name : {"sensors.txt", "square.txt"}) {
    const auto r = client({"--script", (examples / name).string()});
    EXPECT_EQ(r.exit_code, 0) << name << "\n" << r.output;
    EXPECT_FALSE(contains(r.output, "NACK")) << r.output;
    // A pty shows its owner a client's close only until the next open: if
    // the next client opened the port before the mock ran again (a loaded
    // machine), both would be one session and the board would not reset.
    // A real port resets on every open; here the next run waits until the
    // mock has seen this one leave.
    ASSERT_TRUE(mock->process().wait_for_line("client gone", 20s)) << mock->output();
  }
  const auto r = client({"STATUS"});
  EXPECT_TRUE(contains(r.output, "STATUS -> ACK STATUS:V=140,DIR=stop,MOT:IDLE"))
      << "a fresh boot: " << r.output;
}

TEST_F(ArduinoClientCli, TheReplReadsAPipeAndQueuesLinesInOrder) {
  start_mock();
  HilProcess repl(ARDUINO_CLIENT_BINARY, {"--port", port});
  ASSERT_TRUE(repl.write_stdin("ping\n"));
  ASSERT_NO_FATAL_FAILURE(assert_lines(repl, {"PING -> ACK PONG"}));
  // Three lines at once: the second and third wait for the one before.
  ASSERT_TRUE(repl.write_stdin("V 170\nM 10\nstatus\n"));
  ASSERT_NO_FATAL_FAILURE(
      assert_lines(repl, {"V 170 -> ACK OK", "M 10 -> ACK ACCEPTED",
                          "STATUS -> ACK STATUS:V=170,DIR=fwd,MOT:MOVE,tleft:"}));
  // A bad line is an error and the REPL goes on.
  ASSERT_TRUE(repl.write_stdin("V 300\n"));
  const auto error = repl.wait_for_line("error: column 3:");
  ASSERT_TRUE(error) << repl.output();
  EXPECT_TRUE(contains(*error, "V needs a number 0..255, not '300'")) << *error;
  ASSERT_TRUE(repl.write_stdin("history\n"));
  ASSERT_NO_FATAL_FAILURE(
      assert_lines(repl, {"TX seq=00 ^00|PING| *30$", "|ACK|STATUS:V=170,DIR=fwd,MOT:MOVE"}));
  const auto log = dir / "session.ndjson";
  ASSERT_TRUE(repl.write_stdin("save-log " + log.string() + "\n"));
  const auto saved = repl.wait_for_line(" frame(s) to " + log.string() + " (ndjson)");
  ASSERT_TRUE(saved) << repl.output();
  // 8 frames, and 2 more for each health-check PING a slow machine let in.
  const int frames = std::stoi(saved->substr(saved->find("saved ") + 6));
  EXPECT_GE(frames, 8) << *saved;
  ASSERT_TRUE(repl.write_stdin("quit\n"));
  EXPECT_EQ(repl.wait_exit(20s), 0) << repl.output();
  EXPECT_FALSE(contains(repl.output(), "arduino> ")) << "no prompt on a pipe";
  const auto ndjson = read_file(log);
  expect_contains(ndjson, {R"("raw":"^00|PING| *30$")", R"("direction":"RX")"});
  EXPECT_EQ(std::count(ndjson.begin(), ndjson.end(), '\n'), frames) << ndjson;
}

TEST_F(ArduinoClientCli, TheReplEndsAtTheEndOfItsInputAfterTheLastReply) {
  start_mock();
  HilProcess repl(ARDUINO_CLIENT_BINARY, {"--port", port});
  ASSERT_TRUE(repl.write_stdin("V 90\nstatus"));  // the last line has no newline
  repl.close_stdin();
  EXPECT_EQ(repl.wait_exit(20s), 0) << repl.output();
  EXPECT_TRUE(contains(repl.output(), "V 90 -> ACK OK\n")) << repl.output();
  EXPECT_TRUE(contains(repl.output(), "STATUS -> ACK STATUS:V=90,DIR=stop,MOT:IDLE"))
      << repl.output();
}

TEST_F(ArduinoClientCli, ReconnectReopensThePortAndTheBoardResets) {
  start_mock();
  HilProcess repl(ARDUINO_CLIENT_BINARY, {"--port", port});
  ASSERT_TRUE(repl.write_stdin("V 99\nreconnect\nstatus\n"));
  ASSERT_NO_FATAL_FAILURE(assert_lines(
      repl, {"reconnected, link OPEN", "STATUS -> ACK STATUS:V=140,DIR=stop,MOT:IDLE"}));
  EXPECT_EQ(repl.interrupt(), 130) << repl.output();
}

TEST_F(ArduinoClientCli, ANackedCommandExits1WithItsCodeAndStopsTheRun) {
  const auto behaviours =
      write("reject-v.yaml", "behaviours:\n  - do: reject\n    match: V\n    times: 1\n");
  start_mock({"--behaviours", behaviours.string()});
  const auto r = client({"PING", "V 160", "STATUS"});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_TRUE(contains(r.output, "V 160 -> NACK BUSY\n")) << r.output;
  EXPECT_FALSE(contains(r.output, "STATUS ->")) << "the run stops at the failure: " << r.output;
  // --keep-going runs the rest and still exits 1.
  EXPECT_EQ(mock->stop(), 0) << mock->output();
  mock.reset();
  start_mock({"--behaviours", behaviours.string()});
  const auto all = client({"--keep-going", "V 160", "STATUS"});
  EXPECT_EQ(all.exit_code, 1) << all.output;
  EXPECT_TRUE(contains(all.output, "STATUS -> ACK STATUS:V=140,DIR=stop,MOT:IDLE")) << all.output;
}

TEST_F(ArduinoClientCli, ATypoInAScriptExits2WithFileLineAndColumn) {
  const auto out = expect_script_refused("typo.txt", "ping\nV 160\n  stauts\n",
                                         ":3:3: unknown command 'stauts'");
  EXPECT_FALSE(contains(out, "PING ->")) << "nothing runs: " << out;
  const auto token = client({"PING", "V 999"});
  EXPECT_EQ(token.exit_code, 2) << token.output;
  EXPECT_TRUE(contains(token.output, "argument 2 'V 999', column 3: V needs a number 0..255"))
      << token.output;
}

TEST_F(ArduinoClientCli, APortThatDoesNotExistIsAClearErrorAndExit1) {
  const auto r = client({"PING"});  // no mock: the pty path does not exist
  EXPECT_EQ(r.exit_code, 1) << r.output;
  expect_contains(r.output, {"link DOWN: cannot open " + port, "PING -> LINK DOWN ("});
}

TEST_F(ArduinoClientCli, BadUsageExits2AndHelpExits0) {
  HilProcess no_port(ARDUINO_CLIENT_BINARY, {"PING"});
  EXPECT_EQ(no_port.wait_exit(20s), 2) << no_port.output();
  EXPECT_TRUE(contains(no_port.output(), "--port")) << no_port.output();
  HilProcess both(ARDUINO_CLIENT_BINARY, {"--port", port, "--script", "x.txt", "PING"});
  EXPECT_EQ(both.wait_exit(20s), 2) << both.output();
  HilProcess help(ARDUINO_CLIENT_BINARY, {"--help"});
  EXPECT_EQ(help.wait_exit(20s), 0) << help.output();
  EXPECT_TRUE(contains(help.output(), "save-log")) << help.output();
}

TEST(ArduinoClientPort, ADevicePathIsASerialPortAndAUriIsTakenAsItIs) {
  using apps::arduino_client::endpoint_for_port;
  EXPECT_EQ(endpoint_for_port("/dev/ttyUSB0", 9600), serial_endpoint("/dev/ttyUSB0", 9600));
  EXPECT_EQ(endpoint_for_port("pty:///tmp/hil-arduino0", 115200),
            serial_endpoint("/tmp/hil-arduino0", 115200));
  EXPECT_EQ(endpoint_for_port("pty:///tmp/a?baud=300", 9600), serial_endpoint("/tmp/a", 300));
  EXPECT_EQ(endpoint_for_port("tcp://127.0.0.1:9200", 9600),
            link::Endpoint(link::TcpEndpoint{"127.0.0.1", 9200}));
  EXPECT_THROW(endpoint_for_port("ftp://x", 9600), link::EndpointError);
}

TEST(ArduinoClientTokens, EachArgumentIsOneCommandAndErrorsNameTheArgument) {
  using apps::arduino_client::commands_from_tokens;
  const auto ok = commands_from_tokens({"PING", "V:160", "m -20", "wait 1s"});
  EXPECT_TRUE(ok.errors.empty());
  EXPECT_EQ(ok.commands.size(), 4u);
  const auto bad = commands_from_tokens({"PING", "V", "R x"});
  ASSERT_EQ(bad.errors.size(), 2u);
  EXPECT_EQ(bad.errors[0], "argument 2 'V', column 2: V needs a number 0..255");
  EXPECT_EQ(bad.errors[1].rfind("argument 3 'R x', column 3: R needs an angle", 0), 0u);
}

}  // namespace
}  // namespace hil::test
