// Mock cars in virtual time: how many times faster than real time each of the
// four mock cars serves a realistic client session under the virtual-time
// driver (link::VirtualExecutor, mem:// endpoints), as a scenario or a
// property test runs it. Besides Google Benchmark's own flags:
//   --hil_markdown=FILE     writes the results as a Markdown table;
//   --hil_min_realtime=X    exit 1 unless every car that ran did so at least
//                           X times faster than real time.
// Each iteration is one whole session from scratch: a fresh world, car,
// MockServer on mem:// and client, then 60 s of virtual time. Rates are from
// the benchmark thread's CPU time (as Google Benchmark's own
// items_per_second), so time spent waiting for a core on a busy machine does
// not count; with --benchmark_repetitions the best repetition counts.
//
// Every client writes what a user's program would and decodes every byte the
// car sends. A session that does not get done what it set out to do (too few
// arrivals, drives, moves or info lines), or whose car touched anything,
// fails the benchmark instead of timing a car that was stuck.

#include <benchmark/benchmark.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "bench/best_runs.hpp"
#include "bench/hil_flags.hpp"
#include "link/faults/profile.hpp"
#include "link/transport.hpp"
#include "mocks/car.hpp"
#include "mocks/server.hpp"
#include "protocol/arduino/codec.hpp"
#include "protocol/leka/codec.hpp"
#include "protocol/logi/codec.hpp"
#include "protocol/wr8/codec.hpp"

namespace {

namespace link = hil::link;
namespace mocks = hil::mocks;
namespace logi = hil::protocol::logi;
namespace wr8 = hil::protocol::wr8;
namespace arduino = hil::protocol::arduino;
namespace leka = hil::protocol::leka;

using hil::protocol::Bytes;
using hil::protocol::ByteView;
using link::Duration;
using link::milliseconds;
using link::seconds;
using link::Time;
using mocks::CarKind;

constexpr Duration kSession = seconds(60);
constexpr double kSessionSeconds = 60.0;

std::string too_few(const std::string& what, std::uint64_t got, std::uint64_t wanted) {
  return what + ": " + std::to_string(got) + " in 60 s, expected at least " +
         std::to_string(wanted);
}

// ---- the client end of a session ----

// A client program's side of the connection: it writes commands and reads
// everything the car sends. Its timers run on the session's executor, which
// outlives it.
class Client {
 public:
  explicit Client(link::Executor& executor) : executor_(executor) {}
  virtual ~Client() = default;
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  void attach(link::BytePipePtr pipe) {
    pipe_ = std::move(pipe);
    pipe_->start({[this](ByteView bytes) { on_bytes(bytes); }, [](std::error_code) {}});
    on_connect();
  }

  /// Empty when the session got done what the client set out to do;
  /// otherwise what fell short.
  virtual std::string shortfall() const = 0;

 protected:
  virtual void on_connect() = 0;
  virtual void on_bytes(ByteView bytes) = 0;

  void write(const Bytes& bytes) { pipe_->write(bytes); }

  link::Executor& executor_;

 private:
  link::BytePipePtr pipe_;
};

// LOGI: SP:080, GS:002 and ST:RUN, each sent when the previous one's FB came;
// on arrival (a STAT with RUN:0 on the target after the run started) GS to
// the other station and ST:RUN again. A command whose FB has not come a
// second later (corrupted on the way there or back) is sent again.
class LogiClient final : public Client {
 public:
  using Client::Client;

  std::string shortfall() const override {
    // At SP 80 a run from one station to the other takes 11 to 13 s, so
    // 60 s hold five.
    if (refused_ > 0) return "LOGI: " + std::to_string(refused_) + " command(s) refused";
    if (arrivals_ < 3) return too_few("LOGI arrivals", arrivals_, 3);
    if (stat_frames_ < 100) return too_few("LOGI STAT frames read", stat_frames_, 100);
    return {};
  }

 private:
  void on_connect() override { send(logi::SetSpeed{80}); }

  void on_bytes(ByteView bytes) override {
    items_.clear();
    decoder_.feed(bytes, items_);
    for (const auto& item : items_) {
      const auto* frame = std::get_if<hil::protocol::Frame<logi::Message>>(&item);
      if (frame == nullptr) continue;  // a corrupted frame: the client drops it
      if (const auto* fb = std::get_if<logi::Feedback>(&frame->message)) {
        on_feedback(*fb);
      } else if (const auto* stat = std::get_if<logi::Status>(&frame->message)) {
        on_status(*stat);
      }
    }
  }

  void on_feedback(const logi::Feedback& fb) {
    if (!in_flight_ || logi::command_of(*in_flight_) != fb.command) return;
    const logi::Message answered = *in_flight_;
    in_flight_.reset();
    if (!fb.accepted) {
      ++refused_;  // nothing in this session should be: the session stops here
      return;
    }
    if (std::holds_alternative<logi::SetSpeed>(answered)) {
      send(logi::SetStation{target_});
    } else if (std::holds_alternative<logi::SetStation>(answered)) {
      send(logi::SetRun{true});
    } else if (std::holds_alternative<logi::SetRun>(answered)) {
      run_started_ = true;
    }
  }

  void on_status(const logi::Status& stat) {
    ++stat_frames_;
    if (!run_started_) return;
    if (stat.running) {
      seen_running_ = true;
      return;
    }
    if (!seen_running_) return;
    run_started_ = false;
    seen_running_ = false;
    if (stat.station == target_) {
      ++arrivals_;
      target_ = target_ == 2 ? 1 : 2;
      send(logi::SetStation{target_});
    } else {
      send(logi::SetRun{true});  // lost the tape: carry on to the same station
    }
  }

  void send(const logi::Message& message) {
    in_flight_ = message;
    write(logi::encode(message));
    if (retry_ != 0) executor_.cancel(retry_);
    const std::uint64_t sent = ++sent_;
    retry_ = executor_.call_after(seconds(1), [this, sent] {
      retry_ = 0;
      if (in_flight_ && sent == sent_) send(*in_flight_);
    });
  }

  logi::Decoder decoder_;
  std::vector<logi::Item> items_;
  std::optional<logi::Message> in_flight_;
  std::uint64_t sent_ = 0;
  link::Executor::TimerId retry_ = 0;
  int target_ = 2;
  bool run_started_ = false;
  bool seen_running_ = false;
  std::uint64_t arrivals_ = 0;
  std::uint64_t stat_frames_ = 0;
  std::uint64_t refused_ = 0;
};

// WR8: AUTH, then 100 cm drive tasks back to back with a turn of the wheels
// before each. The four angles repeat: each four drives turn the car half
// way round the shelf, ending where the start pose, turned 180 degrees
// about the shelf's centre, would be, so the route closes every eight
// drives and stays about 30 cm from the walls, the shelf and the pillar.
class Wr8Client final : public Client {
 public:
  using Client::Client;

  std::string shortfall() const override {
    // A 100 cm drive takes 3.33 s: 60 s hold 17 drives and their turns.
    if (!logged_in_) return "WR8: no AUTH-REPLY";
    if (errors_ > 0) return "WR8: " + std::to_string(errors_) + " task(s) answered error";
    if (drives_ < 15) return too_few("WR8 drives completed", drives_, 15);
    if (data_ < 550) return too_few("WR8 DATA packets read", data_, 550);
    return {};
  }

 private:
  static constexpr std::array<int, 4> kTurns_deg = {-3, 16, 9, 23};

  void on_connect() override { write(wr8::encode(wr8::Auth{wr8::default_profile().auth_text})); }

  void on_bytes(ByteView bytes) override {
    items_.clear();
    decoder_.feed(bytes, items_);
    for (const auto& item : items_) {
      const auto* frame = std::get_if<hil::protocol::Frame<wr8::Message>>(&item);
      if (frame == nullptr) continue;
      if (std::holds_alternative<wr8::Data>(frame->message)) {
        ++data_;
      } else if (std::holds_alternative<wr8::AuthReply>(frame->message)) {
        if (!logged_in_) next_task();
        logged_in_ = true;
      } else if (const auto* response = std::get_if<wr8::Response>(&frame->message)) {
        if (response->coi != coi_ || response->code == wr8::ResponseCode::started) continue;
        if (response->code == wr8::ResponseCode::error) ++errors_;
        if (response->code == wr8::ResponseCode::completed && driving_) ++drives_;
        next_task();
      }
    }
  }

  void next_task() {
    ++coi_;
    driving_ = !driving_;
    wr8::Task task{coi_, wr8::TaskCode::drive, {wr8::Word::from_i32(100)}};
    if (!driving_) {
      task.task = wr8::TaskCode::turn;
      task.params = {wr8::Word::from_i32(kTurns_deg[turns_++ % kTurns_deg.size()])};
    }
    write(wr8::encode(task));
  }

  static wr8::DecoderOptions vehicle_side() {
    wr8::DecoderOptions options;
    options.sender = wr8::Sender::vehicle;
    return options;
  }

  wr8::Decoder decoder_{vehicle_side()};
  std::vector<wr8::Item> items_;
  std::uint8_t coi_ = 0;
  bool driving_ = true;  // the first task is a turn
  bool logged_in_ = false;
  std::size_t turns_ = 0;
  std::uint64_t drives_ = 0;
  std::uint64_t errors_ = 0;
  std::uint64_t data_ = 0;
};

// Arduino: one request at a time, each sent when the last one's answer came.
// V once, then a cycle of moves with a sonar (B) and IR (I) read before each;
// STATUS is polled every 200 ms, and once it reads IDLE the client lets the
// robot come to rest before the next reads and move. The cycle ends where
// it began (forward, left, out and back, right, back), so the robot's small
// turn and distance errors cancel instead of walking it into a wall over a
// minute.
class ArduinoClient final : public Client {
 public:
  using Client::Client;

  std::string shortfall() const override {
    if (nacks_ > 0) return "Arduino: " + std::to_string(nacks_) + " request(s) answered NACK";
    // A cycle of six moves takes 6.4 s: 60 s hold over 50 moves.
    if (moves_ < 45) return too_few("Arduino moves finished", moves_, 45);
    if (statuses_ < 250) return too_few("Arduino STATUS answers read", statuses_, 250);
    return {};
  }

 private:
  static constexpr std::array<arduino::Body, 6> kCycle = {arduino::Move{40},   arduino::Rotate{-90},
                                                          arduino::Move{30},   arduino::Move{-30},
                                                          arduino::Rotate{90}, arduino::Move{-40}};

  void on_connect() override {
    queue_.push_back(arduino::SetSpeed{140});  // the speed the robot's timing is calibrated at
    queue_move();
    send_next();
    poll();
  }

  void poll() {
    executor_.call_after(milliseconds(200), [this] {
      queue_.push_back(arduino::StatusRequest{});
      send_next();
      poll();
    });
  }

  void queue_move() {
    queue_.push_back(arduino::SonarRead{});
    queue_.push_back(arduino::IrRead{});
    queue_.push_back(kCycle[next_move_++ % kCycle.size()]);
  }

  void send_next() {
    if (in_flight_ || queue_.empty()) return;
    in_flight_ = queue_.front();
    queue_.pop_front();
    // The real client's frames, for the real sketch (the default profile).
    const arduino::Message request{++seq_, *in_flight_};
    write(hil::protocol::to_bytes(arduino::encode_text(request, arduino::kDefaultDialect)));
  }

  void on_bytes(ByteView bytes) override {
    items_.clear();
    decoder_.feed(bytes, items_);
    for (const auto& item : items_) {
      const auto* frame = std::get_if<hil::protocol::Frame<arduino::Message>>(&item);
      if (frame == nullptr || frame->message.seq != seq_ || !in_flight_) continue;
      const arduino::Body request = *in_flight_;
      in_flight_.reset();
      if (std::holds_alternative<arduino::Nack>(frame->message.body)) {
        ++nacks_;
      } else if (const auto* ack = std::get_if<arduino::Ack>(&frame->message.body)) {
        if (std::holds_alternative<arduino::Move>(request) ||
            std::holds_alternative<arduino::Rotate>(request)) {
          moving_ = true;
        } else if (std::holds_alternative<arduino::StatusRequest>(request)) {
          ++statuses_;
          if (moving_ && ack->info.ends_with("MOT:IDLE")) {
            moving_ = false;
            ++moves_;
            // The robot coasts for up to 0.3 s after its motors stop; a
            // move started meanwhile would add to that motion.
            executor_.call_after(milliseconds(300), [this] {
              queue_move();
              send_next();
            });
          }
        }
      }
      send_next();
    }
  }

  arduino::Decoder decoder_;
  std::vector<arduino::Item> items_;
  std::deque<arduino::Body> queue_;
  std::optional<arduino::Body> in_flight_;
  std::uint8_t seq_ = 0;
  std::size_t next_move_ = 0;
  bool moving_ = false;
  std::uint64_t moves_ = 0;
  std::uint64_t statuses_ = 0;
  std::uint64_t nacks_ = 0;
};

// Leka: what a phone app sends while it drives the robot: every 100 ms a
// command group with the motors (a gentle left curve, a circle of about
// 0.2 m radius in the free floor by the start pose), the ears and one belt
// LED running round; every second an info request. The robot answers only
// info, with a text line.
class LekaClient final : public Client {
 public:
  using Client::Client;

  std::string shortfall() const override {
    if (info_lines_ < 59) return too_few("Leka info lines read", info_lines_, 59);
    return {};
  }

 private:
  void on_connect() override { tick(); }

  void tick() {
    const std::uint8_t step = static_cast<std::uint8_t>(ticks_ % 20);
    const std::uint8_t shade = ticks_ / 10 % 2 == 0 ? 255 : 64;  // the ears pulse each second
    write(leka::encode(
        leka::CommandGroup{{leka::MotorDuo{leka::kSpinForward, 50, leka::kSpinForward, 120},
                            leka::EarAll{{shade, 0, 255}}, leka::BeltAll{{0, 0, 0}},
                            leka::BeltSingle{step, {0, 255, 0}}}}));
    if (ticks_ % 10 == 0) write(leka::encode(leka::CommandGroup{{leka::Info{}}}));
    ++ticks_;
    executor_.call_after(milliseconds(100), [this] { tick(); });
  }

  void on_bytes(ByteView bytes) override {
    for (const auto byte : bytes) {
      line_.push_back(static_cast<char>(byte));
      if (byte != '\n') continue;
      if (line_.starts_with("LEKA ") && line_.ends_with("\r\n")) ++info_lines_;
      line_.clear();
    }
  }

  std::uint64_t ticks_ = 0;
  std::string line_;
  std::uint64_t info_lines_ = 0;
};

// ---- one session ----

// Fragmentation, coalescing ("sticky packets") and 1 % corrupted checksums,
// both directions: what a flaky Wi-Fi link and a busy TCP stack do to LOGI.
link::FaultProfile flaky_link() {
  link::FaultProfile profile;
  link::FaultRule fragment;
  fragment.name = "fragment";
  fragment.trigger.probability = 0.5;
  fragment.action = link::Fragment{{1, 8}, {Duration{0}, milliseconds(2)}};
  link::FaultRule coalesce;
  coalesce.name = "coalesce";
  coalesce.trigger.probability = 0.2;
  coalesce.action = link::Coalesce{3, milliseconds(50)};
  link::FaultRule corrupt;
  corrupt.name = "corrupt";
  corrupt.trigger.probability = 0.01;
  corrupt.action = link::Corrupt{link::CorruptTarget::checksum, {}, 1};
  profile.rules = {fragment, coalesce, corrupt};
  link::validate(profile);
  return profile;
}

std::unique_ptr<Client> make_client(CarKind kind, link::Executor& executor) {
  switch (kind) {
    case CarKind::logi:
      return std::make_unique<LogiClient>(executor);
    case CarKind::wr8:
      return std::make_unique<Wr8Client>(executor);
    case CarKind::arduino:
      return std::make_unique<ArduinoClient>(executor);
    case CarKind::leka:
      return std::make_unique<LekaClient>(executor);
  }
  return nullptr;
}

struct SessionResult {
  mocks::FirmwareStats car;
  std::uint64_t faults = 0;
  std::string problem;  ///< empty when the session went as it should
};

SessionResult run_session(CarKind kind, bool faults) {
  link::VirtualExecutor executor;  // first: everything below schedules on it
  link::TransportContext context{executor};
  mocks::CarOptions car_options;
  car_options.kind = kind;
  mocks::MockCar car(car_options);
  mocks::ServerOptions server_options;
  server_options.listen = link::MemEndpoint{"car"};
  server_options.seed = 1;
  if (faults) server_options.faults = flaky_link();
  mocks::MockServer server(context, car.firmware(), server_options);
  server.start();
  const std::unique_ptr<Client> client = make_client(kind, executor);
  link::connect(context, link::MemEndpoint{"car"},
                [&client](std::error_code ec, link::BytePipePtr pipe) {
                  if (!ec) client->attach(std::move(pipe));
                });
  executor.run_until(Time(kSession));

  SessionResult result;
  result.car = car.firmware().stats();
  result.faults = server.faults_injected();
  result.problem = client->shortfall();
  if (const auto contacts = car.world().take_contacts();
      result.problem.empty() && !contacts.empty()) {
    result.problem = "the car touched " + contacts.front().other_name +
                     ": the session's route is not in free space";
  }
  if (result.problem.empty() && !faults && result.car.bad_frames > 0)
    result.problem = "the car counted bad frames on a clean link";
  server.close();
  return result;
}

void session(benchmark::State& state, CarKind kind, bool faults) {
  double frames_in = 0;
  double frames_out = 0;
  double injected = 0;
  std::string problem;
  for (auto _ : state) {
    const SessionResult result = run_session(kind, faults);
    frames_in += static_cast<double>(result.car.frames_in);
    frames_out += static_cast<double>(result.car.frames_out);
    injected += static_cast<double>(result.faults);
    if (problem.empty()) problem = result.problem;
  }
  if (!problem.empty()) state.SkipWithError(problem.c_str());
  using benchmark::Counter;
  state.counters["x_real_time"] = Counter(kSessionSeconds, Counter::kIsIterationInvariantRate);
  state.counters["frames_in_per_s"] = Counter(frames_in, Counter::kIsRate);
  state.counters["frames_out_per_s"] = Counter(frames_out, Counter::kIsRate);
  state.counters["frames_in"] = Counter(frames_in, Counter::kAvgIterations);
  state.counters["frames_out"] = Counter(frames_out, Counter::kAvgIterations);
  if (faults) state.counters["faults"] = Counter(injected, Counter::kAvgIterations);
}

struct Case {
  const char* name;
  CarKind kind;
  bool faults;
  const char* what;  ///< for the table
};

constexpr std::array<Case, 5> kCases = {{
    {"logi", CarKind::logi, false, "LOGI"},
    {"wr8", CarKind::wr8, false, "WR8"},
    {"arduino", CarKind::arduino, false, "Arduino"},
    {"leka", CarKind::leka, false, "Leka"},
    {"logi_faults", CarKind::logi, true, "LOGI, flaky link"},
}};

void register_all() {
  for (const auto& c : kCases) {
    benchmark::RegisterBenchmark(c.name, [c](benchmark::State& state) {
      session(state, c.kind, c.faults);
    })->Unit(benchmark::kMillisecond);
  }
}

// ---- results ----

class RecordingReporter : public hil::bench::BestRunReporter {
 public:
  bool check(double min_realtime) const {
    bool ok = no_errors();
    if (min_realtime <= 0) return ok;
    for (const auto& c : kCases) {
      const double cpu_s = seconds(c.name);
      if (cpu_s <= 0) continue;  // filtered out
      ok = hil::bench::check_realtime_floor(std::string("mock car ") + c.name,
                                            kSessionSeconds / cpu_s, min_realtime) &&
           ok;
    }
    return ok;
  }

  void write_markdown(const std::string& path) const {
    std::ofstream out(path);
    out << "| car | x real time | ms CPU per 60 s session | frames in / out per session | "
           "frames in / out per CPU second |\n"
           "|---|---:|---:|---:|---:|\n";
    char line[256];
    const hil::bench::BestRun* slowest = nullptr;
    const char* slowest_name = "";
    for (const auto& c : kCases) {
      const hil::bench::BestRun* b = best(c.name);
      if (b == nullptr || b->seconds <= 0) continue;
      const double in = b->counter("frames_in");
      const double out_frames = b->counter("frames_out");
      std::snprintf(line, sizeof line, "| %s | %.0f | %.2f | %.0f / %.0f | %.0f / %.0f |\n", c.what,
                    kSessionSeconds / b->seconds, b->seconds * 1e3, in, out_frames, in / b->seconds,
                    out_frames / b->seconds);
      out << line;
      if (slowest == nullptr || b->seconds > slowest->seconds) {
        slowest = b;
        slowest_name = c.what;
      }
    }
    if (slowest == nullptr) return;
    std::snprintf(line, sizeof line, "\nSlowest: %s at %.0fx real time (target >= 1000x).",
                  slowest_name, kSessionSeconds / slowest->seconds);
    out << line;
    const hil::bench::BestRun* clean = best("logi");
    const hil::bench::BestRun* flaky = best("logi_faults");
    if (clean != nullptr && flaky != nullptr && clean->seconds > 0) {
      std::snprintf(line, sizeof line,
                    " The flaky link (%.0f faults injected per session) costs the LOGI session "
                    "%.0f %% more CPU time.",
                    flaky->counter("faults"), (flaky->seconds / clean->seconds - 1) * 100);
      out << line;
    }
    out << "\n";
  }
};

}  // namespace

int main(int argc, char** argv) {
  auto flags = hil::bench::take_hil_flags(argc, argv);
  register_all();
  RecordingReporter reporter;
  return hil::bench::run_and_check(flags, reporter,
                                   [&] { return reporter.check(flags.number("min_realtime")); });
}
