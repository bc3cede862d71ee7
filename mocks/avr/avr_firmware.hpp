#pragma once
// The Arduino robot as its real firmware: a sketch's ELF on an emulated
// ATmega328P (mocks/avr/chip.hpp), its UART on the link and its pins wired
// through a pin map to the simulated differential chassis, sonar and IR
// sensors. The bytes on the wire are the firmware's own; hil adds only the
// world around the board (docs/firmware.md).

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "link/protocol_adapter.hpp"
#include "mocks/avr/chip.hpp"
#include "mocks/avr/pin_map.hpp"
#include "mocks/firmware.hpp"

namespace hil::mocks {

struct AvrConfig {
  /// The firmware image (`hil firmware build` makes one from a sketch).
  std::filesystem::path elf;
  avr::PinMap pins = avr::default_pin_map();
  /// The car profile whose framing the link, faults and captures use
  /// ("firmware" or "readme"; protocol/common/car_profile.hpp).
  std::string profile = "firmware";
  /// From a reset (power-on, or the port opening) to the first
  /// instruction: an Uno's ATmega328P with its fuses (full-swing crystal,
  /// SUT=11) waits 16K CK + 14 CK + 65 ms, about 66 ms. The Uno's
  /// bootloader is not emulated: its own wait comes on top on a real board.
  Duration startup_delay = std::chrono::microseconds(66'000);
  /// The board resets when the client opens the port (DTR auto-reset).
  bool reset_on_connect = true;
  /// The chip runs in slices of this length between driver calls; the
  /// chassis reads the motor pins at the end of each. 10 us..10 ms.
  Duration step = std::chrono::microseconds(250);
  /// How often the IR sensors' digital outputs are read from the world.
  /// step..1 s.
  Duration sensor_period = std::chrono::milliseconds(10);
  /// The sonar's echo: it rises this long after the trigger pulse ends
  /// and lasts the sound's round trip at `speed_of_sound_mps`.
  Duration echo_delay = std::chrono::microseconds(250);
  double speed_of_sound_mps = 343.0;
  /// A shorter trigger pulse starts no measurement (an HC-SR04 needs 10 us).
  Duration min_trigger = std::chrono::microseconds(10);
  /// A firmware that has not turned its UART on this long after a reset
  /// gets a warning in the log (it will never answer).
  Duration uart_warning_after = std::chrono::seconds(2);
  /// Told each warning and each simavr error (one line each).
  std::function<void(const std::string&)> log;

  /// This config, or std::invalid_argument naming the field; checks the
  /// ELF (avr::check_elf) and the pin map too.
  AvrConfig checked() const;
};

enum class ChipPhase : std::uint8_t { reset, running, halted, crashed };

struct AvrState {
  ChipPhase phase = ChipPhase::reset;
  std::uint64_t boots = 0;  ///< power-on counts as the first, then one per reset
  Time reset_at{0};         ///< the latest reset
  int left_pwm = 0;         ///< what the chassis was last given, signed
  int right_pwm = 0;
  std::uint32_t uart_baud = 0;      ///< what the firmware set; 0 while its UART is off
  std::uint64_t sonar_pings = 0;    ///< trigger pulses answered (or not, out of range)
  std::uint64_t encoder_edges = 0;  ///< edges sent on both encoder pins
};

class AvrFirmware final : public FirmwareWith<AvrConfig, AvrState> {
 public:
  /// Loads the image and powers the chip on at the world's time. Throws
  /// std::invalid_argument for a bad config or image, or a vehicle
  /// without a differential chassis.
  AvrFirmware(sim::World& world, sim::Vehicle& vehicle, AvrConfig config);
  ~AvrFirmware() override;

  std::shared_ptr<const link::ProtocolAdapter> adapter() const override;
  /// "ATmega328P RUN L+140 R+140", "ATmega328P RESET", "... HALTED".
  std::string summary() const override;

  const avr::Chip& chip() const { return *chip_; }
  /// The chip's clock at `time` while it runs (for tests).
  std::uint64_t cycle_at(Time time) const;

 protected:
  void on_connect(Time now) override;
  void on_bytes(Time now, ByteView bytes) override;
  void on_tick(Time now) override;
  std::optional<Time> next_tick() const override;

 private:
  void reset_chip(Time now);
  void run_chip(Time now);
  void update_motors();
  void update_sensors(Time now);
  void queue_encoder_edges(const avr::BoardPin& pin, double travel_m, std::uint64_t& sent,
                           bool& level);
  void on_trigger(bool level);
  void check_health(Time now);
  void note(const std::string& line);

  sim::DifferentialChassis& chassis_;
  std::unique_ptr<avr::Chip> chip_;
  std::shared_ptr<const link::ProtocolAdapter> adapter_;
  std::uint32_t link_baud_;  // the car profile's line rate, which the firmware's UART should match
  std::unique_ptr<link::FrameSplitter> from_client_;
  std::unique_ptr<link::FrameSplitter> to_client_;
  Bytes tx_;                       // what the firmware wrote in the slice being run
  Time run_from_{0};               // the chip runs from here (after a reset's delay)
  std::uint64_t epoch_cycle_ = 0;  // the chip's clock at run_from_
  Time last_tick_{0};
  Time next_sensor_read_{0};
  std::uint64_t trigger_rose_ = 0;
  bool trigger_high_ = false;
  bool echo_busy_ = false;
  std::uint64_t left_edges_ = 0, right_edges_ = 0;
  bool left_level_ = false, right_level_ = false;
  bool warned_uart_ = false;
  bool warned_baud_ = false;
  bool reported_stop_ = false;
};

}  // namespace hil::mocks
