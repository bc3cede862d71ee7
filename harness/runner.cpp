#include "harness/runner.hpp"

#include "protocol/common/car_profile.hpp"

#include <chrono>
#include <cmath>
#include <csignal>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <numbers>
#include <random>
#include <sstream>
#include <thread>
#include <utility>
#include <vector>

#include <stdlib.h>

#include <cerrno>
#include <cstring>

#include <asio/io_context.hpp>

#include "harness/exec_client.hpp"
#include "harness/expect.hpp"
#include "harness/reference_client.hpp"
#include "harness/timeline_recorder.hpp"
#include "link/asio_executor.hpp"
#include "link/executor.hpp"
#include "link/transport.hpp"
#include "mocks/car.hpp"
#include "mocks/server.hpp"
#include "protocol/common/overloaded.hpp"
#include "sim/arena_yaml.hpp"
#include "sim/geometry.hpp"
#include "sim/recorder.hpp"

namespace hil::harness {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

// How often the simulation is looked at for stations, collisions and
// rest; samples go out at RunOptions::sample_period on top of it.
constexpr Duration kSimTick = milliseconds(10);
// The chassis counts as moving at 5 mm/s or 0.02 rad/s (about 1 degree/s)
// and as at rest again below half of each, so the noise of a car standing
// on its wheels does not flood the timeline with transitions.
constexpr double kMovingMps = 0.005;
constexpr double kMovingRadps = 0.02;
// Teardown still runs after a timeout; it gets this long of its own.
constexpr Duration kTeardownGrace = seconds(10);
// A guard against a run that makes no progress in time.
constexpr std::uint64_t kMaxTasks = 50'000'000;
// An external client gets this long to exit after its stdin closed, then
// this long after SIGTERM before SIGKILL (docs/client-contract.md).
constexpr Duration kExitGrace = seconds(5);
constexpr Duration kTermGrace = seconds(2);
// Under the real-time driver, the longest the loop waits for the next
// handler before looking at `done` again.
constexpr auto kRealTimeSlice = std::chrono::milliseconds(20);

std::string run_seconds_text(Duration d) {
  const double s = std::chrono::duration<double>(d).count();
  std::ostringstream out;
  if (s == std::floor(s)) {
    out << static_cast<long long>(s) << " s";
  } else {
    out.precision(3);
    out << std::fixed << s << " s";
  }
  return out.str();
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

// What moves time: everything in a run goes through the driver's executor
// and transport context; only the loop that runs tasks differs.
class Driver {
 public:
  virtual ~Driver() = default;
  virtual link::Executor& executor() = 0;
  virtual link::TransportContext& context() = 0;
  virtual bool real_time() const = 0;
  /// Runs tasks until `done` or until the clock reaches `deadline` (the
  /// clock then stands there). Returns an error when the run stopped
  /// making progress.
  virtual std::optional<std::string> drive(const std::function<bool()>& done, Time deadline) = 0;
};

// The virtual-time driver: runs the executor task by task; time jumps to
// the next task.
class VirtualDriver final : public Driver {
 public:
  link::Executor& executor() override { return executor_; }
  link::TransportContext& context() override { return context_; }
  bool real_time() const override { return false; }
  std::optional<std::string> drive(const std::function<bool()>& done, Time deadline) override {
    while (!done()) {
      const auto next = executor_.next_due();
      if (!next || *next > deadline) {
        executor_.run_until(deadline);
        return std::nullopt;
      }
      executor_.run_one();
      // Something that reschedules itself at the same instant forever would
      // hang the run; no scenario needs this many tasks.
      if (++tasks_run_ > kMaxTasks)
        return "the run stopped making progress at " + link::format_ms(executor_.now()) +
               " (more than " + std::to_string(kMaxTasks) + " tasks)";
    }
    return std::nullopt;
  }

 private:
  link::VirtualExecutor executor_;
  link::TransportContext context_{executor_};
  std::uint64_t tasks_run_ = 0;
};

// The real-time driver: an io_context with real sockets and ptys; the
// clock is the steady clock.
class RealTimeDriver final : public Driver {
 public:
  link::Executor& executor() override { return executor_; }
  link::TransportContext& context() override { return context_; }
  bool real_time() const override { return true; }
  std::optional<std::string> drive(const std::function<bool()>& done, Time deadline) override {
    while (!done()) {
      const Time now = executor_.now();
      if (now >= deadline) return std::nullopt;
      const auto slice = std::min<Duration>(deadline - now, kRealTimeSlice);
      if (io_.run_one_for(slice) == 0) {
        // Nothing to wait on at all: the io_context stopped; let the time pass.
        if (io_.stopped()) io_.restart();
        if (executor_.pending() == 0) std::this_thread::sleep_for(slice);
      }
    }
    return std::nullopt;
  }

 private:
  asio::io_context io_;
  link::AsioExecutor executor_{io_};
  link::TransportContext context_{executor_, &io_};
};

// One run of one scenario, under either driver, with the reference client
// or an external program.
class ReferenceRun {
 public:
  ReferenceRun(const Scenario& scenario, const RunOptions& options, std::uint64_t seed,
               ScenarioOutcome& out, std::unique_ptr<Driver> driver)
      : scenario_(scenario),
        options_(options),
        seed_(seed),
        out_(out),
        driver_(std::move(driver)),
        executor_(driver_->executor()),
        context_(driver_->context()),
        timeline_(executor_),
        recorder_(options.sample_period) {}

  ~ReferenceRun() {
    *alive_ = false;
    client_.reset();
    server_.reset();
    if (!temp_dir_.empty()) {
      std::error_code ignored;
      std::filesystem::remove_all(temp_dir_, ignored);
    }
  }

  void run();

 private:
  struct Sequence {
    std::vector<std::size_t> order;
    std::size_t next = 0;
    bool stop_on_failure = true;
    bool done = false;
  };
  struct Running {
    std::function<void(bool ok)> then;
    link::Executor::TimerId timer = 0;
    RunTimeline::ListenerId listener = 0;
  };

  bool build();
  std::optional<link::Endpoint> listen_endpoint();
  bool make_client(const link::Endpoint& endpoint);
  void stop_external_client();
  void plan();
  void start_schedule();
  void advance(Sequence& seq);
  void skip_rest(Sequence& seq, const std::string& reason);
  void begin_step(std::size_t index, std::function<void(bool ok)> then);
  /// `cut_short`: the run ended the step (a timeout), so a step expected to
  /// fail does not pass by it.
  void finish_step(std::size_t index, bool ok, std::string reason, bool cut_short = false);
  void finish_later(std::size_t index, bool ok, std::string reason);
  void begin_wait_until(std::size_t index, const WaitUntilStep& wait);
  void obstacle(std::size_t index, const ObstacleStep& step);
  void pump_actions();
  void time_out(Sequence& seq, const std::string& reason);
  void sim_tick();
  void drive(const std::function<bool()>& done, Time deadline);
  void post(std::function<void()> f);
  void end();

  const Scenario& scenario_;
  const RunOptions& options_;
  std::uint64_t seed_;
  ScenarioOutcome& out_;

  // Destroyed last to first: the driver's executor outlives everything
  // that schedules on it, the timeline everything that writes to it.
  std::unique_ptr<Driver> driver_;
  link::Executor& executor_;
  link::TransportContext& context_;
  RunTimeline timeline_;
  std::unique_ptr<mocks::MockCar> car_;
  std::shared_ptr<WireRecorder> wire_;
  std::unique_ptr<mocks::MockServer> server_;
  std::unique_ptr<ReferenceSession> client_;
  sim::TrajectoryRecorder recorder_;

  std::vector<const Step*> plan_;  // parallel to out_.steps
  std::size_t schedule_base_ = 0;  // out_.steps index of the first scheduled step
  Sequence main_;
  Sequence teardown_;
  std::map<std::size_t, Running> running_;
  std::deque<std::size_t> actions_;
  std::size_t actions_under_way_ = 0;
  std::multimap<std::string, std::size_t> obstacles_;  // name -> arena obstacle index
  bool ended_ = false;
  bool stuck_ = false;
  bool external_ = false;
  bool steps_over_ = false;         // no scheduled step starts any more
  std::filesystem::path temp_dir_;  // real time: the pty and the actions file

  link::Executor::TimerId sim_timer_ = 0;
  Time next_sample_{0};
  std::uint64_t rfid_reads_ = 0;
  bool moving_ = false;
  bool in_fault_ = false;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

void ReferenceRun::post(std::function<void()> f) {
  executor_.post([alive = std::weak_ptr<bool>(alive_), f = std::move(f)] {
    if (const auto a = alive.lock(); a && *a) f();
  });
}

bool ReferenceRun::build() {
  mocks::CarOptions car;
  car.kind = scenario_.car;
  car.seed = mocks::car_seed(seed_, 0);
  car.name = "car0";
  try {
    mocks::apply_profile(car.configs, scenario_.car, scenario_.profile);
    if (scenario_.reply_latency) car.configs.reply_latency = *scenario_.reply_latency;
    if (!scenario_.world.empty()) car.arena = sim::load_arena(world_path(scenario_));
    car_ = std::make_unique<mocks::MockCar>(std::move(car));
  } catch (const std::exception& e) {
    out_.error = std::string("the world cannot be built: ") + e.what();
    return false;
  }
  const auto listen = listen_endpoint();
  if (!listen) return false;
  mocks::ServerOptions server;
  server.listen = *listen;
  server.faults = scenario_.faults;
  server.seed = seed_;
  server.name = "car0";
  if (!options_.work_dir.empty()) {
    out_.wire_log = (std::filesystem::path(options_.work_dir) / "wire.ndjson").string();
    server.wire_log_path = out_.wire_log;
  }
  wire_ = std::make_shared<WireRecorder>(timeline_, car_->firmware().adapter());
  server.observers.push_back(wire_);
  server_ = std::make_unique<mocks::MockServer>(context_, car_->firmware(), std::move(server));
  try {
    server_->start();
  } catch (const std::exception& e) {
    out_.error = std::string("the car cannot listen: ") + e.what();
    return false;
  }
  // Under real time the listener chose the port; the client goes there.
  return make_client(driver_->real_time() ? link::parse_endpoint(server_->address()) : *listen);
}

std::optional<link::Endpoint> ReferenceRun::listen_endpoint() {
  if (!driver_->real_time()) {
    // A serial car's line keeps its baud in virtual time too: every byte
    // takes its 10 bits of line time, as on the pty.
    link::MemEndpoint mem{"car0"};
    const link::Endpoint e = mocks::default_endpoint(scenario_.car, 0);
    if (const auto* pty = std::get_if<link::PtyEndpoint>(&e)) mem.baud = pty->baud;
    return mem;
  }
  // A folder of this run's own for the pty and the actions file, so runs
  // in parallel never meet.
  std::string pattern = (std::filesystem::temp_directory_path() / "hil-run-XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr) {
    out_.error = "cannot make a temporary folder for the run: " + std::string(std::strerror(errno));
    return std::nullopt;
  }
  temp_dir_ = pattern;
  link::Endpoint e = mocks::default_endpoint(scenario_.car, 0);
  if (auto* tcp = std::get_if<link::TcpEndpoint>(&e)) {
    tcp->host = "127.0.0.1";
    tcp->port = 0;  // any free port
  } else if (auto* pty = std::get_if<link::PtyEndpoint>(&e)) {
    pty->path = (temp_dir_ / "car0").string();
  }
  return e;
}

bool ReferenceRun::make_client(const link::Endpoint& endpoint) {
  const auto* exec = std::get_if<ExecClient>(&scenario_.client);
  const std::string* command = options_.client_exec ? &*options_.client_exec
                               : exec               ? &exec->command
                                                    : nullptr;
  if (command == nullptr) {
    client_ = make_reference_session(scenario_.car, context_, endpoint, timeline_,
                                     std::holds_alternative<ReferenceClient>(scenario_.client)
                                         ? std::get<ReferenceClient>(scenario_.client).settings
                                         : nlohmann::json::object(),
                                     scenario_.profile);
    return true;
  }
  external_ = true;
  Placeholders values;
  values["endpoint"] = link::to_uri(endpoint);
  values["profile"] = std::string(
      protocol::find_car_profile(mocks::to_string(scenario_.car), scenario_.profile).name);
  if (const auto* tcp = std::get_if<link::TcpEndpoint>(&endpoint)) {
    values["host"] = tcp->host;
    values["port"] = std::to_string(tcp->port);
  } else if (const auto* pty = std::get_if<link::PtyEndpoint>(&endpoint)) {
    values["pty"] = pty->path;
  }
  values["scenario"] = scenario_.file.empty()
                           ? std::string()
                           : std::filesystem::absolute(scenario_.file).lexically_normal().string();
  const auto actions = temp_dir_ / "actions.txt";
  {
    std::ofstream file(actions);
    const auto write = [&file](const Step& step) {
      if (const auto* a = std::get_if<ActionStep>(&step.action)) file << a->text << '\n';
    };
    for (const auto* phase : {&scenario_.setup, &scenario_.steps, &scenario_.teardown})
      for (const auto& step : *phase)
        write(step);
    for (const auto& s : scenario_.schedule)
      write(s.step);
    if (!file) {
      out_.error = "cannot write the actions file " + actions.string();
      return false;
    }
  }
  values["actions"] = actions.string();
  ExecOptions o;
  try {
    o.command = substitute_placeholders(*command, values);
  } catch (const std::invalid_argument& e) {
    out_.error = "the client command '" + *command + "': " + e.what();
    return false;
  }
  o.environment = values;
  if (exec != nullptr) o.startup_timeout = exec->startup_timeout;
  if (options_.on_client_command) options_.on_client_command(o.command);
  client_ = make_exec_session(context_, std::move(o), timeline_);
  return true;
}

void ReferenceRun::plan() {
  const auto add = [this](const Step& step, const char* phase) {
    StepOutcome o;
    o.line = step.line;
    o.text = step.text;
    o.phase = phase;
    o.ran = false;
    o.ok = true;
    out_.steps.push_back(std::move(o));
    plan_.push_back(&step);
    return out_.steps.size() - 1;
  };
  for (const auto& s : scenario_.setup)
    main_.order.push_back(add(s, "setup"));
  for (const auto& s : scenario_.steps)
    main_.order.push_back(add(s, "steps"));
  for (const auto& s : scenario_.teardown)
    teardown_.order.push_back(add(s, "teardown"));
  teardown_.stop_on_failure = false;  // clean up as much as can be
  schedule_base_ = out_.steps.size();
  for (const auto& s : scenario_.schedule)
    add(s.step, "schedule");
}

void ReferenceRun::start_schedule() {
  for (std::size_t j = 0; j < scenario_.schedule.size(); ++j) {
    const std::size_t index = schedule_base_ + j;
    const Anchor& when = scenario_.schedule[j].when;
    const auto fire = [this, index] {
      if (!ended_ && !steps_over_) begin_step(index, [](bool) {});
    };
    if (!when.event) {
      executor_.call_at(Time(0) + when.offset, [alive = std::weak_ptr<bool>(alive_), fire] {
        if (const auto a = alive.lock(); a && *a) fire();
      });
      continue;
    }
    // The n-th matching record arms the step; a "last" occurrence cannot be
    // known while the run goes on, so it means the first.
    const int wanted = when.occurrence > 0 ? when.occurrence : 1;
    auto seen = std::make_shared<int>(0);
    auto id = std::make_shared<RunTimeline::ListenerId>(0);
    *id = timeline_.listen([this, when, wanted, seen, id, fire](const Record& r) {
      if (!matches(*when.event, r) || ++*seen < wanted) return;
      timeline_.unlisten(*id);
      executor_.call_at(r.at + when.offset, [alive = std::weak_ptr<bool>(alive_), fire] {
        if (const auto a = alive.lock(); a && *a) fire();
      });
    });
  }
}

void ReferenceRun::advance(Sequence& seq) {
  if (seq.done || ended_) return;
  if (seq.next >= seq.order.size()) {
    seq.done = true;
    return;
  }
  const std::size_t index = seq.order[seq.next++];
  begin_step(index, [this, &seq, index](bool ok) {
    if (seq.done) return;  // timed out meanwhile
    if (!ok && seq.stop_on_failure) {
      skip_rest(seq,
                "not run: the step on line " + std::to_string(out_.steps[index].line) + " failed");
      return;
    }
    post([this, &seq] { advance(seq); });
  });
}

void ReferenceRun::skip_rest(Sequence& seq, const std::string& reason) {
  for (; seq.next < seq.order.size(); ++seq.next) {
    StepOutcome& o = out_.steps[seq.order[seq.next]];
    o.ran = false;
    o.ok = false;
    o.reason = reason;
  }
  seq.done = true;
}

void ReferenceRun::begin_step(std::size_t index, std::function<void(bool ok)> then) {
  const Step& step = *plan_[index];
  StepOutcome& o = out_.steps[index];
  o.ran = true;
  o.started = executor_.now();
  running_[index].then = std::move(then);
  timeline_.add(Source::step, "start",
                {{"index", index}, {"line", step.line}, {"text", step.text}, {"phase", o.phase}});
  std::visit(protocol::Overloaded{
                 [&](const ActionStep&) {
                   actions_.push_back(index);
                   pump_actions();
                 },
                 [&](const WaitStep& w) {
                   running_[index].timer = executor_.call_after(
                       w.duration, [this, index] { finish_step(index, true, ""); });
                 },
                 [&](const WaitUntilStep& w) { begin_wait_until(index, w); },
                 [&](const CarStep& c) {
                   timeline_.add(Source::car, "behaviour",
                                 {{"name", c.behaviour.name},
                                  {"action", std::string(mocks::action_name(c.behaviour.action))}});
                   car_->firmware().arm(c.behaviour);
                   finish_later(index, true, "");
                 },
                 [&](const FaultsStep& f) {
                   server_->set_faults(f.profile);
                   finish_later(index, true, "");
                 },
                 [&](const ObstacleStep& s) { obstacle(index, s); },
             },
             step.action);
}

void ReferenceRun::finish_later(std::size_t index, bool ok, std::string reason) {
  post([this, index, ok, reason = std::move(reason)] { finish_step(index, ok, reason); });
}

void ReferenceRun::finish_step(std::size_t index, bool ok, std::string reason, bool cut_short) {
  const auto it = running_.find(index);
  if (it == running_.end()) return;  // already ended (a timeout)
  if (const Step& step = *plan_[index]; step.expect_failure && !cut_short) {
    if (ok) {
      reason = "expected to fail, but it succeeded";
    } else if (!step.failure_contains.empty() &&
               reason.find(step.failure_contains) == std::string::npos) {
      reason = "failed, but not with '" + step.failure_contains + "': " + reason;
    } else {
      reason = "failed as expected: " + reason;
    }
    ok = !ok && reason.starts_with("failed as expected");
  }
  Running r = std::move(it->second);
  running_.erase(it);
  if (r.timer != 0) executor_.cancel(r.timer);
  if (r.listener != 0) timeline_.unlisten(r.listener);
  StepOutcome& o = out_.steps[index];
  o.ok = ok;
  o.reason = std::move(reason);
  o.ended = executor_.now();
  timeline_.add(Source::step, "end",
                {{"index", index},
                 {"line", o.line},
                 {"text", o.text},
                 {"phase", o.phase},
                 {"ok", ok},
                 {"reason", o.reason}});
  if (r.then) r.then(ok);
}

void ReferenceRun::begin_wait_until(std::size_t index, const WaitUntilStep& wait) {
  const Time started = executor_.now();
  // A match at this very moment, recorded just before the step began, counts.
  const auto& records = timeline_.timeline().records();
  for (auto it = records.rbegin(); it != records.rend() && it->at >= started; ++it) {
    if (it->source == Source::step && it->kind == "start") continue;
    if (matches(wait.until, *it)) {
      finish_later(index, true, "");
      return;
    }
  }
  Running& r = running_[index];
  r.listener = timeline_.listen([this, index, matcher = wait.until](const Record& rec) {
    if (!matches(matcher, rec)) return;
    const auto it = running_.find(index);
    if (it == running_.end() || it->second.listener == 0) return;
    timeline_.unlisten(it->second.listener);
    it->second.listener = 0;
    finish_later(index, true, "");
  });
  const std::string what = wait.until.text.empty() ? plan_[index]->text : wait.until.text;
  r.timer = executor_.call_after(wait.timeout, [this, index, what, timeout = wait.timeout] {
    finish_step(index, false, "no '" + what + "' within " + run_seconds_text(timeout));
  });
}

void ReferenceRun::obstacle(std::size_t index, const ObstacleStep& step) {
  sim::World& world = car_->world();
  if (!step.add) {
    std::size_t lifted = 0;
    const auto [from, to] = obstacles_.equal_range(step.name);
    for (auto it = from; it != to; ++it)
      if (world.remove_obstacle(it->second)) ++lifted;
    obstacles_.erase(step.name);
    if (lifted == 0)
      finish_later(index, false, "no obstacle named '" + step.name + "' to take away");
    else
      finish_later(index, true, "");
    return;
  }
  world.advance_to(executor_.now());
  sim::Vehicle& vehicle = car_->vehicle();
  const auto footprint = vehicle.chassis().footprint();
  constexpr double kDepthM = 0.10;  // a parcel: 10 cm deep, 30 cm wide
  constexpr double kWidthM = 0.30;
  const double front_m = footprint.center_ahead_m + footprint.length_m / 2;
  const auto center = vehicle.pose().to_arena({front_m + step.ahead_m + kDepthM / 2, 0});
  try {
    obstacles_.emplace(step.name,
                       world.add_obstacle(sim::BoxObstacle{step.name, center, kDepthM, kWidthM,
                                                           vehicle.pose().heading_rad}));
    finish_later(index, true, "");
  } catch (const std::exception& e) {
    finish_later(index, false, e.what());
  }
}

// A client that takes actions side by side gets each at once (a scheduled
// emergency stop beside the sequence's action); others one at a time.
void ReferenceRun::pump_actions() {
  while (!actions_.empty() && !ended_ && (actions_under_way_ == 0 || client_->concurrent())) {
    const std::size_t index = actions_.front();
    actions_.pop_front();
    ++actions_under_way_;
    const std::string text = std::get<ActionStep>(plan_[index]->action).text;
    client_->execute(text, [this, index, text](bool ok, const std::string& reason) {
      --actions_under_way_;
      timeline_.add(Source::client, "action",
                    {{"index", index}, {"text", text}, {"ok", ok}, {"reason", reason}});
      finish_step(index, ok, reason);
      pump_actions();
    });
  }
}

void ReferenceRun::time_out(Sequence& seq, const std::string& reason) {
  skip_rest(seq, reason);
  client_->cancel();
  actions_under_way_ = 0;
  actions_.clear();
  std::vector<std::size_t> under_way;
  for (const auto& [index, r] : running_)
    under_way.push_back(index);
  for (const auto index : under_way)
    finish_step(index, false, reason, true);
}

void ReferenceRun::sim_tick() {
  sim_timer_ = 0;
  if (ended_) return;
  const Time now = executor_.now();
  sim::World& world = car_->world();
  world.advance_to(now);
  sim::Vehicle& vehicle = car_->vehicle();
  for (const auto& c : recorder_.observe(world)) {
    if (c.vehicle != vehicle.index() || c.phase != sim::ContactEvent::Phase::begin) continue;
    static constexpr const char* kWith[] = {"wall", "obstacle", "vehicle"};
    const std::string with =
        c.other_name.empty() ? std::string(kWith[static_cast<int>(c.with)]) : c.other_name;
    timeline_.add(Source::sim, "collision", {{"with", with}});
  }
  if (vehicle.rfid_reads() != rfid_reads_) {
    rfid_reads_ = vehicle.rfid_reads();
    if (const auto tag = vehicle.rfid()) {
      nlohmann::json data{{"tag", *tag}};
      // "002" is station 2, so `station: 2` matches; other tags by name.
      if (!tag->empty() && tag->find_first_not_of("0123456789") == std::string::npos)
        data["station"] = std::stoi(*tag);
      else
        data["station"] = *tag;
      timeline_.add(Source::sim, "station", std::move(data));
    }
  }
  const sim::Twist v = vehicle.velocity();
  const double speed = std::hypot(v.vx_mps, v.vy_mps);
  if (!moving_ && (speed >= kMovingMps || std::abs(v.wz_radps) >= kMovingRadps)) {
    moving_ = true;
    timeline_.add(Source::sim, "moving");
  } else if (moving_ && speed < kMovingMps / 2 && std::abs(v.wz_radps) < kMovingRadps / 2) {
    moving_ = false;
    timeline_.add(Source::sim, "at_rest");
  }
  if (car_->firmware().in_fault() != in_fault_) {
    in_fault_ = car_->firmware().in_fault();
    timeline_.add(Source::car, "fault_state", {{"on", in_fault_}});
  }
  client_->poll();
  if (now >= next_sample_) {
    const sim::Pose pose = vehicle.pose();
    timeline_.add(Source::sim, "sample",
                  {{"x_m", sim::round_to(pose.x_m, 1e-4)},
                   {"y_m", sim::round_to(pose.y_m, 1e-4)},
                   {"heading_deg", sim::round_to(pose.heading_rad * 180 / std::numbers::pi, 0.01)},
                   {"speed_mps", sim::round_to(speed, 1e-4)}});
    while (next_sample_ <= now)
      next_sample_ += options_.sample_period;
  }
  const Time next = std::min(now + kSimTick, next_sample_);
  sim_timer_ = executor_.call_at(next, [alive = std::weak_ptr<bool>(alive_), this] {
    if (const auto a = alive.lock(); a && *a) sim_tick();
  });
}

void ReferenceRun::drive(const std::function<bool()>& done, Time deadline) {
  if (stuck_) return;
  if (auto error = driver_->drive(done, deadline)) {
    stuck_ = true;
    out_.error = *error;
  }
}

// An external program's shutdown is part of the run: it should stop the
// car and hang up once its input closes (docs/client-contract.md).
void ReferenceRun::stop_external_client() {
  const auto finished = [this] { return client_->finished(); };
  client_->stop();
  drive(finished, executor_.now() + kExitGrace);
  if (finished()) return;
  timeline_.add(Source::client, "notice",
                {{"text", "the client did not exit within " + run_seconds_text(kExitGrace) +
                              " of its input closing: sent SIGTERM"}});
  client_->terminate(false);
  drive(finished, executor_.now() + kTermGrace);
  if (finished()) return;
  timeline_.add(Source::client, "notice",
                {{"text", "the client ignored SIGTERM for " + run_seconds_text(kTermGrace) +
                              ": sent SIGKILL"}});
  client_->terminate(true);
  drive(finished, executor_.now() + kTermGrace);
}

void ReferenceRun::run() {
  if (!build()) return;
  plan();
  // The world starts at rest: that is the state the first transition leaves.
  timeline_.add(Source::sim, "at_rest");
  client_->start();
  sim_tick();
  start_schedule();
  post([this] { advance(main_); });

  drive([this] { return main_.done; }, Time(0) + scenario_.timeout);
  if (!main_.done) time_out(main_, "timed out after " + run_seconds_text(scenario_.timeout));

  post([this] { advance(teardown_); });
  drive([this] { return teardown_.done; }, executor_.now() + kTeardownGrace);
  if (!teardown_.done)
    time_out(teardown_, "teardown timed out after " + run_seconds_text(kTeardownGrace));

  drive([] { return false; }, executor_.now() + scenario_.settle);
  end();
}

void ReferenceRun::end() {
  steps_over_ = true;
  // Expectations judge the session up to here: an external program's
  // shutdown after its input closed (a last stop, the hang-up) is the
  // contract's business, judged by its exit.
  const Time session_end = executor_.now();
  if (external_) stop_external_client();
  ended_ = true;
  const Time run_end = executor_.now();
  // Scheduled steps still under way (a wait_until that never matched) end
  // with the run; those whose moment never came stay "not run".
  std::vector<std::size_t> under_way;
  for (const auto& [index, r] : running_)
    under_way.push_back(index);
  for (const auto index : under_way)
    finish_step(index, false, "still under way when the run ended", true);
  for (std::size_t i = schedule_base_; i < out_.steps.size(); ++i) {
    if (!out_.steps[i].ran) out_.steps[i].reason = "not run: its moment never came";
  }
  timeline_.close();
  if (sim_timer_ != 0) executor_.cancel(sim_timer_);
  if (!external_) client_->stop();
  server_->close();
  // What the closes cause, outside the timeline (a moment of real time for
  // sockets to finish closing).
  drive([] { return false; }, driver_->real_time() ? run_end + milliseconds(20) : run_end);

  out_.timeline = timeline_.take();
  out_.arena = car_->world().arena();
  out_.trajectories = recorder_.trajectories();
  out_.run_time = run_end;
  auto expectations = scenario_.expectations;
  const auto on_exit = [](const Expectation& e) {
    return e.what.source == Source::client && e.what.kind == "exit";
  };
  if (external_) {
    // Unless the scenario says what the exit should be, a clean one.
    const bool said = std::any_of(expectations.begin(), expectations.end(), on_exit);
    if (!said) {
      Expectation exit;
      exit.label = "the client exited with code 0 after its input closed";
      exit.window.from.offset = session_end - Time(0);
      exit.window.within = run_end - session_end;
      exit.what = Matcher{
          Source::client, "exit", {FieldTest{"code", FieldTest::Op::equals, 0}}, "client exit 0"};
      expectations.push_back(std::move(exit));
    }
  }
  const Duration slack = options_.time_slack    ? *options_.time_slack
                         : driver_->real_time() ? kRealTimeSlack
                                                : Duration(0);
  // An expectation on the exit looks past the session's end, where the exit is.
  for (const auto& e : expectations)
    out_.expectations.push_back(check(e, out_.timeline, on_exit(e) ? run_end : session_end, slack));
}

}  // namespace

ScenarioOutcome run_scenario(const Scenario& scenario, const RunOptions& options) {
  const auto wall_start = std::chrono::steady_clock::now();
  ScenarioOutcome out;
  out.file = scenario.file;
  out.name = scenario.name;
  out.tags = scenario.tags;
  out.seed = options.seed    ? *options.seed
             : scenario.seed ? *scenario.seed
                             : (static_cast<std::uint64_t>(std::random_device{}()) << 32) |
                                   std::random_device{}();
  out.repro_command = "hil run " + (scenario.file.empty() ? scenario.name : scenario.file) +
                      " --seed " + std::to_string(out.seed);

  const bool exec = options.client_exec || std::holds_alternative<ExecClient>(scenario.client);
  out.real_time = exec || std::get<ReferenceClient>(scenario.client).real_time;
  // A program that closes its stdin early must not end hil with SIGPIPE;
  // the write fails with EPIPE instead.
  if (exec) std::signal(SIGPIPE, SIG_IGN);
  std::unique_ptr<Driver> driver;
  if (out.real_time)
    driver = std::make_unique<RealTimeDriver>();
  else
    driver = std::make_unique<VirtualDriver>();
  {
    ReferenceRun run(scenario, options, out.seed, out, std::move(driver));
    run.run();
  }
  out.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return out;
}

}  // namespace hil::harness
