#include "harness/runner.hpp"

#include <chrono>
#include <csignal>
#include <filesystem>
#include <functional>
#include <memory>
#include <random>
#include <utility>
#include <variant>

#include <stdlib.h>

#include <cerrno>
#include <cstring>

#include "harness/client_under_test.hpp"
#include "harness/emulated_car.hpp"
#include "harness/judging.hpp"
#include "harness/origin.hpp"
#include "harness/run_driver.hpp"
#include "harness/sim_observer.hpp"
#include "harness/step_sequencer.hpp"
#include "harness/timeline_recorder.hpp"
#include "link/endpoint.hpp"
#include "mocks/car.hpp"
#include "mocks/server.hpp"
#include "protocol/common/car_profile.hpp"
#include "sim/arena_yaml.hpp"

namespace hil::harness {
namespace {

// Teardown still runs after a timeout; it gets this long of its own.
constexpr Duration kTeardownGrace = std::chrono::seconds(10);
// The car is judged this long after the client stopped (docs/scenarios.md,
// "The end of a run"): long enough for any car's ramp down to rest.
constexpr Duration kEndLook = std::chrono::seconds(1);

// How long an external program may take to its first result line, which
// also bounds the wait for its origin (harness/origin.hpp).
Duration startup_timeout(const Scenario& scenario) {
  if (const auto* exec = std::get_if<ExecClient>(&scenario.client)) return exec->startup_timeout;
  return ExecClient{}.startup_timeout;
}

// Whether the run's client is an external program (the scenario's `exec`,
// or `hil run --client-exec`).
bool external_client(const Scenario& scenario, const RunOptions& options) {
  return options.client_exec || std::holds_alternative<ExecClient>(scenario.client);
}

// The world file as written, or next to the scenario file when relative.
std::string world_path(const Scenario& scenario) {
  std::filesystem::path p(scenario.world);
  if (p.is_relative() && !scenario.file.empty() && !std::filesystem::exists(p)) {
    const auto beside = std::filesystem::path(scenario.file).parent_path() / p;
    if (std::filesystem::exists(beside)) return beside.string();
  }
  return p.string();
}

// A folder of a real-time run's own for the car's pty and an external
// program's actions file, so runs in parallel never meet; removed with it.
class RunFolder {
 public:
  RunFolder() = default;
  RunFolder(const RunFolder&) = delete;
  RunFolder& operator=(const RunFolder&) = delete;
  ~RunFolder() {
    if (path_.empty()) return;
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }

  /// Makes the folder; the reason for the run's outcome when it cannot.
  std::optional<std::string> make() {
    std::string pattern = (std::filesystem::temp_directory_path() / "hil-run-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr)
      return "cannot make a temporary folder for the run: " + std::string(std::strerror(errno));
    path_ = pattern;
    return std::nullopt;
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// One run of one scenario: the car and its world behind the faulty link,
// the client under test, the steps and the observer of the simulation,
// all on one driver; then the verdicts.
class ScenarioRun {
 public:
  ScenarioRun(const Scenario& scenario, const RunOptions& options, ScenarioOutcome& out)
      : scenario_(scenario),
        options_(options),
        out_(out),
        driver_(make_run_driver(out.real_time)),
        timeline_(driver_->executor()) {}

  void run();

 private:
  link::Executor& executor() { return driver_->executor(); }
  bool build();
  bool build_car();
  std::optional<link::Endpoint> listen_endpoint();
  bool start_server(const link::Endpoint& listen);
  bool make_client(const link::Endpoint& car);
  void play_steps();
  void drive(const std::function<bool()>& done, Time deadline);
  void end();
  Time stop_client();

  const Scenario& scenario_;
  const RunOptions& options_;
  ScenarioOutcome& out_;

  // Destroyed last to first: the folder outlives what is in it, the
  // driver's executor everything that schedules on it, the timeline
  // everything that writes to it.
  RunFolder folder_;
  std::unique_ptr<RunDriver> driver_;
  RunTimeline timeline_;
  std::unique_ptr<mocks::MockCar> car_;
  std::shared_ptr<WireRecorder> wire_;
  std::unique_ptr<mocks::MockServer> server_;
  std::unique_ptr<ClientUnderTest> client_;
  std::unique_ptr<SimObserver> observer_;
  std::unique_ptr<StepSequencer> steps_;
  std::unique_ptr<OriginWatch> origin_;  // an external program's
  bool stuck_ = false;
};

bool ScenarioRun::build() {
  if (!build_car()) return false;
  const auto listen = listen_endpoint();
  if (!listen || !start_server(*listen)) return false;
  // Under real time the listener chose the port; the client goes there.
  return make_client(driver_->real_time() ? link::parse_endpoint(server_->address()) : *listen);
}

bool ScenarioRun::build_car() {
  mocks::CarOptions car;
  car.kind = scenario_.car;
  car.seed = mocks::car_seed(out_.seed, 0);
  car.name = "car0";
  try {
    // The emulated board first: the profile sets its framing too. A car
    // played from a capture plays it, whatever firmware the scenario names.
    if (!options_.replay) {
      car.configs.avr = options_.firmware ? options_.firmware : scenario_.firmware;
      if (car.configs.avr && options_.on_firmware_note)
        car.configs.avr->log = options_.on_firmware_note;
    }
    mocks::apply_profile(car.configs, scenario_.car, scenario_.profile);
    if (scenario_.reply_latency) car.configs.reply_latency = *scenario_.reply_latency;
    // An external client's run times count from its first connection (its
    // origin), and so do the LOGI car's STAT and control grids, as they
    // count from time 0 with the reference client.
    car.configs.logi.grid_from_first_connection = external_client(scenario_, options_);
    if (!scenario_.world.empty()) car.arena = sim::load_arena(world_path(scenario_));
    car.replay = options_.replay ? options_.replay : scenario_.replay;
    car_ = std::make_unique<mocks::MockCar>(std::move(car));
  } catch (const std::exception& e) {
    out_.error = std::string("the world cannot be built: ") + e.what();
    return false;
  }
  return true;
}

std::optional<link::Endpoint> ScenarioRun::listen_endpoint() {
  if (!driver_->real_time()) {
    // A serial car's line keeps its baud in virtual time too: every byte
    // takes its 10 bits of line time, as on the pty.
    link::MemEndpoint mem{"car0"};
    const link::Endpoint e = mocks::default_endpoint(scenario_.car, 0);
    if (const auto* pty = std::get_if<link::PtyEndpoint>(&e)) mem.baud = pty->baud;
    return mem;
  }
  if (auto error = folder_.make()) {
    out_.error = std::move(*error);
    return std::nullopt;
  }
  link::Endpoint e = mocks::default_endpoint(scenario_.car, 0);
  if (auto* tcp = std::get_if<link::TcpEndpoint>(&e)) {
    tcp->host = "127.0.0.1";
    tcp->port = 0;  // any free port
  } else if (auto* pty = std::get_if<link::PtyEndpoint>(&e)) {
    pty->path = (folder_.path() / "car0").string();
  }
  return e;
}

bool ScenarioRun::start_server(const link::Endpoint& listen) {
  mocks::ServerOptions server;
  server.listen = listen;
  // An external program's fault times count from its origin, which its
  // first contact fixes (StepSequencer::origin_fixed moves them then); until
  // that, what is in force from time 0 stays in force.
  server.faults = external_client(scenario_, options_) && has_timed_rules(scenario_.faults)
                      ? awaiting_origin(scenario_.faults)
                      : scenario_.faults;
  server.seed = out_.seed;
  server.name = "car0";
  if (!options_.work_dir.empty()) {
    out_.wire_log = (std::filesystem::path(options_.work_dir) / "wire.ndjson").string();
    server.wire_log_path = out_.wire_log;
  }
  wire_ = std::make_shared<WireRecorder>(timeline_, car_->firmware().adapter());
  server.observers.push_back(wire_);
  server_ =
      std::make_unique<mocks::MockServer>(driver_->context(), car_->firmware(), std::move(server));
  try {
    server_->start();
  } catch (const std::exception& e) {
    out_.error = std::string("the car cannot listen: ") + e.what();
    return false;
  }
  return true;
}

bool ScenarioRun::make_client(const link::Endpoint& car) {
  try {
    client_ = std::make_unique<ClientUnderTest>(
        ClientSetup{scenario_, options_, driver_->context(), timeline_, car, folder_.path()});
  } catch (const ClientSetupError& e) {
    out_.error = e.what();
    return false;
  }
  return true;
}

void ScenarioRun::drive(const std::function<bool()>& done, Time deadline) {
  if (stuck_) return;
  if (auto error = driver_->drive(done, deadline)) {
    stuck_ = true;
    out_.error = *error;
  }
}

void ScenarioRun::run() {
  if (!build()) return;
  steps_ = std::make_unique<StepSequencer>(
      scenario_, out_.steps,
      StepTargets{executor(), timeline_, *car_, *server_, client_->session()});
  // The world starts at rest: that is the state the first transition leaves.
  timeline_.add(SimKind::at_rest);
  // An external program's run times count from its first contact with the
  // car; the reference client's from the run's start.
  if (client_->external()) {
    origin_ = std::make_unique<OriginWatch>(executor(), timeline_, startup_timeout(scenario_));
    client_->session().on_first_result([this] { origin_->first_result(); });
  }
  client_->session().start();
  observer_ = std::make_unique<SimObserver>(executor(), *car_, timeline_, options_.sample_period,
                                            [this] { client_->session().poll(); });
  observer_->start();
  play_steps();
  end();
}

// The main sequence within the scenario's timeout, the teardown within its
// grace, then the settle time.
void ScenarioRun::play_steps() {
  using Sequence = StepSequencer::Sequence;
  steps_->start_schedule();
  if (origin_) {
    origin_->when_fixed([this](const Origin& origin) {
      steps_->origin_fixed(origin.at);
      // The car's clocks count from the origin too, however it was fixed.
      car_->firmware().set_clock_origin(origin.at);
    });
  } else
    steps_->origin_fixed(Time(0));
  // A serial car has no `connect` step: an external program opens the port
  // when it starts, as it would connect. Its steps begin at its origin (that
  // opening, its first result line, or its startup timeout), so the windows
  // after a step do not count the program's start-up.
  if (origin_ &&
      std::holds_alternative<link::PtyEndpoint>(mocks::default_endpoint(scenario_.car, 0)))
    origin_->when_fixed([this](const Origin&) { steps_->start(Sequence::main); });
  else
    steps_->start(Sequence::main);
  drive([this] { return steps_->done(Sequence::main); }, Time(0) + scenario_.timeout);
  if (!steps_->done(Sequence::main))
    steps_->time_out(Sequence::main, "timed out after " + run_seconds_text(scenario_.timeout));

  steps_->start(Sequence::teardown);
  drive([this] { return steps_->done(Sequence::teardown); }, executor().now() + kTeardownGrace);
  if (!steps_->done(Sequence::teardown))
    steps_->time_out(Sequence::teardown,
                     "teardown timed out after " + run_seconds_text(kTeardownGrace));

  drive([] { return false; }, executor().now() + scenario_.settle);
}

// The client stops (an external program's input closes and it exits; the
// reference client quits as an operator would); the car is judged
// kEndLook later, then everything closes.
void ScenarioRun::end() {
  steps_->stop_schedule();
  // Expectations judge the session up to here: an external program's
  // shutdown after its input closed (a last stop, the hang-up) is the
  // contract's business, judged by its exit and the car's state after it.
  const Time session_end = executor().now();
  const std::size_t session_records = timeline_.timeline().size();
  const Origin origin = origin_ ? origin_->settled() : Origin{};
  const Time client_end = stop_client();
  drive([] { return false; }, client_end + kEndLook);
  const SimObserver::Motion motion = observer_->motion();
  observer_->stop();
  const Time run_end = executor().now();
  steps_->close();
  timeline_.close();
  server_->close();
  // What the closes cause, outside the timeline (a moment of real time for
  // sockets to finish closing).
  drive([] { return false; },
        driver_->real_time() ? run_end + std::chrono::milliseconds(20) : run_end);

  out_.timeline = timeline_.take();
  out_.arena = car_->world().arena();
  out_.trajectories = observer_->trajectories();
  out_.run_time = run_end;
  out_.session_end = session_end;
  out_.expectations = judge(JudgedRun{
      scenario_, out_.timeline, client_->external(), session_end, session_records, client_end,
      time_slack(options_, driver_->real_time(),
                 dynamic_cast<const mocks::AvrFirmware*>(&car_->firmware()) != nullptr),
      origin,
      EndMotion{run_end - client_end, run_end, motion.moving, motion.speed_mps, motion.driven}});
}

// Stops the client; returns when it had stopped.
Time ScenarioRun::stop_client() {
  if (client_->external())
    client_->end_program(
        [this](const std::function<bool()>& done, Time deadline) { drive(done, deadline); });
  else
    client_->session().stop();
  return executor().now();
}

std::uint64_t chosen_seed(const Scenario& scenario, const RunOptions& options) {
  if (options.seed) return *options.seed;
  if (scenario.seed) return *scenario.seed;
  return (static_cast<std::uint64_t>(std::random_device{}()) << 32) | std::random_device{}();
}

}  // namespace

namespace {

// Why the capture of --replay cannot play `scenario`'s car, or nullopt.
std::optional<std::string> replay_mismatch(const Scenario& scenario,
                                           const mocks::ReplaySpec& replay) {
  if (!replay.capture) return std::nullopt;
  const auto& header = replay.capture->header;
  const std::string car(mocks::to_string(scenario.car));
  if (header.car != car)
    return "its car is " + car + " and --replay " + replay.path + " is a capture of " + header.car;
  const auto& wanted = protocol::find_car_profile(car, scenario.profile).name;
  const auto& recorded = protocol::find_car_profile(car, header.profile).name;
  if (wanted != recorded) {
    return "its car plays profile " + std::string(wanted) + " and --replay " + replay.path +
           " was probed in profile " + std::string(recorded);
  }
  return std::nullopt;
}

// Why the firmware of --sketch or --elf cannot play `scenario`'s car, or nullopt.
std::optional<std::string> firmware_mismatch(const Scenario& scenario, const RunOptions& options) {
  const std::string& given = options.firmware_given;
  if (scenario.car != mocks::CarKind::arduino) {
    return "its car is " + std::string(mocks::to_string(scenario.car)) + " and " + given +
           " runs on the emulated Arduino board";
  }
  if (scenario.replay) {
    return "its car plays the capture " + scenario.replay->path + " (car: replay:), not " + given;
  }
  if (auto why = emulated_board_problem(scenario))
    return *why + ": " + given + " runs on the emulated board as it is (docs/firmware.md)";
  return std::nullopt;
}

}  // namespace

std::optional<std::string> skip_reason(const Scenario& scenario, const RunOptions& options) {
  if (options.replay) {
    if (auto why = replay_mismatch(scenario, *options.replay)) return why;
  }
  if (options.firmware) {
    if (auto why = firmware_mismatch(scenario, options)) return why;
  }
  const auto* reference = std::get_if<ReferenceClient>(&scenario.client);
  if (!options.client_exec || reference == nullptr || reference->settings.empty())
    return std::nullopt;
  std::string names;
  for (const auto& [name, value] : reference->settings.items())
    names += (names.empty() ? "" : ", ") + name;
  return "it sets hil's reference client's " + names +
         " (client: reference: settings:), which the program given by --client-exec does not "
         "take; give the program those options on its own command line and run a copy of the "
         "scenario without the settings (docs/scenarios.md, \"Skipped scenarios\")";
}

bool runs_in_real_time(const Scenario& scenario, const RunOptions& options) {
  return external_client(scenario, options) || std::get<ReferenceClient>(scenario.client).real_time;
}

ScenarioOutcome run_scenario(const Scenario& scenario, const RunOptions& options) {
  const auto wall_start = std::chrono::steady_clock::now();
  ScenarioOutcome out;
  out.file = scenario.file;
  out.name = scenario.name;
  out.tags = scenario.tags;
  out.seed = chosen_seed(scenario, options);
  out.repro_command = "hil run " + (scenario.file.empty() ? scenario.name : scenario.file) +
                      " --seed " + std::to_string(out.seed);

  if (auto why = skip_reason(scenario, options)) {
    out.skipped = std::move(*why);
    return out;
  }
  const bool exec = external_client(scenario, options);
  out.real_time = runs_in_real_time(scenario, options);
  // A program that closes its stdin early must not end hil with SIGPIPE;
  // the write fails with EPIPE instead.
  if (exec) std::signal(SIGPIPE, SIG_IGN);
  ScenarioRun(scenario, options, out).run();
  out.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return out;
}

}  // namespace hil::harness
