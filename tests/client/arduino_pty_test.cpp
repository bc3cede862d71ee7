// The Arduino client session over a real pty at 9600 baud under the
// real-time driver, against both boards: the behavioural mock and hil's
// test sketch on the emulated ATmega328P (tests/client/arduino_board.hpp).
// Waits are bounded and generous.

#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <string>

#include <asio/io_context.hpp>

#include "client/arduino/session.hpp"
#include "link/endpoint.hpp"
#include "mocks/arduino.hpp"
#include "mocks/avr/avr_firmware.hpp"
#include "tests/client/arduino_board.hpp"
#include "tests/link/transports/real_time.hpp"
#include "tests/mocks/real_time_car.hpp"

namespace hil::client::arduino {
namespace {

namespace proto = protocol::arduino;

// The board, by its firmware's type, and how to make it.
struct OnMock {
  using Firmware = mocks::ArduinoFirmware;
  static constexpr test::Board kBoard = test::Board::mock;
  static mocks::ArduinoConfig config() { return {}; }
};
struct OnSketch {
  using Firmware = mocks::AvrFirmware;
  static constexpr test::Board kBoard = test::Board::sketch;
  static mocks::AvrConfig config() { return test::sketch_config(); }
};

struct BoardNames {
  template <class T>
  static std::string GetName(int) {
    return test::board_name(T::kBoard);
  }
};

template <class Board>
struct ArduinoSessionOverPty : ::testing::Test {};
using Boards = ::testing::Types<OnMock, OnSketch>;
TYPED_TEST_SUITE(ArduinoSessionOverPty, Boards, BoardNames);

TYPED_TEST(ArduinoSessionOverPty, ASessionAt9600BaudGetsEveryAnswerAndLogsEveryFrame) {
  mocks::test::PtyCar<typename TypeParam::Firmware> car("arduino0", "?baud=9600",
                                                        sim::arduino_robot(), TypeParam::config());
  asio::io_context& io = car.io;

  ArduinoSession session(car.context, link::parse_endpoint(car.uri));
  session.open();
  ASSERT_TRUE(link::test::run_until(io, [&] {
    return session.state() == ConnectionState::connected;
  })) << "the port never opened";
  if constexpr (TypeParam::kBoard == test::Board::sketch) {
    // The emulated board resets as the port opens (about 66 ms); the
    // requests wait until its sketch has turned the UART on after that
    // reset (its second boot, power-on being the first).
    ASSERT_TRUE(link::test::run_until(io, [&] {
      return car.firmware.state().boots >= 2 &&
             car.firmware.state().phase == mocks::ChipPhase::running &&
             car.firmware.state().uart_baud != 0;
    })) << "the sketch never turned its UART on";
  }

  auto run = [&](auto submit) {
    std::optional<Result> result;
    submit(session, [&](const Result& r) { result = r; });
    EXPECT_TRUE(link::test::run_until(io, [&] { return result.has_value(); }));
    return result.value_or(Result{});
  };
  auto ping = run([](auto& s, auto cb) { return s.ping(cb); });
  EXPECT_EQ(ping.code, ResultCode::ok) << ping.detail;
  // The real sketch's answers (the default profile).
  EXPECT_EQ(ping.info, "PONG");
  auto v = run([](auto& s, auto cb) { return s.set_v(180, cb); });
  EXPECT_EQ(v.info, "OK");
  auto status = run([](auto& s, auto cb) { return s.status(cb); });
  EXPECT_EQ(status.info, "STATUS:V=180,DIR=stop,MOT:IDLE");
  // A raw token goes out as typed; the board refuses the value.
  auto bad = run([](auto& s, auto cb) { return s.raw("V:999", cb); });
  EXPECT_EQ(bad.code, ResultCode::nack) << bad.detail;
  EXPECT_EQ(bad.nack, (proto::Nack{proto::NackCode::bad_v}));
  auto turn = run([](auto& s, auto cb) { return s.raw("R:-90", cb); });
  EXPECT_EQ(turn.info, "ACCEPTED");
  if constexpr (TypeParam::kBoard == test::Board::mock) EXPECT_EQ(car.firmware.state().pwm, 180);

  const auto entries = session.log().entries();
  ASSERT_GE(entries.size(), 8u);
  EXPECT_EQ(entries[0].raw, "^00|PING| *30$");
  EXPECT_EQ(entries[0].kind, LogKind::tx);
  EXPECT_EQ(entries[1].kind, LogKind::rx);
  EXPECT_EQ(entries[1].seq, std::optional<std::uint8_t>(0x00));
  session.close();
  EXPECT_EQ(session.state(), ConnectionState::disconnected);
}

}  // namespace
}  // namespace hil::client::arduino
