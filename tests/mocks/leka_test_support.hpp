#pragma once
// What the mock Leka firmware's virtual-time tests share: the robot behind a
// raw link with a client connected, the LED colours and frames they send,
// the info line the robot answers and the `LekaTest` fixture.

#include <gtest/gtest.h>

#include <initializer_list>
#include <memory>
#include <string>
#include <utility>

#include "link/protocol_adapter.hpp"
#include "mocks/leka.hpp"
#include "protocol/leka/codec.hpp"
#include "sim/presets.hpp"
#include "tests/mocks/mock_test_support.hpp"
#include "tests/support/hex.hpp"
#include "tests/support/stream_support.hpp"

namespace hil::mocks::test {

namespace leka = protocol::leka;
using leka::Rgb;
using link::milliseconds;
using protocol::Bytes;

using hil::test::concat;
using hil::test::hex;

using LekaCar = VirtualCar<LekaFirmware>;

inline constexpr Rgb kOff{};
inline constexpr Rgb kRed{255, 0, 0};
inline constexpr Rgb kGreen{0, 255, 0};
inline constexpr Rgb kBlue{0, 0, 255};
inline constexpr Rgb kWhite{255, 255, 255};

/// One frame carrying `commands` as a single group.
inline Bytes frame(std::initializer_list<leka::Command> commands) {
  return leka::encode(leka::CommandGroup{commands});
}

// The source document's three worked frames, byte for byte (the `readme`
// profile of docs/protocols/leka.md): info, belt LED 0 red, and all twenty
// belt LEDs in one group.
inline const Bytes kSeedInfo = hex("2A 2B 2C 2D 01 70 70");
inline const Bytes kSeedBeltRed = hex("2A 2B 2C 2D 05 15 00 FF 00 00 41");
inline const Bytes kSeedBelt20 =
    hex("2A 2B 2C 2D 64 15 00 33 00 00 15 01 66 00 00 15 02 99 00 00 15 03 CC 00 00 15 04 FF 00 00 "
        "15 05 00 00 00 15 06 00 33 00 15 07 00 66 00 15 08 00 99 00 15 09 00 CC 00 15 0A 00 FF 00 "
        "15 0B 00 00 00 15 0C 00 00 33 15 0D 00 00 66 15 0E 00 00 99 15 0F 00 00 CC 15 10 FF 00 00 "
        "15 11 00 FF 00 15 12 00 00 FF 15 13 FF FF FF A8");

/// What the default robot answers to info.
inline const std::string kInfoLine = "LEKA name=leka firmware=1.0.0 buffer=128 state=ok\r\n";

// These tests watch the firmware's own serial buffer fill with partial
// frames and garbage, so the link passes bytes exactly as they are written
// (a frame-aware link would hold a partial frame itself until it is whole).
inline ServerOptions raw_link() {
  ServerOptions options;
  options.protocol = link::protocol_adapter("raw");
  return options;
}

inline LekaCar make_car(LekaConfig config = {}, sim::VehicleDef vehicle = sim::leka_robot()) {
  return LekaCar(
      std::move(vehicle),
      [config](sim::World& w, sim::Vehicle& v) {
        return std::make_unique<LekaFirmware>(w, v, config);
      },
      raw_link());
}

// A client connects at 0 ms (connected at 1 ms); bytes written at 1 ms are
// read by the main loop's pass at 10 ms.
struct LekaTest : ::testing::Test {
  LekaCar car = make_car();
  std::shared_ptr<ClientEnd> client = car.connect();

  const LekaState& state() { return car.firmware().state(); }
  sim::DifferentialChassis& chassis() { return *car.vehicle().differential(); }
  /// Writes `bytes` now and runs the loop's next pass.
  void send_and_pass(const Bytes& bytes) {
    client->write(bytes);
    const auto period = car.firmware().config().loop_period;
    car.run_until(link::Time((car.now() / period + 1) * period));
  }
};

}  // namespace hil::mocks::test
