#include "conform/check.hpp"

#include <algorithm>
#include <numeric>

#include "conform/probe_runner.hpp"
#include "mocks/car.hpp"
#include "mocks/server.hpp"
#include "protocol/common/car_profile.hpp"

namespace hil::conform {

Capture probe_mock(const Probe& probe, std::string_view mock_profile, std::uint64_t seed) {
  const auto& profile = protocol::find_car_profile(mocks::to_string(probe.car), mock_profile);
  mocks::CarOptions options;
  options.kind = probe.car;
  options.seed = seed;
  mocks::apply_profile(options.configs, probe.car, profile.name);
  return probe_in_virtual_time(probe, std::move(options), "mock:" + std::string(profile.name));
}

Capture probe_in_virtual_time(const Probe& probe, mocks::CarOptions options,
                              const std::string& target, std::shared_ptr<link::WireLog> log) {
  auto driver = harness::make_run_driver(false);
  options.kind = probe.car;
  const std::uint64_t seed = options.seed;
  mocks::MockCar car(std::move(options));
  // A serial car's line keeps its baud in virtual time: each byte takes
  // its ten bits of line time, as on the pty.
  link::MemEndpoint mem{"car0"};
  const auto real = mocks::default_endpoint(probe.car, 0, car.firmware().profile());
  if (const auto* pty = std::get_if<link::PtyEndpoint>(&real)) mem.baud = pty->baud;
  mocks::ServerOptions server_options;
  server_options.listen = mem;
  server_options.name = "car0";
  server_options.seed = seed;
  mocks::MockServer server(driver->context(), car.firmware(), std::move(server_options));
  server.start();
  CaptureRecorder recorder(capture_header(probe, target, 0), std::move(log));
  auto run = run_probe(*driver, mem, probe, recorder);
  server.close();
  return std::move(run.capture);
}

std::vector<std::string> CheckResult::ranking() const {
  std::vector<std::size_t> order(by_profile.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return by_profile[a].matches() > by_profile[b].matches();
  });
  std::vector<std::string> names;
  for (const auto i : order)
    names.push_back(by_profile[i].mock_profile);
  return names;
}

const Comparison& CheckResult::of(std::string_view profile) const {
  for (const auto& c : by_profile) {
    if (c.mock_profile == profile) return c;
  }
  throw std::out_of_range("no comparison for profile " + std::string(profile));
}

CheckResult check(const Capture& capture, const Tolerances& tolerances, std::uint64_t seed) {
  const auto car = mocks::parse_car_kind(capture.header.car);
  if (!car) throw CheckError("the capture is of an unknown car '" + capture.header.car + "'");
  const auto problem = protocol::car_profile_problem(capture.header.car, capture.header.profile);
  if (!problem.empty()) throw CheckError("the capture's profile: " + problem);
  const Probe probe = make_probe(*car, capture.header.profile);
  if (capture.header.probe_version != probe.version) {
    throw CheckError("the capture was made by probe " + capture.header.probe_version +
                     " and this hil runs " + probe.version +
                     ": probe the car again with this hil (hil conform probe)");
  }
  CheckResult result;
  for (const auto& profile : protocol::car_profiles_of(capture.header.car)) {
    const auto mock = probe_mock(probe, profile.name, seed);
    result.by_profile.push_back(
        compare(capture, mock, probe, std::string(profile.name), tolerances));
  }
  // Each difference names the other profiles that answer as the car did.
  for (auto& comparison : result.by_profile) {
    for (std::size_t i = 0; i < comparison.exchanges.size(); ++i) {
      auto& row = comparison.exchanges[i];
      if (row.matches()) continue;
      for (const auto& other : result.by_profile) {
        if (&other != &comparison && other.exchanges[i].matches())
          row.explained_by.push_back(other.mock_profile);
      }
    }
  }
  return result;
}

}  // namespace hil::conform
