#pragma once
// What logi-client's tests against `hil mock logi` share: the car on a
// free port with the same seed every run, and the client's paths to it.

#include <chrono>
#include <string>
#include <utility>
#include <vector>

#include "tests/apps/client_program_support.hpp"

namespace hil::test {

/// logi-client against `hil mock logi --seed 1` (the same car every run),
/// with a scratch folder. The car is stopped when the test ends; how it
/// stops is checked only by the tests that stop it themselves.
class LogiClientTest : public ClientProgramTest {
 protected:
  explicit LogiClientTest(const std::string& temp_prefix)
      : ClientProgramTest(LOGI_CLIENT_BINARY, temp_prefix) {}

  void TearDown() override {}

  /// Starts the car with `extra` arguments.
  void start_car(std::vector<std::string> extra = {}) {
    extra.insert(extra.begin(), {"--seed", "1"});
    start_mock(mock_on_tcp_args("logi", std::move(extra)));
  }

  /// Starts the car with the fault profile `yaml`, written as `name` in the
  /// scratch folder.
  void start_car_with_faults(const std::string& name, const std::string& yaml) {
    start_car({"--faults", write(name, yaml).string()});
  }
};

}  // namespace hil::test
