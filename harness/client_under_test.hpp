#pragma once
// The client a scenario runs against: the car's reference client, or an
// external program (the scenario's `client: exec`, or RunOptions::
// client_exec for every scenario) started the way docs/client-contract.md
// says, with its placeholders and its actions file filled in.

#include <filesystem>
#include <functional>
#include <memory>
#include <stdexcept>

#include "harness/reference_client.hpp"
#include "harness/runner.hpp"
#include "harness/timeline_recorder.hpp"
#include "link/endpoint.hpp"
#include "link/transport.hpp"

namespace hil::harness {

/// Why the client could not be set up; the run's outcome error says it.
struct ClientSetupError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// What the client is made from. The references must outlive the client.
struct ClientSetup {
  const Scenario& scenario;
  const RunOptions& options;
  link::TransportContext& context;
  RunTimeline& timeline;
  /// Where the car listens.
  link::Endpoint car;
  /// The run's own folder, where an external program's actions file goes.
  std::filesystem::path folder;
};

class ClientUnderTest {
 public:
  /// Runs tasks until `done` or `deadline` (the run's driver).
  using Drive = std::function<void(const std::function<bool()>& done, Time deadline)>;

  /// Makes the client; an external program is started by session().start().
  /// Throws ClientSetupError when the actions file cannot be written or
  /// the command names a placeholder it cannot have.
  explicit ClientUnderTest(const ClientSetup& setup);

  ScenarioClient& session() { return *session_; }
  /// An external program (else the reference client).
  bool external() const { return external_; }

  /// An external program's shutdown, part of the run: closes its input and
  /// waits for it to exit; SIGTERM, then SIGKILL, when it does not in time
  /// (each noted in the timeline).
  void end_program(const Drive& drive);

 private:
  link::Executor& executor_;
  RunTimeline& timeline_;
  bool external_ = false;
  std::unique_ptr<ScenarioClient> session_;
};

}  // namespace hil::harness
