#include "harness/client_under_test.hpp"

#include <chrono>
#include <fstream>
#include <string>
#include <utility>

#include "harness/exec_client.hpp"
#include "harness/run_driver.hpp"
#include "protocol/common/car_profile.hpp"

namespace hil::harness {
namespace {

// An external client gets this long to exit after its stdin closed, then
// this long after SIGTERM before SIGKILL (docs/client-contract.md).
constexpr Duration kExitGrace = std::chrono::seconds(5);
constexpr Duration kTermGrace = std::chrono::seconds(2);

// The command of the external program, or null for the reference client.
const std::string* program_command(const ClientSetup& setup) {
  if (setup.options.client_exec) return &*setup.options.client_exec;
  if (const auto* exec = std::get_if<ExecClient>(&setup.scenario.client)) return &exec->command;
  return nullptr;
}

std::unique_ptr<ScenarioClient> make_reference(const ClientSetup& setup) {
  if (setup.options.reference_client) {
    if (auto replaced = setup.options.reference_client(setup)) return replaced;
  }
  const Scenario& scenario = setup.scenario;
  const auto* reference = std::get_if<ReferenceClient>(&scenario.client);
  return make_reference_client(scenario.car, setup.context, setup.car, setup.timeline,
                               reference ? reference->settings : nlohmann::json::object(),
                               scenario.profile);
}

// Every operator action of the scenario, one a line, for {actions}.
std::filesystem::path write_actions_file(const ClientSetup& setup) {
  const Scenario& scenario = setup.scenario;
  const auto path = setup.folder / "actions.txt";
  std::ofstream file(path);
  const auto write = [&file](const Step& step) {
    if (const auto* a = std::get_if<ActionStep>(&step.action)) file << a->text << '\n';
  };
  for (const auto* phase : {&scenario.setup, &scenario.steps, &scenario.teardown})
    for (const auto& step : *phase)
      write(step);
  for (const auto& s : scenario.schedule)
    write(s.step);
  if (!file) throw ClientSetupError("cannot write the actions file " + path.string());
  return path;
}

Placeholders placeholders(const ClientSetup& setup) {
  const Scenario& scenario = setup.scenario;
  Placeholders values;
  values["endpoint"] = link::to_uri(setup.car);
  values["profile"] = std::string(
      protocol::find_car_profile(mocks::to_string(scenario.car), scenario.profile).name);
  if (const auto* tcp = std::get_if<link::TcpEndpoint>(&setup.car)) {
    values["host"] = tcp->host;
    values["port"] = std::to_string(tcp->port);
  } else if (const auto* pty = std::get_if<link::PtyEndpoint>(&setup.car)) {
    values["pty"] = pty->path;
  }
  values["scenario"] = scenario.file.empty()
                           ? std::string()
                           : std::filesystem::absolute(scenario.file).lexically_normal().string();
  values["actions"] = write_actions_file(setup).string();
  return values;
}

std::unique_ptr<ScenarioClient> make_program(const ClientSetup& setup, const std::string& command) {
  ExecOptions o;
  o.environment = placeholders(setup);
  try {
    o.command = substitute_placeholders(command, o.environment);
  } catch (const std::invalid_argument& e) {
    throw ClientSetupError("the client command '" + command + "': " + e.what());
  }
  if (const auto* exec = std::get_if<ExecClient>(&setup.scenario.client))
    o.startup_timeout = exec->startup_timeout;
  if (setup.options.on_client_command) setup.options.on_client_command(o.command);
  return make_exec_client(setup.context, std::move(o), setup.timeline);
}

}  // namespace

ClientUnderTest::ClientUnderTest(const ClientSetup& setup)
    : executor_(setup.context.executor), timeline_(setup.timeline) {
  const std::string* command = program_command(setup);
  external_ = command != nullptr;
  session_ = external_ ? make_program(setup, *command) : make_reference(setup);
}

// An external program's shutdown is part of the run: it should stop the
// car and hang up once its input closes (docs/client-contract.md).
void ClientUnderTest::end_program(const Drive& drive) {
  const auto finished = [this] { return session_->finished(); };
  session_->stop();
  drive(finished, executor_.now() + kExitGrace);
  // Still running: SIGTERM, then SIGKILL, each with kTermGrace to take effect.
  const std::string notices[] = {
      "the client did not exit within " + run_seconds_text(kExitGrace) +
          " of its input closing: sent SIGTERM",
      "the client ignored SIGTERM for " + run_seconds_text(kTermGrace) + ": sent SIGKILL"};
  for (const bool hard : {false, true}) {
    if (finished()) return;
    timeline_.add(ClientKind::notice, {{"text", notices[hard ? 1 : 0]}});
    session_->terminate(hard);
    drive(finished, executor_.now() + kTermGrace);
  }
}

}  // namespace hil::harness
