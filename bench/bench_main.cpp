// main() for the decoder benchmarks. Besides Google Benchmark's own flags:
//   --hil_max_bytewise_ratio=R  after the run, every "<name>/bytewise" result
//       must cost at most R times its "<name>/whole" result per byte, or the
//       program exits 1 (CTest holds the decoders to linear behaviour so);
//   --hil_markdown=FILE  writes the results as a Markdown table.
// With --benchmark_repetitions the best repetition of each benchmark counts:
// it is the one least disturbed by other load on the machine.

#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "bench/best_runs.hpp"
#include "bench/hil_flags.hpp"

namespace {

using hil::bench::BestRunReporter;

/// The decoders wait on nothing, so their best repetition is by wall time.
class RecordingReporter : public BestRunReporter {
 public:
  RecordingReporter() : BestRunReporter(Clock::wall) {}

  bool check(double max_ratio) const {
    bool ok = !failed();
    for (const auto& [name, ratio] : ratios()) {
      const bool pass = ratio <= max_ratio;
      std::printf("%s: bytewise/whole cost per byte = %.2f (limit %.1f) %s\n", name.c_str(), ratio,
                  max_ratio, pass ? "ok" : "TOO SLOW");
      ok = ok && pass;
    }
    return ok;
  }

  void write_markdown(const std::string& path) const {
    std::ofstream out(path);
    out << "| decoder | fed | MB/s | frames/s | ms per 1 MiB stream |\n|---|---|---:|---:|---:|\n";
    char line[256];
    for (const auto& [name, b] : all()) {
      const auto slash = name.rfind('/');
      std::snprintf(line, sizeof line, "| %s | %s | %.1f | %.0f | %.2f |\n",
                    name.substr(0, slash).c_str(), name.substr(slash + 1).c_str(),
                    b.counter("stream_bytes") / b.seconds / 1e6, b.counter("frames_per_s"),
                    b.seconds * 1e3);
      out << line;
    }
    out << "\n| decoder | bytewise / whole cost per byte |\n|---|---:|\n";
    for (const auto& [name, ratio] : ratios()) {
      std::snprintf(line, sizeof line, "| %s | %.2f |\n", name.c_str(), ratio);
      out << line;
    }
  }

 private:
  std::map<std::string, double> ratios() const {
    std::map<std::string, double> out;
    for (const auto& [name, b] : all()) {
      const auto slash = name.rfind("/bytewise");
      if (slash == std::string::npos) continue;
      const double whole = seconds(name.substr(0, slash) + "/whole");
      if (whole <= 0) continue;
      out[name.substr(0, slash)] = b.seconds / whole;
    }
    return out;
  }
};

}  // namespace

void hil_register_benchmarks();

int main(int argc, char** argv) {
  auto flags = hil::bench::take_hil_flags(argc, argv);
  const double max_ratio = flags.number("max_bytewise_ratio");
  hil_register_benchmarks();
  RecordingReporter reporter;
  return hil::bench::run_and_check(flags, reporter,
                                   [&] { return max_ratio <= 0 || reporter.check(max_ratio); });
}
