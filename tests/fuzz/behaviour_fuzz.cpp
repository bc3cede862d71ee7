// libFuzzer target for the scripted-behaviour loader: any bytes either load
// or are refused with config::ConfigError (never a crash, a hang or another
// exception).

#include "mocks/behaviour_yaml.hpp"
#include "tests/fuzz/loader_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  hil::fuzz::expect_only<hil::config::ConfigError>([&] {
    (void)hil::mocks::parse_behaviours_text(hil::fuzz::as_text(data, size), "fuzz.yaml");
  });
  return 0;
}
