#pragma once
// `hil conform check`: replays a capture's probe against hil's mock of the
// same car in virtual time, once per profile, and compares each run with
// the capture.
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "conform/compare.hpp"
#include "conform/probe.hpp"
#include "link/capture/probe_capture.hpp"
#include "mocks/car.hpp"

namespace hil::conform {

/// Runs `probe` against hil's mock of `probe.car` playing `mock_profile`
/// (empty: the car's default), on the virtual-time driver over mem://
/// (a serial car's line keeps its baud). Deterministic for one seed.
Capture probe_mock(const Probe& probe, std::string_view mock_profile, std::uint64_t seed = 1);

/// Runs `probe` against the car `options` make (a mock, or a real firmware
/// on the emulated board: `options.configs.avr`), in virtual time as
/// probe_mock does; `target` names it in the capture's header, and `log`,
/// when given, gets every record as it happens (a capture file).
Capture probe_in_virtual_time(const Probe& probe, mocks::CarOptions options,
                              const std::string& target,
                              std::shared_ptr<link::WireLog> log = nullptr);

/// A capture that this hil cannot check; what() says why and what to do.
class CheckError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct CheckResult {
  /// One comparison per profile of the car, in registry order.
  std::vector<Comparison> by_profile;
  /// The profiles ranked by matches, best first (ties in registry order).
  std::vector<std::string> ranking() const;
  const Comparison& of(std::string_view profile) const;
};

/// Checks `capture` against every profile of its car; each difference in a
/// comparison lists the other profiles that answer that exchange as the
/// car did. Throws CheckError when the capture was made by another probe
/// version or for a profile this hil does not have.
CheckResult check(const Capture& capture, const Tolerances& tolerances = {},
                  std::uint64_t seed = 1);

}  // namespace hil::conform
