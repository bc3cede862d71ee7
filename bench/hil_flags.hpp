#pragma once
// The benchmark programs' own flags (--hil_NAME=VALUE), taken out of the
// command line before Google Benchmark sees the rest, and the run that
// follows.

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <map>
#include <string>
#include <vector>

namespace hil::bench {

struct HilFlags {
  std::map<std::string, std::string> values;  ///< NAME -> VALUE for --hil_NAME=VALUE
  std::vector<char*> rest;                    ///< everything else, argv[0] first

  double number(const std::string& name, double fallback = 0) const {
    const auto it = values.find(name);
    return it == values.end() ? fallback : std::atof(it->second.c_str());
  }
  std::string text(const std::string& name) const {
    const auto it = values.find(name);
    return it == values.end() ? std::string{} : it->second;
  }
};

inline HilFlags take_hil_flags(int argc, char** argv) {
  HilFlags flags;
  for (int i = 0; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto eq = arg.find('=');
    if (i > 0 && arg.starts_with("--hil_") && eq != std::string::npos) {
      flags.values[arg.substr(6, eq - 6)] = arg.substr(eq + 1);
    } else {
      flags.rest.push_back(argv[i]);
    }
  }
  return flags;
}

/// Runs the registered benchmarks with `flags.rest` through `reporter`;
/// false when Google Benchmark did not understand an argument.
template <class Reporter>
bool run_benchmarks(HilFlags& flags, Reporter& reporter) {
  int n = static_cast<int>(flags.rest.size());
  benchmark::Initialize(&n, flags.rest.data());
  if (benchmark::ReportUnrecognizedArguments(n, flags.rest.data())) return false;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return true;
}

/// The end of a benchmark program's main(): runs the registered benchmarks
/// through `reporter`, has it write its Markdown to --hil_markdown=FILE
/// when asked, then asks `passes()`. The exit status: 2 when Google
/// Benchmark did not understand an argument, 1 when passes() is false.
template <class Reporter, class Passes>
int run_and_check(HilFlags& flags, Reporter& reporter, Passes passes) {
  if (!run_benchmarks(flags, reporter)) return 2;
  if (const auto markdown = flags.text("markdown"); !markdown.empty())
    reporter.write_markdown(markdown);
  return passes() ? 0 : 1;
}

}  // namespace hil::bench
