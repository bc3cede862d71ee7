#pragma once
// What wr8-client's console tests share: a mock vehicle on mem://car in
// virtual time, a session of the client, its runner and the console
// writing to a string, with the console's exit code and time.

#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "apps/wr8-client/console.hpp"
#include "link/endpoint.hpp"
#include "link/time.hpp"
#include "mocks/server.hpp"
#include "sim/presets.hpp"
#include "tests/client/client_test_support.hpp"
#include "tests/support/text.hpp"

namespace hil::apps::wr8_client {

using hil::test::contains;
using hil::test::expect_contains;

/// The options of a console reading lines as a person types them.
inline ConsoleOptions interactive() {
  ConsoleOptions o;
  o.interactive = true;
  return o;
}

/// `Firmware` behind a mock server named wr8 on mem://car, a `Session` to
/// it with its `Runner`, and the `Console` on both.
template <class Firmware, class Session, class Runner, class Console>
class ConsoleBench {
 public:
  /// `config` is the session's; `firmware_args` follow the world and the
  /// vehicle in the firmware's constructor.
  template <class Config, class... FirmwareArgs>
  ConsoleBench(Config config, ConsoleOptions options, FirmwareArgs&&... firmware_args) {
    mocks::ServerOptions server = client::test::on_mem("car");
    server.name = "wr8";
    car_.start_car(sim::wr8_vehicle(), std::move(server),
                   std::forward<FirmwareArgs>(firmware_args)...);
    session_ = std::make_unique<Session>(car_.context, link::MemEndpoint{"car"}, std::move(config),
                                         [this](link::Time now, const auto& e) {
                                           runner_->on_event(now, e);
                                           console_->on_event(now, e);
                                         });
    runner_ = std::make_unique<Runner>(car_.executor, *session_);
    console_ = std::make_unique<Console>(car_.executor, *session_, *runner_, out_,
                                         std::move(options), [this](int code) {
                                           exit_code_ = code;
                                           exit_at_ = car_.executor.now();
                                         });
  }

  Console& console() { return *console_; }
  Firmware& firmware() { return *car_.firmware; }
  void run_until(link::Time t) { car_.executor.run_until(t); }
  /// Runs until the console exits (at most 60 s of virtual time).
  void run_to_exit() {
    while (!exit_code_ && car_.executor.now() < link::seconds(60))
      car_.executor.run_until(car_.executor.now() + link::milliseconds(10));
  }
  /// Types each of `lines`, then runs until the console exits; its output.
  std::string lines_to_exit(const std::vector<std::string>& lines) {
    for (const auto& line : lines)
      console_->line(line);
    run_to_exit();
    return output();
  }
  /// Runs `actions` as a batch until the console exits; its output.
  std::string batch_to_exit(std::vector<typename Console::Action> actions) {
    console_->run_batch(std::move(actions));
    run_to_exit();
    return output();
  }
  std::string output() const { return out_.str(); }
  std::optional<int> exit_code() const { return exit_code_; }
  std::optional<link::Time> exit_at() const { return exit_at_; }

 private:
  client::test::VirtualCar<Firmware> car_;
  std::unique_ptr<Session> session_;
  std::unique_ptr<Runner> runner_;
  std::unique_ptr<Console> console_;
  std::ostringstream out_;
  std::optional<int> exit_code_;
  std::optional<link::Time> exit_at_;
};

}  // namespace hil::apps::wr8_client
