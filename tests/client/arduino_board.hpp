#pragma once
// The two Arduino boards the client tests run against: hil's behavioural
// mock (mocks/arduino.hpp, the `firmware` dialect unless told) and hil's
// own test sketch (scenarios/firmware/hil_arduino/hil_arduino.ino) as its
// ELF on the emulated ATmega328P (mocks/avr/avr_firmware.hpp), and a car
// in virtual time built with either.
//
// The emulated board is the sketch as built: scripted behaviours that
// change the firmware's own answers (Reject, Ignore, faults) never act on
// it; link faults and the behaviours the driver carries out (closing the
// connection, bytes sent on a timer) do. Like a real Uno it resets when
// the port opens and hears nothing until its sketch has started
// (AvrConfig::startup_delay, about 66 ms).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "link/executor.hpp"
#include "link/transport.hpp"
#include "mocks/arduino.hpp"
#include "mocks/avr/avr_firmware.hpp"
#include "mocks/server.hpp"
#include "sim/presets.hpp"
#include "sim/world.hpp"
#include "tests/client/client_test_support.hpp"

namespace hil::client::test {

enum class Board {
  mock,    ///< the behavioural mock
  sketch,  ///< hil's test sketch on the emulated ATmega328P
};

/// "Mock" or "Sketch": the part of a test's name that says which board.
inline std::string board_name(Board board) {
  return board == Board::mock ? "Mock" : "Sketch";
}

/// How GoogleTest shows a Board parameter.
inline void PrintTo(Board board, std::ostream* os) {
  *os << board_name(board);
}

/// Both boards, for INSTANTIATE_TEST_SUITE_P.
inline auto both_boards() {
  return ::testing::Values(Board::mock, Board::sketch);
}

/// The test name suffix of a suite parameterised by Board.
inline std::string board_param_name(const ::testing::TestParamInfo<Board>& info) {
  return board_name(info.param);
}

/// hil's test sketch on the emulated board, with its defaults.
inline mocks::AvrConfig sketch_config() {
  mocks::AvrConfig config;
  config.elf = HIL_TEST_SKETCH_ELF;
  return config;
}

/// `board`'s firmware for `vehicle` (the mock with `mock_config`).
inline std::unique_ptr<mocks::Firmware> make_board(Board board, sim::World& world,
                                                   sim::Vehicle& vehicle,
                                                   mocks::ArduinoConfig mock_config = {}) {
  if (board == Board::sketch)
    return std::make_unique<mocks::AvrFirmware>(world, vehicle, sketch_config());
  return std::make_unique<mocks::ArduinoFirmware>(world, vehicle, std::move(mock_config));
}

/// How long `bytes` take through the emulated board's UART at the sketch's
/// 9,600 baud (ten bits a byte: start, eight data, stop).
inline link::Duration sketch_uart_time(std::size_t bytes) {
  return link::Duration(static_cast<std::int64_t>(bytes) * 10 * 1'000'000'000 / 9600);
}

/// The emulated board's own time for a request of `out` bytes that reaches
/// it whole and its answer of `back` bytes (at least 2). The mock answers
/// in the instant a frame reaches it; the board's UART hands the request's
/// first byte to the sketch at once and each next one a byte time later,
/// and takes the answer's first two bytes at once (its data register and
/// its shift register) and each next one as the line frees a place.
inline link::Duration sketch_frames_time(std::size_t out, std::size_t back) {
  return sketch_uart_time(out - 1) + sketch_uart_time(back - 2);
}

/// What the emulated board adds on top of that: the sketch's own work
/// between a request's '$' and its answer's first byte, and the 250 us
/// slices it runs in (AvrConfig::step; its output is handed over at a
/// slice's end). Times taken on it are held to [model, model + this].
inline constexpr link::Duration kSketchSlack = link::milliseconds(2);

/// An Arduino car in virtual time whose firmware is either board: the
/// Arduino robot preset in a world of `world_def`, the board behind a mock
/// server, started. Empty until start_board().
struct BoardCar {
  void start_board(Board which, mocks::ServerOptions options, mocks::ArduinoConfig mock_config = {},
                   sim::WorldDef world_def = {}) {
    board = which;
    world.emplace(std::move(world_def));
    sim::Vehicle& v = world->add_vehicle(sim::arduino_robot());
    firmware = make_board(which, *world, v, std::move(mock_config));
    server = std::make_unique<mocks::MockServer>(context, *firmware, std::move(options));
    server->start();
  }

  /// The behavioural mock (null on the emulated board).
  mocks::ArduinoFirmware* mock() { return dynamic_cast<mocks::ArduinoFirmware*>(firmware.get()); }
  /// The emulated board (null on the mock).
  mocks::AvrFirmware* sketch() { return dynamic_cast<mocks::AvrFirmware*>(firmware.get()); }

  /// Power-on, and one reset per port opening: the same count on both boards.
  std::uint64_t boots() {
    if (auto* m = mock()) return m->state().boots;
    return sketch()->state().boots;
  }

  /// Runs until the board hears its port: at once on the mock; on the
  /// emulated board until its sketch has turned the UART on after the
  /// reset the port's opening caused (what an operator waits for before
  /// typing to a real Uno). Whether it does within a second.
  bool wait_until_listening() {
    auto* board_chip = sketch();
    if (board_chip == nullptr) return true;
    return run_until_done(
        executor,
        [board_chip] {
          return board_chip->state().phase == mocks::ChipPhase::running &&
                 board_chip->state().uart_baud != 0;
        },
        link::seconds(1));
  }

  Board board = Board::mock;
  link::VirtualExecutor executor;
  link::TransportContext context{executor};
  std::optional<sim::World> world;
  std::unique_ptr<mocks::Firmware> firmware;
  std::unique_ptr<mocks::MockServer> server;
};

}  // namespace hil::client::test
