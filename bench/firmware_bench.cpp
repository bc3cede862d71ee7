// Real firmware on the emulated ATmega328P, in virtual time: how many
// seconds of the board's time one CPU second emulates. Besides Google
// Benchmark's own flags:
//   --hil_markdown=FILE     writes the results as a Markdown table;
//   --hil_min_realtime=X    exit 1 unless every case ran at least X times
//                           faster than real time.
// The firmware is hil's own test sketch (scenarios/firmware/hil_arduino),
// whose loop() polls its serial port as every Arduino sketch does. Cases:
//   chip           the chip alone running the sketch (simavr and hil's run
//                  loop, nothing else);
//   board_idle     the board in a world with a client on its port and
//                  nothing said: what a scenario pays while a client waits;
//   board_session  the same with a client that polls PING, STATUS, B and I
//                  every 100 ms and starts a move each second, decoding every
//                  answer (a session with too few answers fails instead of
//                  timing a stuck board).
// Rates are from CPU time; the best repetition counts.

#include <benchmark/benchmark.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>

#include "bench/best_runs.hpp"
#include "bench/hil_flags.hpp"
#include "link/transport.hpp"
#include "mocks/avr/avr_firmware.hpp"
#include "mocks/server.hpp"
#include "protocol/arduino/sketch.hpp"
#include "sim/presets.hpp"

namespace {

namespace link = hil::link;
namespace mocks = hil::mocks;
using link::Duration;
using link::milliseconds;
using link::seconds;

constexpr double kSeconds = 10.0;  // of the board's time per iteration

mocks::AvrConfig sketch() {
  mocks::AvrConfig config;
  config.elf = HIL_BENCH_SKETCH_ELF;
  return config;
}

void chip_alone(benchmark::State& state) {
  for (auto _ : state) {
    hil::mocks::avr::Chip chip(HIL_BENCH_SKETCH_ELF);
    chip.run_to(static_cast<std::uint64_t>(kSeconds * hil::mocks::avr::Chip::kFrequencyHz));
    benchmark::DoNotOptimize(chip.cycle());
  }
  state.counters["x_real_time"] =
      benchmark::Counter(kSeconds, benchmark::Counter::kIsIterationInvariantRate);
}

// A board in the built-in warehouse behind a MockServer on mem://, with a
// client on its port; `poll` says whether the client talks.
struct Bench {
  link::VirtualExecutor executor;
  link::TransportContext context{executor};
  hil::sim::World world{hil::sim::WorldDef{}};
  hil::sim::Vehicle& vehicle = world.add_vehicle(hil::sim::arduino_robot());
  mocks::AvrFirmware firmware{world, vehicle, sketch()};
  std::unique_ptr<mocks::MockServer> server;
  link::BytePipePtr pipe;
  std::string received;

  Bench() {
    mocks::ServerOptions options;
    options.listen = link::MemEndpoint{"board"};
    server = std::make_unique<mocks::MockServer>(context, firmware, std::move(options));
    server->start();
    link::connect(
        context, link::MemEndpoint{"board"}, [this](std::error_code ec, link::BytePipePtr p) {
          if (ec) return;
          pipe = p;
          pipe->start({[this](hil::protocol::ByteView b) { received.append(b.begin(), b.end()); },
                       [](std::error_code) {}});
        });
    executor.run_for(milliseconds(1));
  }
  ~Bench() { server->close(); }
};

void board(benchmark::State& state, bool poll) {
  std::size_t answers = 0;
  std::size_t wanted = 0;
  for (auto _ : state) {
    Bench bench;
    int seq = 0;
    const auto ask = [&](std::string_view cmd, std::string_view payload) {
      char s[3];
      std::snprintf(s, sizeof s, "%02X", ++seq & 0xFF);
      const std::string frame = hil::protocol::arduino::sketch_frame(s, cmd, payload);
      bench.pipe->write(hil::protocol::ByteView(reinterpret_cast<const std::uint8_t*>(frame.data()),
                                                frame.size()));
    };
    bench.executor.run_for(milliseconds(300));  // the reset and setup()
    std::size_t asked = 0;
    for (int tick = 0; tick < static_cast<int>(kSeconds * 10) - 3; ++tick) {
      if (poll) {
        static constexpr std::array<const char*, 4> kPolls{"PING", "STATUS", "B", "I"};
        ask(kPolls[static_cast<std::size_t>(tick) % kPolls.size()], " ");
        ++asked;
        if (tick % 10 == 5) {
          ask("M", tick % 20 == 5 ? "5" : "-5");
          ++asked;
        }
      }
      bench.executor.run_for(milliseconds(100));
    }
    std::size_t frames = 0;
    for (const char c : bench.received)
      frames += c == '$' ? 1 : 0;
    answers += frames;
    wanted += asked;
  }
  if (answers < wanted) state.SkipWithError("the board answered fewer requests than it was sent");
  state.counters["x_real_time"] =
      benchmark::Counter(kSeconds, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["answers"] =
      benchmark::Counter(static_cast<double>(answers), benchmark::Counter::kAvgIterations);
}

struct Case {
  const char* name;
  const char* what;
};
constexpr std::array<Case, 3> kCases{
    {{"chip", "the chip alone (simavr and hil's run loop)"},
     {"board_idle", "the board, a client connected, idle"},
     {"board_session", "the board, a client polling every 100 ms"}}};

class Reporter : public hil::bench::BestRunReporter {
 public:
  bool check(double floor) const {
    bool ok = no_errors();
    if (floor <= 0) return ok;
    for (const auto& c : kCases) {
      const double s = seconds(c.name);
      if (s > 0) ok = hil::bench::check_realtime_floor(c.name, kSeconds / s, floor) && ok;
    }
    return ok;
  }
  void write_markdown(const std::string& path) const {
    std::ofstream out(path);
    out << "| case | x real time | CPU s per 10 s of the board | answers per 10 s |\n"
           "|---|---:|---:|---:|\n";
    for (const auto& c : kCases) {
      const hil::bench::BestRun* b = best(c.name);
      if (b == nullptr || b->seconds <= 0) continue;
      char line[256];
      std::snprintf(line, sizeof line, "| %s | %.1f | %.3f | %.0f |\n", c.what,
                    kSeconds / b->seconds, b->seconds, b->counter("answers"));
      out << line;
    }
  }
};

}  // namespace

int main(int argc, char** argv) {
  auto flags = hil::bench::take_hil_flags(argc, argv);
  benchmark::RegisterBenchmark("chip", chip_alone)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("board_idle", [](benchmark::State& s) {
    board(s, false);
  })->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("board_session", [](benchmark::State& s) {
    board(s, true);
  })->Unit(benchmark::kMillisecond);
  Reporter reporter;
  return hil::bench::run_and_check(flags, reporter,
                                   [&] { return reporter.check(flags.number("min_realtime")); });
}
