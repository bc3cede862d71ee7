// main() for the decoder benchmarks. Besides Google Benchmark's own flags it
// takes --hil_max_bytewise_ratio=R: after the run, every "<name>/bytewise"
// result must cost at most R times its "<name>/whole" result per byte, or the
// program exits 1. CTest uses this to hold the decoders to linear behaviour; with
// --benchmark_repetitions the best repetition of each counts.

#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <vector>

namespace {

class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const auto& run : runs) {
      if (run.error_occurred) failed_ = true;
      const std::string name = run.benchmark_name();
      if (run.run_type == Run::RT_Iteration && run.iterations > 0) {
        // Best of the repetitions: the least disturbed by other load.
        const double t = run.GetAdjustedRealTime();
        const auto it = seconds_.find(name);
        if (it == seconds_.end() || t < it->second) seconds_[name] = t;
      }
    }
    ConsoleReporter::ReportRuns(runs);
  }

  bool check(double max_ratio) const {
    bool ok = !failed_;
    for (const auto& [name, t] : seconds_) {
      const auto slash = name.rfind("/bytewise");
      if (slash == std::string::npos) continue;
      const auto whole = seconds_.find(name.substr(0, slash) + "/whole");
      if (whole == seconds_.end() || whole->second <= 0) continue;
      const double ratio = t / whole->second;
      const bool pass = ratio <= max_ratio;
      std::printf("%s: bytewise/whole cost per byte = %.2f (limit %.1f) %s\n", name.substr(0, slash).c_str(),
                  ratio, max_ratio, pass ? "ok" : "TOO SLOW");
      ok = ok && pass;
    }
    return ok;
  }

 private:
  std::map<std::string, double> seconds_;
  bool failed_ = false;
};

}  // namespace

void hil_register_benchmarks();

int main(int argc, char** argv) {
  double max_ratio = 0;
  std::vector<char*> args;
  for (int i = 0; i < argc; ++i) {
    constexpr const char* kFlag = "--hil_max_bytewise_ratio=";
    if (std::strncmp(argv[i], kFlag, std::strlen(kFlag)) == 0) {
      max_ratio = std::atof(argv[i] + std::strlen(kFlag));
    } else {
      args.push_back(argv[i]);
    }
  }
  int n = static_cast<int>(args.size());
  hil_register_benchmarks();
  benchmark::Initialize(&n, args.data());
  if (benchmark::ReportUnrecognizedArguments(n, args.data())) return 2;
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  if (max_ratio > 0 && !reporter.check(max_ratio)) return 1;
  return 0;
}
