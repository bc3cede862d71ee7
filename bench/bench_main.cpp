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

#include "bench/hil_flags.hpp"

namespace {

struct Best {
  double ms_per_iteration = 0;
  double bytes_per_second = 0;
  double frames_per_second = 0;
  double stream_bytes = 0;
};

class RecordingReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const auto& run : runs) {
      if (run.error_occurred) failed_ = true;
      if (run.run_type != Run::RT_Iteration || run.iterations == 0) continue;
      const double seconds = run.real_accumulated_time / static_cast<double>(run.iterations);
      const std::string name = run.benchmark_name();
      auto it = best_.find(name);
      if (it != best_.end() && it->second.ms_per_iteration <= seconds * 1e3) continue;
      Best b;
      b.ms_per_iteration = seconds * 1e3;
      const auto counter = [&](const char* key) {
        const auto c = run.counters.find(key);
        return c == run.counters.end() ? 0.0 : static_cast<double>(c->second);
      };
      b.stream_bytes = counter("stream_bytes");
      b.bytes_per_second = b.stream_bytes / seconds;
      b.frames_per_second = counter("frames_per_s");
      best_[name] = b;
    }
    ConsoleReporter::ReportRuns(runs);
  }

  bool check(double max_ratio) const {
    bool ok = !failed_;
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
    for (const auto& [name, b] : best_) {
      const auto slash = name.rfind('/');
      std::snprintf(line, sizeof line, "| %s | %s | %.1f | %.0f | %.2f |\n",
                    name.substr(0, slash).c_str(), name.substr(slash + 1).c_str(),
                    b.bytes_per_second / 1e6, b.frames_per_second, b.ms_per_iteration);
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
    for (const auto& [name, b] : best_) {
      const auto slash = name.rfind("/bytewise");
      if (slash == std::string::npos) continue;
      const auto whole = best_.find(name.substr(0, slash) + "/whole");
      if (whole == best_.end() || whole->second.ms_per_iteration <= 0) continue;
      out[name.substr(0, slash)] = b.ms_per_iteration / whole->second.ms_per_iteration;
    }
    return out;
  }

  std::map<std::string, Best> best_;
  bool failed_ = false;
};

}  // namespace

void hil_register_benchmarks();

int main(int argc, char** argv) {
  auto flags = hil::bench::take_hil_flags(argc, argv);
  const double max_ratio = flags.number("max_bytewise_ratio");
  hil_register_benchmarks();
  RecordingReporter reporter;
  if (!hil::bench::run_benchmarks(flags, reporter)) return 2;
  if (const auto markdown = flags.text("markdown"); !markdown.empty())
    reporter.write_markdown(markdown);
  if (max_ratio > 0 && !reporter.check(max_ratio)) return 1;
  return 0;
}
