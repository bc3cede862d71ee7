// libFuzzer target for the fault profile loader and its duration parser:
// any bytes either load or are refused with config::ConfigError, and a loaded
// profile passes the checks a profile built in code must pass (the loader
// and validate() must agree on what a sound profile is).

#include <stdexcept>
#include "base/duration.hpp"
#include "link/faults/profile_yaml.hpp"

#include "tests/fuzz/loader_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto text = hil::fuzz::as_text(data, size);
  hil::fuzz::expect_only<hil::config::ConfigError>([&] {
    const auto profile = hil::link::parse_fault_profile_text(text, "fuzz.yaml");
    try {
      hil::link::validate(profile);
    } catch (const std::invalid_argument& e) {
      std::fprintf(stderr, "the loader accepted a profile validate() refuses: %s\n", e.what());
      std::abort();
    }
  });
  // Durations come from the same files and from command lines.
  if (size < 64) (void)hil::parse_duration(text);
  return 0;
}
