// libFuzzer target for the world (arena) loader: any bytes either load or
// are refused with config::ConfigError, and a loaded arena written back with to_yaml()
// loads again to an arena that writes the same YAML.

#include "sim/arena_yaml.hpp"
#include "tests/fuzz/fuzz_support.hpp"
#include "tests/fuzz/loader_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  hil::fuzz::expect_only<hil::config::ConfigError>([&] {
    const auto arena = hil::sim::parse_arena_text(hil::fuzz::as_text(data, size), "fuzz.yaml");
    const std::string yaml = hil::sim::to_yaml(arena);
    hil::sim::Arena again;
    try {
      again = hil::sim::parse_arena_text(yaml, "round-trip.yaml");
    } catch (const hil::config::ConfigError& e) {
      std::fprintf(stderr, "to_yaml() wrote an arena that does not load: %s\n%s\n", e.what(),
                   yaml.c_str());
      std::abort();
    }
    hil::fuzz::check(hil::sim::to_yaml(again) == yaml, "arena changes across to_yaml()");
  });
  return 0;
}
