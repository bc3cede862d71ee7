#pragma once
// The Arduino serial robot's firmware as a mock: framed ^SEQ|CMD|PAYLOAD*CS$
// requests answered with ACK/NACK, time-based moves of a differential
// chassis, sonar and IR reads, a reset each time the port opens
// (docs/mocks/arduino.md).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "link/protocol_adapter.hpp"
#include "mocks/firmware.hpp"
#include "protocol/arduino/codec.hpp"
#include "protocol/arduino/message.hpp"
#include "protocol/arduino/sketch.hpp"

namespace hil::mocks {

/// How the mock Arduino firmware behaves where real sketches could differ.
/// The defaults are the sketch the protocol document describes.
struct ArduinoConfig {
  /// Which board to be: the real sketch (`firmware`: its parser, its reply
  /// texts, malformed frames dropped without an answer) or the README's
  /// examples (`readme`). docs/mocks/arduino.md has both.
  protocol::arduino::Dialect dialect = protocol::arduino::kDefaultDialect;
  /// Duty after a boot, and what V sets (the sketch's basePWM), 0..255.
  int base_pwm = 140;
  /// M runs for |cm| * this many milliseconds (MS_PER_CM), > 0 and <= 1000.
  double ms_per_cm = 18.0;
  /// R runs for |deg| * this many milliseconds (MS_PER_DEG), > 0 and <= 1000.
  double ms_per_deg = 6.0;
  /// false (the sketch): a move lasts the same time at any V, so it over- or
  /// undershoots away from the calibration PWM. true: the time is scaled by
  /// base_pwm / V, so the distance holds at any V above 0.
  bool scale_duration_with_pwm = false;
  /// The board resets when the client opens the port (DTR auto-reset).
  /// false: a board without auto-reset keeps its state across sessions.
  bool reset_on_connect = true;
  /// When a request arrives again with the same bytes (same SEQ) as the one
  /// answered last, send the same answer again without acting on it twice.
  /// The sketch does not do this: a repeated M restarts the move.
  bool repeat_answer_for_repeated_request = false;
  /// What B answers when no echo comes back within the sonar's range
  /// (pulseIn timing out reads 0 on most sketches).
  int no_echo_cm = 0;
  /// The ACK text for PING in the readme dialect (the sketch says PONG).
  std::string ping_reply = "OK";
  /// NACK code for V, M and R while the firmware is in its fault state.
  std::string fault_code = "FAULT";
  /// NACK code for a command a Reject behaviour refuses.
  std::string reject_code = "BUSY";
  /// Longest request frame the board takes in, markers included; longer
  /// ones are dropped without an answer. At least 10.
  std::size_t max_frame_bytes = protocol::arduino::kFirmwareMaxFrameBytes;
  /// false: a lowercase checksum is answered NACK BAD_CS.
  bool accept_lowercase_checksum = true;
  /// Period of the control loop that ends moves and keeps the simulation
  /// running while the robot moves. Ticks fall on multiples of it.
  Duration control_period = link::milliseconds(10);
};

/// What the robot is doing.
enum class ArduinoMotion : std::uint8_t { idle, move, rotate };

/// The firmware's state, read-only for tests and the status line.
struct ArduinoState {
  /// The V setting: the duty the next M or R drives at.
  int pwm = 140;
  ArduinoMotion motion = ArduinoMotion::idle;
  /// The running move's argument: cm for M, degrees for R.
  int motion_arg = 0;
  /// The duty the running move drives at (V when it started).
  int motion_pwm = 0;
  /// The sketch's lastDir: +1 after a forward move starts, -1 after a
  /// backward one, 0 after a stop, a rotation or a move's end. STATUS
  /// shows it as DIR=fwd, rev or stop.
  int last_dir = 0;
  Time motion_started{0};
  Time motion_ends{0};
  /// Boots so far: power-on counts as the first, then one per reset.
  std::uint64_t boots = 0;
  Time booted_at{0};
  /// SEQ of the last answer sent since the boot; empty right after a boot.
  std::optional<std::uint8_t> last_seq;
};

class ArduinoFirmware final : public FirmwareWith<ArduinoConfig, ArduinoState> {
 public:
  /// Throws std::invalid_argument when the vehicle has no differential
  /// chassis or a config value is out of its range.
  ArduinoFirmware(sim::World& world, sim::Vehicle& vehicle, ArduinoConfig config = {});

  std::string summary() const override;

  bool moving() const { return state_.motion != ArduinoMotion::idle; }

  /// The STATUS answer at `now` in the configured dialect.
  std::string status_text(Time now) const;
  /// The HELP answer of a dialect.
  static std::string_view help_text(
      protocol::arduino::Dialect dialect = protocol::arduino::kDefaultDialect);

 protected:
  void on_connect(Time now) override;
  void on_bytes(Time now, ByteView bytes) override;
  void on_tick(Time now) override;
  std::optional<Time> next_tick() const override;
  void on_fault(Time now, bool entered) override;

 private:
  using Message = protocol::arduino::Message;

  void boot(Time now);
  void end_due_motion(Time now);
  /// "IDLE", "MOVING M:25" or "FAULT": the first words of STATUS.
  std::string activity() const;
  void handle_frame(Time now, const protocol::Frame<Message>& frame);
  void handle_error(const protocol::DecodeError& error);
  /// Acts on a request and returns the answer's body.
  protocol::arduino::Body execute(Time now, const Message& request);
  void start_motion(Time now, ArduinoMotion motion, int arg);
  void stop_motion();
  void answer(const Message& message);
  std::string ir_text() const;

  // The real sketch's receive path and commands (mocks/arduino_sketch.cpp).
  struct SketchReply {
    bool ack = true;
    std::string text;
  };
  void receive_as_sketch(Time now, ByteView bytes);
  void handle_sketch_request(Time now, const Bytes& raw,
                             const protocol::arduino::SketchRequest& request);
  SketchReply execute_sketch(Time now, std::string_view command, std::string_view payload);
  void sketch_answer(std::string_view seq, bool ack, std::string_view text);
  std::string sketch_status(Time now) const;
  std::string sketch_ir() const;

  sim::DifferentialChassis& chassis_;
  protocol::arduino::Decoder decoder_;
  std::vector<protocol::arduino::Item> items_;
  protocol::arduino::SketchReceiver sketch_;
  std::vector<protocol::arduino::SketchFrame> sketch_frames_;
  Time last_tick_{0};
  protocol::Bytes last_request_;
  std::string last_answer_;
};

}  // namespace hil::mocks
