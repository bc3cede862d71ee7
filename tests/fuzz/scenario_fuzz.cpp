// libFuzzer target for the scenario loader: any bytes, read as a scenario
// file, either load or are refused with config::ConfigError (never a crash, a hang
// or another exception). The file "lives" in a folder that does not exist,
// so files it names (world:, faults: ...) fail to load instead of reading
// whatever the fuzzer's working directory holds; those formats have
// targets of their own.

#include "harness/scenario_yaml.hpp"
#include "tests/fuzz/loader_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  hil::fuzz::expect_only<hil::config::ConfigError>([&] {
    (void)hil::harness::parse_scenario_text(hil::fuzz::as_text(data, size),
                                            "/nonexistent-hil-fuzz/fuzz.yaml");
  });
  return 0;
}
