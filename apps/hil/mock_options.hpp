#pragma once
// The options of `hil mock` and what they make: each car's firmware
// settings, the faults and behaviours, the seed, checked before any car
// starts.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "link/endpoint.hpp"
#include "link/faults/profile.hpp"
#include "mocks/behaviour.hpp"
#include "mocks/car.hpp"

namespace hil::apps {

// What each car is.
struct MockCarArgs {
  std::string kind;
  std::string profile;        ///< empty: the car's default profile
  std::string reply_latency;  ///< a duration; empty: none
  std::string auth;
  std::optional<double> data_hz;
  std::string world;
  std::string faults;
  std::string behaviours;
  std::optional<std::uint64_t> seed;
  std::string replay;              ///< a probe capture to play; empty: the mock firmware
  std::string unmatched = "mock";  ///< what answers a request the capture has no recording for
  std::string sketch;              ///< Arduino: a sketch to build and run on the emulated board
  std::string elf;                 ///< Arduino: a firmware image to run on the emulated board
  std::string pins;                ///< with sketch or elf: the pin map file
  std::string board_startup;       ///< with sketch or elf: the board's start-up; empty: 66 ms
};

// Where car N listens.
struct MockListenArgs {
  std::string bind = "127.0.0.1";
  std::optional<std::uint16_t> port;
  std::string pty;
  std::optional<unsigned> baud;
  unsigned reset_ms = 0;
  std::string rfc2217;  ///< serial cars: "[ADDR:]PORT" of an RFC 2217 server instead of a pty
};

// What the desk shows and takes.
struct MockDeskArgs {
  bool quiet = false;
  bool verbose = false;
  std::string ports_file;
  std::string wire_log;
  bool no_status = false;
  bool commands = false;
  bool view = false;
  std::string view_port;  ///< empty: the default port
};

struct MockArgs {
  MockCarArgs car;
  MockListenArgs listen;
  std::size_t count = 1;
  MockDeskArgs desk;
};

constexpr std::uint16_t kDefaultViewPort = 8080;

// A fleet of TCP cars is what a fleet manager is tested against; one
// io_context serves 1,000 LOGI cars in real time on 2 cores
// (docs/performance.md), and each car holds two descriptors (its listener and
// its client), so 10,000 cars stay within common hard limits of 20,000+ and
// within the port range. Serial cars each hold a pty pair and a symlink in
// /tmp, and the kernel's pty pool is shared with every terminal on the
// machine, so they keep a smaller limit.
constexpr std::size_t kMaxTcpCars = 10000;
constexpr std::size_t kMaxSerialCars = 64;
// Up to this many cars, one line each; beyond, the first, the last and a
// summary (-v lists every car, --ports-file writes them to a file).
constexpr std::size_t kCarsListed = 16;
// Why the cars cannot start: printed after "hil mock: ", with the exit
// status (2 for options that do not fit together, 1 for what failed).
struct MockStartError {
  std::string message;
  int status = 1;
};

// The cars as the options make them, checked before anything starts.
struct MockPlan {
  mocks::CarKind kind{};
  mocks::CarOptions base;
  /// The car's profile: --profile's, or the capture's with --replay.
  std::string profile;
  link::FaultProfile faults;
  std::vector<mocks::Behaviour> behaviours;
  bool serial = false;  ///< cars on ptys or RFC 2217 (else TCP)
  /// --rfc2217: where car 0's RFC 2217 server listens (car N on PORT+N,
  /// or free ports with port 0); the line's baud and reset come from the
  /// pty options. Empty: the cars are on ptys.
  std::optional<link::Rfc2217Endpoint> rfc2217;
  std::uint64_t seed = 0;
  std::uint16_t view_port = kDefaultViewPort;
};

/// "[ADDR:]PORT" ("4000", "0.0.0.0:4000", "[::1]:4000") as an RFC 2217
/// endpoint, 127.0.0.1 when no address is given. Throws MockStartError.
link::Rfc2217Endpoint parse_rfc2217_option(const std::string& text);

/// Whether a listener on `host` is reachable from this machine only.
bool is_loopback(const std::string& host);

/// Loads the files the options name and checks the options against each
/// other and the machine (raising the open-file limit for a big fleet).
/// Throws MockStartError.
MockPlan plan_mock(const MockArgs& args);

}  // namespace hil::apps
