// hil's own Arduino sketch on the emulated ATmega328P, under the
// virtual-time driver: it answers as the behavioural mock's `firmware`
// dialect does, its motor pins drive the chassis, its sonar and IR pins
// read the simulated world, and the same bytes at the same times give the
// same bytes back and the same world whatever slices the driver runs in.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "mocks/arduino.hpp"
#include "mocks/avr/avr_firmware.hpp"
#include "protocol/arduino/sketch.hpp"
#include "sim/presets.hpp"
#include "tests/mocks/arduino_rig.hpp"
#include "tests/mocks/mock_test_support.hpp"

namespace hil::mocks {
namespace {

using link::milliseconds;
using protocol::arduino::sketch_frame;
using test::at_ms;

using Board = test::VirtualCar<AvrFirmware>;

AvrConfig sketch_config() {
  AvrConfig config;
  config.elf = HIL_TEST_SKETCH_ELF;
  return config;
}

std::unique_ptr<Board> make_board(AvrConfig config = sketch_config(), sim::WorldDef world = {}) {
  return std::make_unique<Board>(
      sim::arduino_robot(),
      [config](sim::World& w, sim::Vehicle& v) {
        return std::make_unique<AvrFirmware>(w, v, config);
      },
      ServerOptions{}, std::move(world));
}

// A board with a client on its port, past the reset and Serial.begin().
struct Session {
  explicit Session(sim::WorldDef world = {}, AvrConfig config = sketch_config())
      : board(make_board(std::move(config), std::move(world))), client(board->connect()) {
    board->run_for(milliseconds(200));
    client->take();
  }
  // The whole answer: the request's bytes and the reply's take about a
  // millisecond each on the chip's UART at 9,600 baud.
  std::string ask(std::string_view frame, link::Duration wait = milliseconds(150)) {
    client->write(frame);
    board->run_for(wait);
    return client->take_text();
  }
  std::unique_ptr<Board> board;
  std::shared_ptr<test::ClientEnd> client;
};

// Requests whose answers do not depend on the world, and what the real
// sketch's parser does with them (docs/mocks/arduino.md, `firmware`).
std::vector<std::string> world_free_requests() {
  return {
      sketch_frame("01", "PING", " "),  // the real client's empty payload
      sketch_frame("02", "PING", ""),   // empty payload: BAD_FMT
      sketch_frame("03", "V", "160"),
      sketch_frame("04", "V", "999"),  // BAD_V
      sketch_frame("05", "V", "abc"),  // atol: 0
      sketch_frame("06", "HELP", " "),
      sketch_frame("07", "STATUS", " "),
      sketch_frame("08", "S", " "),
      sketch_frame("09", "FLY", " "),      // BAD_CMD
      sketch_frame("0A", "ping", " "),     // commands are case-blind
      sketch_frame("ZZ", "PING", " "),     // BAD_SEQ
      sketch_frame("0B", "PING", " x|y"),  // a fourth field is ignored
      "^0C|PING| *00$",                    // BAD_CS
      "^0D|PING| *31",                     // no end marker yet...
      "$",                                 // ...then it comes: answered
      "^0E|PING| *3$",                     // one checksum digit: dropped
      "garbage^0F|PING| *36$",             // bytes before ^ are skipped
      "^" + std::string(100, 'A') + "$",   // past 96 bytes: dropped
  };
}

TEST(AvrFirmware, AnswersEveryWorldFreeRequestAsTheBehaviouralMockDoes) {
  Session board;
  test_arduino::Robot mock;  // the `firmware` dialect, the default profile
  mock.run_for(milliseconds(200));
  mock.client->take();
  for (const auto& request : world_free_requests()) {
    const std::string emulated = board.ask(request);
    mock.client->write(request);
    mock.run_for(milliseconds(150));
    EXPECT_EQ(emulated, mock.client->take_text()) << "request " << request;
  }
  // And the sketch really answered: PONG to the real client's PING.
  EXPECT_EQ(board.ask(sketch_frame("10", "PING", " ")), sketch_frame("10", "ACK", "PONG"));
}

TEST(AvrFirmware, AMoveDrivesTheChassisForItsTimeThroughTheMotorPins) {
  Session board(test_arduino::open_field());
  const sim::Pose start = board.board->vehicle().pose();
  EXPECT_EQ(board.ask(sketch_frame("01", "M", "20")), sketch_frame("01", "ACK", "ACCEPTED"));
  const auto& state = board.board->firmware().state();
  EXPECT_EQ(state.left_pwm, 140);  // basePWM after a boot, forward on both sides
  EXPECT_EQ(state.right_pwm, 140);
  const std::string status = board.ask(sketch_frame("02", "STATUS", " "), milliseconds(100));
  EXPECT_NE(status.find("MOT:MOVE,tleft:"), std::string::npos) << status;
  board.board->run_for(milliseconds(800));  // 20 cm at 18 ms/cm: 360 ms, then coast
  EXPECT_EQ(state.left_pwm, 0);
  EXPECT_EQ(board.ask(sketch_frame("03", "STATUS", " ")),
            sketch_frame("03", "ACK", "STATUS:V=140,DIR=stop,MOT:IDLE"));
  const sim::Pose end = board.board->vehicle().pose();
  const double moved_cm = std::hypot(end.x_m - start.x_m, end.y_m - start.y_m) * 100;
  // The chassis' calibration makes 18 ms/cm true at PWM 140; the pins
  // are read every millisecond, and the wheels ramp at 2 m/s^2.
  EXPECT_NEAR(moved_cm, 20.0, 1.5);
}

TEST(AvrFirmware, ARotationTurnsTheSidesOppositeWays) {
  Session board(test_arduino::open_field());
  EXPECT_EQ(board.ask(sketch_frame("01", "R", "90"), milliseconds(60)),
            sketch_frame("01", "ACK", "ACCEPTED"));
  const auto& state = board.board->firmware().state();
  EXPECT_EQ(state.left_pwm, 140);
  EXPECT_EQ(state.right_pwm, -140);
  board.board->run_for(milliseconds(1000));
  // Positive degrees turn right: clockwise, the heading falls.
  EXPECT_NEAR(test_arduino::heading_deg(board.board->vehicle().pose()), -90.0, 6.0);
}

sim::WorldDef wall_ahead(double gap_m) {
  sim::WorldDef world = test_arduino::open_field();
  world.arena.width_m = 6.0 + gap_m;  // the robot stands at x = 6, facing +x
  return world;
}

int number_after(const std::string& text, const std::string& key) {
  const auto at = text.find(key);
  if (at == std::string::npos) return -1;
  return std::stoi(text.substr(at + key.size()));
}

TEST(AvrFirmware, TheSonarPinsMeasureTheSimulatedDistance) {
  for (const double gap_m : {0.6, 1.5}) {
    Session board(wall_ahead(gap_m));
    test_arduino::Robot mock({}, wall_ahead(gap_m));
    mock.run_for(milliseconds(200));
    mock.client->take();
    const std::string emulated = board.ask(sketch_frame("01", "B", " "));
    mock.client->write(sketch_frame("01", "B", " "));
    mock.run_for(milliseconds(150));
    const std::string expected = mock.client->take_text();
    const int cm = number_after(emulated, "B:");
    const int mock_cm = number_after(expected, "B:");
    ASSERT_GT(mock_cm, 0) << expected;
    // pulseIn() counts its loop in whole microseconds: within 1 cm.
    EXPECT_NEAR(cm, mock_cm, 1) << emulated << " vs " << expected;
    EXPECT_EQ(board.board->firmware().state().sonar_pings, 1U);
  }
}

TEST(AvrFirmware, NoEchoBeyondTheSonarsRangeReadsZero) {
  Session board(test_arduino::open_field());
  EXPECT_EQ(board.ask(sketch_frame("01", "B", " ")), sketch_frame("01", "ACK", "B:0"));
}

TEST(AvrFirmware, TheIrPinsReadTheSimulatedSensors) {
  for (const double gap_m : {0.05, 3.0}) {
    Session board(wall_ahead(gap_m));
    test_arduino::Robot mock({}, wall_ahead(gap_m));
    mock.run_for(milliseconds(200));
    mock.client->take();
    const std::string emulated = board.ask(sketch_frame("01", "I", " "));
    mock.client->write(sketch_frame("01", "I", " "));
    mock.run_for(milliseconds(150));
    // The ADC reads back exactly the value the sensor model gives.
    EXPECT_EQ(emulated, mock.client->take_text()) << "gap " << gap_m;
  }
}

TEST(AvrFirmware, OpeningThePortResetsTheBoardAndLosesWhatCameDuringTheStartUp) {
  std::vector<std::string> log;
  AvrConfig config = sketch_config();
  config.log = [&log](const std::string& line) { log.push_back(line); };
  auto board = make_board(config);
  auto client = board->connect();
  EXPECT_EQ(board->firmware().state().boots, 2U);  // power-on, then the open
  // Inside the 66 ms start-up the UART is off: this request is lost.
  client->write(sketch_frame("01", "PING", " "));
  board->run_for(milliseconds(300));
  EXPECT_EQ(client->take_text(), "");
  client->write(sketch_frame("02", "PING", " "));
  board->run_for(milliseconds(100));
  EXPECT_EQ(client->take_text(), sketch_frame("02", "ACK", "PONG"));
  EXPECT_EQ(board->firmware().state().uart_baud, 9615U);  // 9,600 with U2X0, UBRR0 207
  // A sketch that opens its port at the line's baud draws no warning.
  EXPECT_TRUE(log.empty()) << log.front();
}

TEST(AvrFirmware, AByteIsTheSketchsTheMomentItsStopBitIsIn) {
  // With no line in between, the request's 14 bytes reach the chip at
  // once and its USART hands them over one per byte time (1.04 ms at
  // 9,600 baud, 10 bits a byte), the first at once: the last is read at
  // 13 x 1.04 = 13.54 ms. The sketch answers within microseconds and its
  // 16 bytes leave one per byte time: the last is written to UDR0 at
  // 13.54 + 15 x 1.04 = 29.17 ms, seen at the end of the board's 250 us
  // slice.
  Session board;
  board.client->write(sketch_frame("01", "PING", " "));
  const Time start = board.board->now();
  std::optional<Time> done;
  board.board->run_until_each(start + milliseconds(40), [&] {
    if (!done && board.client->text().find('$') != std::string::npos) done = board.board->now();
  });
  ASSERT_TRUE(done);
  EXPECT_EQ(board.client->take_text(), sketch_frame("01", "ACK", "PONG"));
  const double ms = std::chrono::duration<double, std::milli>(*done - start).count();
  EXPECT_GE(ms, 29.1);
  EXPECT_LE(ms, 29.5);
}

// The bytes back and the world after a session, running the driver in
// slices of `slice`.
struct Outcome {
  std::string bytes;
  std::uint64_t world_hash = 0;
  std::uint64_t cycles = 0;
};

Outcome run_session(link::Duration slice) {
  auto board = make_board(sketch_config(), wall_ahead(1.0));
  auto client = board->connect();
  const std::vector<std::pair<int, std::string>> steps{
      {200, sketch_frame("01", "V", "200")},    {300, sketch_frame("02", "M", "30")},
      {450, sketch_frame("03", "B", " ")},      {700, sketch_frame("04", "I", " ")},
      {900, sketch_frame("05", "STATUS", " ")}, {1200, sketch_frame("06", "R", "-45")},
      {1500, sketch_frame("07", "STATUS", " ")}};
  for (const auto& [at, frame] : steps) {
    while (board->now() + slice <= at_ms(at))
      board->run_for(slice);
    board->run_until(at_ms(at));
    client->write(frame);
  }
  while (board->now() + slice <= at_ms(2000))
    board->run_for(slice);
  board->run_until(at_ms(2000));
  return {client->text(), board->world().state_hash(), board->firmware().chip().cycle()};
}

TEST(AvrFirmware, TheSameSessionGivesTheSameBytesAndWorldWhateverTheDriversSlices) {
  const Outcome whole = run_session(milliseconds(2000));
  const Outcome fine = run_session(std::chrono::microseconds(700));
  const Outcome odd = run_session(milliseconds(37));
  ASSERT_NE(whole.bytes.find("ACCEPTED"), std::string::npos) << whole.bytes;
  EXPECT_EQ(fine.bytes, whole.bytes);
  EXPECT_EQ(odd.bytes, whole.bytes);
  EXPECT_EQ(fine.world_hash, whole.world_hash);
  EXPECT_EQ(odd.world_hash, whole.world_hash);
  // 2 s at 16 MHz, less the 66 ms start-up after the port opened.
  EXPECT_NEAR(static_cast<double>(whole.cycles), 2.0 * 16e6, 0.1 * 16e6);
}

std::filesystem::path patched_copy(const std::string& name, std::size_t offset,
                                   std::vector<unsigned char> bytes) {
  const auto path = std::filesystem::path(::testing::TempDir()) / name;
  std::filesystem::copy_file(HIL_TEST_SKETCH_ELF, path,
                             std::filesystem::copy_options::overwrite_existing);
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  f.seekp(static_cast<std::streamoff>(offset));
  f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  return path;
}

void expect_refused(const std::filesystem::path& elf, const std::string& words) {
  AvrConfig config;
  config.elf = elf;
  try {
    (void)config.checked();
    FAIL() << elf << " was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(elf.filename().string()), std::string::npos) << e.what();
  }
}

TEST(AvrFirmware, AnImageForAnotherChipIsRefusedWithWhatItIsFor) {
  expect_refused(patched_copy("mega.elf", 36, {6, 0, 0, 0}), "avr6 (ATmega2560-class)");
  expect_refused(patched_copy("x86.elf", 18, {62, 0}), "another processor");
  const auto text = std::filesystem::path(::testing::TempDir()) / "sketch.txt";
  std::ofstream(text) << "void setup() {}\n";
  expect_refused(text, "not an ELF file");
  expect_refused(std::filesystem::path(::testing::TempDir()) / "missing.elf", "cannot read");
}

TEST(AvrFirmware, APinMapThatCannotBeWiredIsRefused) {
  AvrConfig config = sketch_config();
  config.pins.left.pwm = *avr::board_pin("D4");  // no timer output
  EXPECT_THROW((void)config.checked(), std::invalid_argument);
}

}  // namespace
}  // namespace hil::mocks
