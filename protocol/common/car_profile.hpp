#pragma once
// Profiles: the named dialects of each car. A car whose real firmware or
// client does something other than its protocol document has one profile
// for each, so hil can play either; every place that speaks a car's
// protocol takes a profile name and refuses an unknown one with the list
// of valid names (docs/protocols/<car>.md has a section per profile).

#include <chrono>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace hil::protocol {

struct CarProfile {
  std::string_view car;   ///< "logi", "wr8", "arduino" or "leka"
  std::string_view name;  ///< "firmware", "readme", ...
  /// Where its behaviour comes from: a document, or a repository and commit.
  std::string_view source;
  /// One line: how it differs from the car's other profiles.
  std::string_view summary;
  /// The profile a car gets when none is named.
  bool is_default = false;
  /// A serial car's line rate (8N1, 10 bits per byte); 0 for a TCP car.
  unsigned baud = 0;
  /// The firmware's processing time before each answer when a scenario or
  /// `hil mock` names none. A serial car's bytes also take their line time
  /// at its baud, on a pty and in virtual time alike; this comes on top.
  std::chrono::microseconds reply_latency{0};
  /// Why reply_latency is what it is, for `hil profiles` and the docs.
  std::string_view latency_basis;
  /// The TCP port the real car listens on (`hil mock` listens on it plus
  /// the car's index); 0: hil's own port for the car, or a serial car.
  std::uint16_t tcp_port = 0;
};

/// An unknown car or profile name; the message lists the valid ones.
class ProfileError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Every profile of every car, cars in the order logi, wr8, arduino, leka.
std::span<const CarProfile> car_profiles();

/// The cars that have profiles, in registry order.
std::vector<std::string_view> car_profile_cars();

/// The profiles of one car, the default first. Throws ProfileError for an
/// unknown car.
std::vector<CarProfile> car_profiles_of(std::string_view car);

/// Throws ProfileError for an unknown car.
const CarProfile& default_car_profile(std::string_view car);

/// The named profile of `car`; an empty name is the default. Throws
/// ProfileError ("arduino has no profile 'x'; its profiles are firmware
/// (the default) and readme").
const CarProfile& find_car_profile(std::string_view car, std::string_view name);

/// Empty when `name` is a profile of `car` (or empty, the default), else
/// find_car_profile's message: for validating command-line options.
std::string car_profile_problem(std::string_view car, std::string_view name);

/// "firmware (the default) and readme": the names of one car's profiles.
std::string car_profile_names(std::string_view car);

}  // namespace hil::protocol
