// wr8-client's console (what it prints, in what order, and its exit code)
// against the mock vehicle on mem:// in virtual time, with exact times.

#include "apps/wr8-client/console.hpp"

#include <unistd.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include "mocks/wr8.hpp"
#include "tests/apps/wr8-client/console_bench.hpp"

namespace hil::apps::wr8_client {
namespace {

using link::milliseconds;
using link::seconds;

/// The mock vehicle, a session, a runner and the console writing to a string.
struct Bench : ConsoleBench<mocks::Wr8Firmware, wr8::Wr8Session, wr8::OperatorRunner, Wr8Console> {
  explicit Bench(ConsoleOptions options) : ConsoleBench(wr8::ClientConfig{}, std::move(options)) {}
};

TEST(Wr8Console, LinesRunInOrderAndStateComesAfterTheDrive) {
  Bench bench(interactive());
  const std::string out = bench.lines_to_exit({"connect", "drive 20", "state", "quit"});
  ASSERT_EQ(bench.exit_code(), kExitOk);
  const auto started = out.find("   0.000 s  task drive (COI 0) started");
  const auto result = out.find("drive 20                 ok    completed");
  const auto state = out.find("odometry:   ");
  ASSERT_NE(started, std::string::npos) << out;
  ASSERT_NE(result, std::string::npos) << out;
  ASSERT_NE(state, std::string::npos) << out;
  EXPECT_LT(started, result);
  EXPECT_LT(result, state);
  expect_contains(out, {"connection: connected", "battery:    100 %"});
  EXPECT_FALSE(contains(out, "wr8> ")) << out;
}

TEST(Wr8Console, ABadLineIsAMessageAndTheLoopGoesOn) {
  Bench bench(interactive());
  bench.console().line("jump 3");
  bench.console().line("wait 1s");
  bench.console().end_of_input();
  bench.run_to_exit();
  EXPECT_EQ(bench.exit_code(), kExitOk);
  EXPECT_EQ(bench.exit_at(), seconds(1));  // end of input waits for the queue
  const std::string out = bench.output();
  expect_contains(
      out, {"error: column 1: unknown action 'jump'", "   1.000 s  wait 1s                  ok"});
}

/// Connects, arms `action` on the car at `at`, and gives the console's
/// output at `until`.
std::string output_with(link::Time at, mocks::Action action, link::Time until) {
  Bench bench(interactive());
  bench.console().line("connect");
  bench.run_until(at);
  bench.firmware().arm({.name = "", .when = {}, .action = std::move(action)});
  bench.run_until(until);
  return bench.output();
}

TEST(Wr8Console, MutedDataIsReportedStaleAndFreshAgainAsItHappens) {
  const std::string out =
      output_with(milliseconds(150), mocks::MuteTelemetry{seconds(1)}, seconds(2));
  // Last DATA at 100 ms; stale 500 ms later; DATA again on the grid after the mute.
  expect_contains(out, {"   0.600 s  DATA stale: none for 500ms", "s  DATA flowing again"});
}

TEST(Wr8Console, ADroppedConnectionIsReportedWithTheReconnect) {
  const std::string out = output_with(milliseconds(500), mocks::CloseConnection{}, seconds(3));
  EXPECT_TRUE(contains(out, "connection lost; reconnecting")) << out;
}

TEST(Wr8Console, LogHistoryAndSaveLog) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("hil-wr8-console-" + std::to_string(::getpid()) + ".ndjson");
  Bench bench(interactive());
  const std::string out = bench.lines_to_exit(
      {"connect", "log 1", "history", "save-log " + path.string(), "save-log", "help", "quit"});
  expect_contains(out, {"RX   02 08 01 02  AuthReply", "saved ", "error: save-log needs a path"});
  EXPECT_TRUE(contains(out, "wait-data")) << out;  // help
  std::ifstream in(path);
  std::string first;
  std::getline(in, first);
  EXPECT_EQ(first.rfind("{", 0), 0u) << first;
  std::filesystem::remove(path);
}

TEST(Wr8Console, BatchPrintsDataOnChangeOrOnceASecond) {
  ConsoleOptions o;
  o.print_data = true;
  Bench bench(o);
  const std::string out =
      bench.batch_to_exit({wr8::op::Connect{}, wr8::op::Wait{milliseconds(2500)}});
  EXPECT_EQ(bench.exit_code(), kExitOk);
  expect_contains(out, {"   0.100 s  data  STOP  odometry 0 cm", "   1.100 s  data  STOP",
                        "   2.100 s  data  STOP"});
  EXPECT_FALSE(contains(out, "   0.200 s  data")) << out;
  EXPECT_TRUE(contains(out, "   2.500 s  wait 2500ms")) << out;
}

TEST(Wr8Console, BatchExitsOneOnTheFirstFailure) {
  Bench bench(ConsoleOptions{});
  const std::string out =
      bench.batch_to_exit({wr8::op::Connect{}, wr8::op::Turn{60}, wr8::op::Drive{10}});
  EXPECT_EQ(bench.exit_code(), kExitFailed);
  EXPECT_TRUE(contains(out, "turn 60                  FAIL  the vehicle answered error")) << out;
  EXPECT_FALSE(contains(out, "drive 10")) << out;
}

TEST(Wr8Console, InterruptExits130) {
  Bench bench(interactive());
  bench.console().line("connect");
  bench.console().line("drive 50");
  bench.run_until(milliseconds(300));
  ASSERT_TRUE(bench.firmware().state().drive.has_value());
  bench.console().interrupt();
  EXPECT_EQ(bench.exit_code(), kExitInterrupted);
  EXPECT_TRUE(contains(bench.output(), "interrupted")) << bench.output();
  // The disconnect reached the car: it dropped the drive and stops.
  bench.run_until(milliseconds(310));
  EXPECT_FALSE(bench.firmware().state().drive.has_value());
}

}  // namespace
}  // namespace hil::apps::wr8_client
