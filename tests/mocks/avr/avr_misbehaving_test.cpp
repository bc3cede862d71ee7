// Firmware that goes wrong on the emulated board: one that never opens its
// UART, one that halts, one that crashes, one on another baud rate. Each is
// a warning in the log or a state the status line shows, never a hang.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "mocks/avr/avr_firmware.hpp"
#include "mocks/avr/sketch_build.hpp"
#include "sim/presets.hpp"
#include "tests/mocks/mock_test_support.hpp"

namespace hil::mocks {
namespace {

using link::milliseconds;
using link::seconds;

using Board = test::VirtualCar<AvrFirmware>;

// One of the sketches beside this file, built once into the build tree's
// cache.
std::filesystem::path built(const std::string& name) {
  avr::SketchBuildOptions options;
  options.cache_dir = HIL_TEST_FIRMWARE_CACHE;
  const auto ino = std::filesystem::path(HIL_TEST_SKETCHES_DIR) / name / (name + ".ino");
  return avr::build_sketch(ino, options).elf;
}

struct Sketch {
  explicit Sketch(const std::string& sketch) {
    AvrConfig config;
    config.elf = built(sketch);
    config.log = [this](const std::string& line) { log.push_back(line); };
    board = std::make_unique<Board>(sim::arduino_robot(), [config](sim::World& w, sim::Vehicle& v) {
      return std::make_unique<AvrFirmware>(w, v, config);
    });
    client = board->connect();
  }
  bool logged(const std::string& words) const {
    for (const auto& line : log)
      if (line.find(words) != std::string::npos) return true;
    return false;
  }
  std::vector<std::string> log;
  std::unique_ptr<Board> board;
  std::shared_ptr<test::ClientEnd> client;
};

TEST(AvrMisbehaving, AFirmwareThatNeverOpensItsUartIsWarnedAboutOnce) {
  Sketch run("silent");
  run.board->run_for(seconds(1));
  EXPECT_TRUE(run.log.empty());  // not yet: 2 s is the limit
  run.client->write(std::string("^01|PING| *31$"));
  run.board->run_for(seconds(3));
  EXPECT_EQ(run.client->take_text(), "");
  ASSERT_EQ(run.log.size(), 1U);
  EXPECT_TRUE(run.logged("has not turned its UART on 2000 ms after the reset")) << run.log[0];
  EXPECT_EQ(run.board->firmware().summary(), "ATmega328P RUN L+0 R+0");
}

TEST(AvrMisbehaving, AFirmwareThatHaltsIsReportedAndAsksForNoMoreTime) {
  Sketch run("halts");
  run.board->run_for(milliseconds(500));
  EXPECT_EQ(run.client->take_text(), "bye");
  EXPECT_EQ(run.board->firmware().summary(), "ATmega328P HALTED");
  EXPECT_TRUE(run.logged("halted (asleep with interrupts off)"));
  // Its wheels are still, so nothing is due: the driver is not kept busy.
  EXPECT_EQ(run.board->firmware().next_wakeup(), std::nullopt);
  run.board->run_for(seconds(60));  // returns at once
  EXPECT_EQ(run.board->firmware().summary(), "ATmega328P HALTED");
}

TEST(AvrMisbehaving, AFirmwareThatCrashesIsReported) {
  Sketch run("crashes");
  run.board->run_for(milliseconds(500));
  EXPECT_EQ(run.client->take_text(), "go");
  EXPECT_EQ(run.board->firmware().summary(), "ATmega328P CRASHED");
  EXPECT_TRUE(run.logged("crashed at cycle")) << (run.log.empty() ? "" : run.log.back());
}

TEST(AvrMisbehaving, AReconnectResetsAStoppedChip) {
  Sketch run("halts");
  run.board->run_for(milliseconds(500));
  ASSERT_EQ(run.board->firmware().summary(), "ATmega328P HALTED");
  run.client->pipe->close();
  run.board->run_for(milliseconds(10));
  auto again = run.board->connect();
  run.board->run_for(milliseconds(500));
  EXPECT_EQ(again->take_text(), "bye");
  EXPECT_EQ(run.board->firmware().state().boots, 3U);  // power-on, two opens
}

TEST(AvrMisbehaving, AFirmwareOnAnotherBaudRateIsWarned) {
  Sketch run("fast_uart");
  run.board->run_for(milliseconds(500));
  EXPECT_EQ(run.board->firmware().state().uart_baud, 117647U);  // 115,200 as UBRR0 16 makes it
  EXPECT_TRUE(run.logged("set its UART to 117647 baud"));
}

}  // namespace
}  // namespace hil::mocks
