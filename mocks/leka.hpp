#pragma once
// The Leka Alpha robot's firmware as a mock: command frames read from a
// 128-byte serial buffer on a fixed main loop, ear and belt LEDs, two motors
// driving a differential chassis, motivator and guidance behaviours, and an
// info line, the only thing the robot ever sends (docs/mocks/leka.md).

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "link/protocol_adapter.hpp"
#include "mocks/firmware.hpp"
#include "protocol/leka/codec.hpp"
#include "protocol/leka/message.hpp"

namespace hil::mocks {

/// How the mock Leka firmware behaves where real firmwares could differ.
struct LekaConfig {
  /// Command ids and checksum the robot reads: the README's (readme, the
  /// default) or the spec's tables (comspecs_v3); docs/protocols/leka.md.
  protocol::leka::Dialect dialect = protocol::leka::Dialect::readme;
  /// Period of the firmware's main loop: each pass reads the serial buffer
  /// and runs the commands found. Passes fall on multiples of it. > 0.
  Duration loop_period = link::milliseconds(10);
  /// Size of the robot's serial buffer (7..261). Bytes that arrive while it
  /// holds this many unparsed bytes are lost; it is also the frame bound.
  std::size_t serial_buffer_bytes = protocol::leka::kMaxFrameBytes;
  /// Highest belt LED id; the belt has this many LEDs plus one.
  std::uint8_t max_belt_led_id = 0x13;
  /// false: a frame with an out-of-range value (LED id, spin, behaviour id)
  /// is dropped. true: it runs, values clamped (see the doc).
  bool accept_out_of_range = false;
  /// Named in the info line; printable ASCII without spaces.
  std::string robot_name = "leka";
  std::string firmware_version = "1.0.0";
  /// How long a motivator plays (> 0).
  Duration motivator_duration = link::seconds(2);
  /// How long a guidance plays (> 0).
  Duration guidance_duration = link::seconds(3);
  /// A motivator's running light moves one belt LED on per step (> 0).
  Duration chaser_step = link::milliseconds(100);
  /// A motivator turns on the spot, changing direction this often (> 0).
  Duration motivator_turn = link::milliseconds(500);
  /// Speed byte of a motivator's turn (0..255).
  std::uint8_t motivator_speed = 96;
  /// A guidance's LEDs are on for this long, then off as long (> 0).
  Duration guidance_blink = link::milliseconds(500);
  /// false (a serial slave that cannot tell the link dropped): the robot
  /// goes on as it was. true: a disconnect stops the motors and a behaviour.
  bool stop_on_disconnect = false;
};

/// One motor as the last command (or behaviour) set it.
struct LekaMotor {
  std::uint8_t spin = protocol::leka::kSpinForward;  ///< kSpinForward or kSpinBackward
  std::uint8_t speed = 0;                            ///< 0..255
  friend bool operator==(const LekaMotor&, const LekaMotor&) = default;
};

enum class LekaBehaviourKind : std::uint8_t { motivator, guidance };

/// A behaviour playing now.
struct LekaBehaviour {
  LekaBehaviourKind kind = LekaBehaviourKind::motivator;
  std::uint8_t id = 0;  ///< 0x51..0x55 (motivator) or 0x41..0x4F (guidance)
  Time started{0};
  Time ends{0};  ///< the first pass at or after this ends it
  friend bool operator==(const LekaBehaviour&, const LekaBehaviour&) = default;
};

/// What the robot did with its input so far (beyond FirmwareStats).
struct LekaCounters {
  std::uint64_t commands_run = 0;      ///< commands that took effect
  std::uint64_t info_answers = 0;      ///< info lines sent (or dropped with no client)
  std::uint64_t bytes_lost = 0;        ///< arrived while the serial buffer was full
  std::uint64_t garbage = 0;           ///< runs of bytes outside any frame
  std::uint64_t bad_checksum = 0;      ///< frames whose checksum did not match
  std::uint64_t oversized = 0;         ///< length byte over the frame bound
  std::uint64_t bad_format = 0;        ///< length 0, or a command cut by the group's end
  std::uint64_t unknown_code = 0;      ///< a command id not in the table
  std::uint64_t bad_value = 0;         ///< a value out of range, frame dropped
  std::uint64_t tolerated = 0;         ///< out-of-range frames run (accept_out_of_range)
  std::uint64_t refused_in_fault = 0;  ///< motor and motivator commands not run in fault
  std::uint64_t behaviours_started = 0;
  std::uint64_t behaviours_interrupted = 0;  ///< ended early by a command or the fault
  friend bool operator==(const LekaCounters&, const LekaCounters&) = default;
};

/// The robot's state, read-only for tests and the status line.
struct LekaState {
  /// What the LEDs show now: the last commands' colours, or a behaviour's.
  std::array<protocol::leka::Rgb, 2> ears{};
  std::vector<protocol::leka::Rgb> belt;
  LekaMotor left;
  LekaMotor right;
  std::optional<LekaBehaviour> behaviour;
  /// Bytes in the serial buffer not yet parsed, a partial frame included.
  std::size_t serial_buffered = 0;
  LekaCounters counters;
};

class LekaFirmware final : public FirmwareWith<LekaConfig, LekaState> {
 public:
  /// Throws std::invalid_argument when the vehicle has no differential
  /// chassis or a config value is out of its range.
  LekaFirmware(sim::World& world, sim::Vehicle& vehicle, LekaConfig config = {});

  std::string summary() const override;

  /// The info line as the robot would send it now.
  std::string info_text() const;
  /// Signed chassis duty for a motor: the speed byte scaled to the chassis'
  /// PWM range, negative when spinning backward.
  int pwm_of(const LekaMotor& motor) const;

 protected:
  void on_disconnect(Time now) override;
  void on_bytes(Time now, ByteView bytes) override;
  void on_tick(Time now) override;
  std::optional<Time> next_tick() const override;
  void on_fault(Time now, bool entered) override;

 private:
  using Command = protocol::leka::Command;

  bool busy() const;
  Time grid_at_or_after(Time t) const;
  /// Runs the main loop's passes due before `now` (and at `now` when
  /// include_now), skipping passes that would find nothing to do.
  void run_due_passes(Time now, bool include_now);
  void run_pass(Time at);
  void handle_item(Time at, const protocol::leka::Item& item);
  void run_command(Time at, const Command& command);
  void execute(Time at, const Command& command);
  void set_motors(LekaMotor left, LekaMotor right);
  void stop_motors() { set_motors({}, {}); }
  void show_base_leds();
  void start_behaviour(Time at, LekaBehaviourKind kind, std::uint8_t id);
  void end_behaviour(bool interrupted);
  void play_behaviour(Time at);

  sim::DifferentialChassis& chassis_;
  protocol::leka::Decoder decoder_;
  std::vector<protocol::leka::Item> items_;
  Bytes serial_;  // received, not yet handed to the parser
  Bytes held_;    // the bytes the parser holds (a partial frame or garbage)
  // The LEDs as the commands set them; a behaviour shows its own pattern
  // over them and they come back when it ends.
  std::array<protocol::leka::Rgb, 2> base_ears_{};
  std::vector<protocol::leka::Rgb> base_belt_;
  Time next_loop_{0};
};

}  // namespace hil::mocks
