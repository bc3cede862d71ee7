#pragma once
// Typed commands of the Leka Alpha robot protocol (docs/protocols/leka.md):
// what a master sends to the robot, one command group per frame.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "protocol/common/bytes.hpp"

namespace hil::protocol::leka {

/// The two conventions of the Leka Alpha spec (the car's profiles, see
/// protocol/common/car_profile.hpp). `readme`: the command table and worked
/// examples of the spec's README. `comspecs_v3`: the command ids of the
/// same release's machine-readable tables (one more command, led.ear.range,
/// shifts the LED ids after it) and an 8-bit checksum over length and
/// group (docs/protocols/leka.md, "Profiles").
enum class Dialect : std::uint8_t { readme, comspecs_v3 };

/// "readme" or "comspecs-v3".
std::string_view to_string(Dialect dialect);
/// The dialect of a Leka profile name; empty is the default profile.
/// Throws protocol::ProfileError for a name that is not a Leka profile.
Dialect dialect_named(std::string_view profile);

/// The seed does not define spin or direction bytes; this profile uses 0 and 1.
inline constexpr std::uint8_t kSpinForward = 0;
inline constexpr std::uint8_t kSpinBackward = 1;

/// An LED colour, one byte per channel (0 = off, 255 = full).
struct Rgb {
  std::uint8_t red = 0;
  std::uint8_t green = 0;
  std::uint8_t blue = 0;
  friend bool operator==(const Rgb&, const Rgb&) = default;
};

/// 0x70: asks the robot to identify itself (no data).
struct Info {
  friend bool operator==(const Info&, const Info&) = default;
};
/// 0xFD: all LEDs off.
struct StopLed {
  friend bool operator==(const StopLed&, const StopLed&) = default;
};
/// 0xFE: both motors off.
struct StopMotor {
  friend bool operator==(const StopMotor&, const StopMotor&) = default;
};
/// 0xFF: LEDs and motors off.
struct StopRobot {
  friend bool operator==(const StopRobot&, const StopRobot&) = default;
};
/// 0x11: both ears in one colour.
struct EarAll {
  Rgb color;
  friend bool operator==(const EarAll&, const EarAll&) = default;
};
/// led.ear.range (comspecs-v3 only, 0x12): ears first..last in one colour.
struct EarRange {
  std::uint8_t first = 0;
  std::uint8_t last = 0;
  Rgb color;
  friend bool operator==(const EarRange&, const EarRange&) = default;
};
/// 0x12 (comspecs-v3: 0x13): one ear (led 0 or 1).
struct EarSingle {
  std::uint8_t led = 0;
  Rgb color;
  friend bool operator==(const EarSingle&, const EarSingle&) = default;
};
/// 0x13 (comspecs-v3: 0x14): the whole belt in one colour.
struct BeltAll {
  Rgb color;
  friend bool operator==(const BeltAll&, const BeltAll&) = default;
};
/// 0x14 (comspecs-v3: 0x15): belt LEDs first..last (inclusive) in one colour.
struct BeltRange {
  std::uint8_t first = 0;
  std::uint8_t last = 0;
  Rgb color;
  friend bool operator==(const BeltRange&, const BeltRange&) = default;
};
/// 0x15 (comspecs-v3: 0x16): one belt LED.
struct BeltSingle {
  std::uint8_t led = 0;
  Rgb color;
  friend bool operator==(const BeltSingle&, const BeltSingle&) = default;
};
/// 0x21: both motors, same direction and speed.
struct MotorAll {
  std::uint8_t direction = kSpinForward;  ///< kSpinForward or kSpinBackward
  std::uint8_t speed = 0;                 ///< 0..255, share of full speed (no unit in the seed)
  friend bool operator==(const MotorAll&, const MotorAll&) = default;
};
/// 0x22: each motor its own spin and speed.
struct MotorDuo {
  std::uint8_t left_spin = kSpinForward;
  std::uint8_t left_speed = 0;  ///< 0..255
  std::uint8_t right_spin = kSpinForward;
  std::uint8_t right_speed = 0;  ///< 0..255
  friend bool operator==(const MotorDuo&, const MotorDuo&) = default;
};
/// 0x23: left motor only.
struct MotorLeft {
  std::uint8_t spin = kSpinForward;
  std::uint8_t speed = 0;  ///< 0..255
  friend bool operator==(const MotorLeft&, const MotorLeft&) = default;
};
/// 0x24: right motor only.
struct MotorRight {
  std::uint8_t spin = kSpinForward;
  std::uint8_t speed = 0;  ///< 0..255
  friend bool operator==(const MotorRight&, const MotorRight&) = default;
};
/// 0x50: plays a motivator behaviour, id 0x51..0x55.
struct Motivator {
  std::uint8_t id = 0x51;
  friend bool operator==(const Motivator&, const Motivator&) = default;
};
/// 0x40: plays a guidance behaviour, id 0x41..0x4F.
struct Guidance {
  std::uint8_t id = 0x41;
  friend bool operator==(const Guidance&, const Guidance&) = default;
};

using Command = std::variant<Info, StopLed, StopMotor, StopRobot, EarAll, EarRange, EarSingle,
                             BeltAll, BeltRange, BeltSingle, MotorAll, MotorDuo, MotorLeft,
                             MotorRight, Motivator, Guidance>;

/// What one frame carries: one or more commands, run by the robot in order.
struct CommandGroup {
  std::vector<Command> commands;
  friend bool operator==(const CommandGroup&, const CommandGroup&) = default;
};

/// The decoder's message is a whole command group (one per frame).
using Message = CommandGroup;

/// Static facts about one command: its ids, dotted name and data size.
struct CommandSpec {
  std::string_view name;  ///< "led.belt.single", as in the command table
  /// The wire id in each dialect; 0 where the dialect has no such command.
  std::uint8_t readme_id;
  std::uint8_t comspecs_id;
  std::size_t data_bytes;      ///< bytes after the id
  std::string_view data_help;  ///< the data fields in order, for help texts

  std::uint8_t id(Dialect d) const { return d == Dialect::readme ? readme_id : comspecs_id; }
  bool in(Dialect d) const { return id(d) != 0; }
};

/// Every known command, in the order of Command's alternatives.
extern const std::array<CommandSpec, 16> kCommandSpecs;

/// The command with wire id `id` in `dialect`, or null.
const CommandSpec* find_spec(std::uint8_t id, Dialect dialect = Dialect::readme);
const CommandSpec* find_spec(std::string_view name);
const CommandSpec& spec_of(const Command& c);

/// The data bytes of a command (without its id).
Bytes data_of(const Command& c);
/// Builds the command of `spec` from exactly spec.data_bytes data bytes.
/// Returns nullopt when `data` has another size.
std::optional<Command> make_command(const CommandSpec& spec, ByteView data);

/// Limits the seed gives (or leaves to this profile) for id and spin bytes.
struct ValueLimits {
  /// Highest belt LED id. The seed's table says 0x19, its 20-LED example
  /// stops at 0x13; this profile follows the example (see the doc).
  std::uint8_t max_belt_led_id = 0x13;
};

/// The first value in `c` outside its range, as a sentence; nullopt when all fit.
std::optional<std::string> range_problem(const Command& c, const ValueLimits& limits = {});

/// One-line description, e.g. "led.belt.single led=0 rgb=(255,0,0)".
std::string describe(const Command& c);
/// The commands joined with " + ", e.g. "led.ear.all rgb=(255,0,0) + motor.all ...".
std::string describe(const CommandGroup& g);

}  // namespace hil::protocol::leka
