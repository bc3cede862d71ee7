// wr8-client's console (what it prints, in what order, and its exit code)
// against the mock vehicle on mem:// in virtual time, with exact times.

#include "apps/wr8-client/console.hpp"

#include <unistd.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "link/executor.hpp"
#include "link/transport.hpp"
#include "mocks/server.hpp"
#include "mocks/wr8.hpp"
#include "sim/presets.hpp"
#include "sim/world.hpp"

namespace hil::apps::wr8_client {
namespace {

using link::milliseconds;
using link::seconds;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// The mock vehicle, a session, a runner and the console writing to a string.
class Bench {
 public:
  explicit Bench(ConsoleOptions options)
      : vehicle_(world_.add_vehicle(sim::wr8_vehicle())), firmware_(world_, vehicle_) {
    mocks::ServerOptions server;
    server.listen = link::MemEndpoint{"car"};
    server.name = "wr8";
    server_ = std::make_unique<mocks::MockServer>(context_, firmware_, std::move(server));
    server_->start();
    session_ =
        std::make_unique<wr8::Wr8Session>(context_, link::MemEndpoint{"car"}, wr8::ClientConfig{},
                                          [this](link::Time now, const wr8::Event& e) {
                                            runner_->on_event(now, e);
                                            console_->on_event(now, e);
                                          });
    runner_ = std::make_unique<wr8::OperatorRunner>(executor_, *session_);
    console_ = std::make_unique<Wr8Console>(executor_, *session_, *runner_, out_,
                                            std::move(options), [this](int code) {
                                              exit_code_ = code;
                                              exit_at_ = executor_.now();
                                            });
  }

  Wr8Console& console() { return *console_; }
  mocks::Wr8Firmware& firmware() { return firmware_; }
  void run_until(link::Time t) { executor_.run_until(t); }
  /// Runs until the console exits (at most 60 s of virtual time).
  void run_to_exit() {
    while (!exit_code_ && executor_.now() < seconds(60))
      executor_.run_until(executor_.now() + milliseconds(10));
  }
  std::string output() const { return out_.str(); }
  std::optional<int> exit_code() const { return exit_code_; }
  std::optional<link::Time> exit_at() const { return exit_at_; }

 private:
  link::VirtualExecutor executor_;
  link::TransportContext context_{executor_};
  sim::World world_{sim::WorldDef{}};
  sim::Vehicle& vehicle_;
  mocks::Wr8Firmware firmware_;
  std::unique_ptr<mocks::MockServer> server_;
  std::unique_ptr<wr8::Wr8Session> session_;
  std::unique_ptr<wr8::OperatorRunner> runner_;
  std::unique_ptr<Wr8Console> console_;
  std::ostringstream out_;
  std::optional<int> exit_code_;
  std::optional<link::Time> exit_at_;
};

ConsoleOptions interactive() {
  ConsoleOptions o;
  o.interactive = true;
  return o;
}

TEST(Wr8Console, LinesRunInOrderAndStateComesAfterTheDrive) {
  Bench bench(interactive());
  for (const char* line : {"connect", "drive 20", "state", "quit"})
    bench.console().line(line);
  bench.run_to_exit();
  ASSERT_EQ(bench.exit_code(), kExitOk);
  const std::string out = bench.output();
  const auto started = out.find("   0.000 s  task drive (COI 0) started");
  const auto result = out.find("drive 20                 ok    completed");
  const auto state = out.find("odometry:   ");
  ASSERT_NE(started, std::string::npos) << out;
  ASSERT_NE(result, std::string::npos) << out;
  ASSERT_NE(state, std::string::npos) << out;
  EXPECT_LT(started, result);
  EXPECT_LT(result, state);
  EXPECT_TRUE(contains(out, "connection: connected")) << out;
  EXPECT_TRUE(contains(out, "battery:    100 %")) << out;
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
  EXPECT_TRUE(contains(out, "error: column 1: unknown action 'jump'")) << out;
  EXPECT_TRUE(contains(out, "   1.000 s  wait 1s                  ok")) << out;
}

TEST(Wr8Console, MutedDataIsReportedStaleAndFreshAgainAsItHappens) {
  Bench bench(interactive());
  bench.console().line("connect");
  bench.run_until(milliseconds(150));
  bench.firmware().arm({.name = "", .when = {}, .action = mocks::MuteTelemetry{seconds(1)}});
  bench.run_until(seconds(2));
  const std::string out = bench.output();
  // Last DATA at 100 ms; stale 500 ms later; DATA again on the grid after the mute.
  EXPECT_TRUE(contains(out, "   0.600 s  DATA stale: none for 500ms")) << out;
  EXPECT_TRUE(contains(out, "s  DATA flowing again")) << out;
}

TEST(Wr8Console, ADroppedConnectionIsReportedWithTheReconnect) {
  Bench bench(interactive());
  bench.console().line("connect");
  bench.run_until(milliseconds(500));
  bench.firmware().arm({.name = "", .when = {}, .action = mocks::CloseConnection{}});
  bench.run_until(seconds(3));
  const std::string out = bench.output();
  EXPECT_TRUE(contains(out, "connection lost; reconnecting")) << out;
}

TEST(Wr8Console, LogHistoryAndSaveLog) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("hil-wr8-console-" + std::to_string(::getpid()) + ".ndjson");
  Bench bench(interactive());
  for (const std::string& line :
       {std::string("connect"), std::string("log 1"), std::string("history"),
        "save-log " + path.string(), std::string("save-log"), std::string("help"),
        std::string("quit")})
    bench.console().line(line);
  bench.run_to_exit();
  const std::string out = bench.output();
  EXPECT_TRUE(contains(out, "RX   02 08 01 02  AuthReply")) << out;
  EXPECT_TRUE(contains(out, "saved ")) << out;
  EXPECT_TRUE(contains(out, "error: save-log needs a path")) << out;
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
  bench.console().run_batch({wr8::op::Connect{}, wr8::op::Wait{milliseconds(2500)}});
  bench.run_to_exit();
  EXPECT_EQ(bench.exit_code(), kExitOk);
  const std::string out = bench.output();
  EXPECT_TRUE(contains(out, "   0.100 s  data  STOP  odometry 0 cm")) << out;
  EXPECT_TRUE(contains(out, "   1.100 s  data  STOP")) << out;
  EXPECT_TRUE(contains(out, "   2.100 s  data  STOP")) << out;
  EXPECT_FALSE(contains(out, "   0.200 s  data")) << out;
  EXPECT_TRUE(contains(out, "   2.500 s  wait 2500ms")) << out;
}

TEST(Wr8Console, BatchExitsOneOnTheFirstFailure) {
  Bench bench(ConsoleOptions{});
  bench.console().run_batch({wr8::op::Connect{}, wr8::op::Turn{60}, wr8::op::Drive{10}});
  bench.run_to_exit();
  EXPECT_EQ(bench.exit_code(), kExitFailed);
  const std::string out = bench.output();
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
