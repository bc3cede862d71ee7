#pragma once
// Where a sketch's pins meet the simulated robot: which Arduino pins drive
// the motors and which the sonar, IR sensors and wheel encoders answer on,
// for an Uno-class board (ATmega328P). The default is the protocol
// document's wiring table; a sketch wired otherwise brings a small YAML
// file (docs/firmware.md, "The pin map").

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace hil::mocks::avr {

/// One pin of the board as the chip sees it.
struct BoardPin {
  std::string name;  ///< "D5", "A0": the board's own label
  int number = 0;    ///< the Arduino pin number: D0..D13 are 0..13, A0..A5 are 14..19
  char port = 'B';   ///< the chip's I/O port: 'B', 'C' or 'D'
  int bit = 0;       ///< 0..7 within the port
  /// The timer output compare that analogWrite() uses on this pin.
  struct Pwm {
    int timer = 0;       ///< 0, 1 or 2
    char channel = 'A';  ///< 'A' or 'B' (OCnA, OCnB)
    friend bool operator==(const Pwm&, const Pwm&) = default;
  };
  std::optional<Pwm> pwm;
  std::optional<int> adc_channel;  ///< 0..5 on the analog pins
  friend bool operator==(const BoardPin&, const BoardPin&) = default;
};

/// The board pin called `name` ("D0".."D13", "A0".."A5", case-insensitive),
/// or nullopt when an Uno-class ATmega328P has no such pin (A6 and A7 are
/// only on the surface-mount package, not on the Uno).
std::optional<BoardPin> board_pin(std::string_view name);

/// A motor driver channel: PWM duty on one pin, direction on two.
struct MotorPins {
  BoardPin pwm;                     ///< must have a timer output (analogWrite)
  BoardPin forward;                 ///< high with `reverse` low: the side drives forward
  BoardPin reverse;                 ///< high with `forward` low: backward; both or neither: stopped
  std::optional<BoardPin> encoder;  ///< pulsed as the side's wheels turn
  friend bool operator==(const MotorPins&, const MotorPins&) = default;
};

struct IrPins {
  std::optional<BoardPin> analog;   ///< must be an analog pin (ADC channel)
  std::optional<BoardPin> digital;  ///< high while the sensor sees an obstacle
  friend bool operator==(const IrPins&, const IrPins&) = default;
};

struct PinMap {
  MotorPins left;
  MotorPins right;
  std::optional<BoardPin> sonar_trigger;  ///< a pulse here starts a measurement
  std::optional<BoardPin> sonar_echo;     ///< answered with the echo pulse
  IrPins ir_left;
  IrPins ir_right;
  /// Encoder edges per wheel revolution, counting both edges of each slot;
  /// > 0.
  int encoder_ticks_per_rev = 40;
  /// Wheel diameter that turns a side's travel into revolutions; > 0.
  double wheel_diameter_m = 0.065;
  /// Where the map came from, for messages: a file, or "the default pin map".
  std::string source = "the default pin map";
  friend bool operator==(const PinMap&, const PinMap&) = default;
};

/// The protocol document's wiring table (seed 003, "Pin mapping"): left
/// motor PWM D5, FWD A0, REV A1, encoder D2; right motor PWM D6, FWD A3,
/// REV A2, encoder D3; sonar trigger D11, echo D12; IR analog A4/A5,
/// digital D7/D8.
PinMap default_pin_map();

/// Checks that the map can be wired: no pin given two roles, no role on
/// the UART pins D0/D1 (the link's), PWM only on a pin with a timer output,
/// analog IR only on an ADC pin, counts and sizes above zero, every pin
/// the board's own (as board_pin() gives it). Throws std::invalid_argument
/// naming `map.source` and the role as a pin map file spells it: "the
/// default pin map: motors.left.pwm: D4 has no PWM output (analogWrite
/// pins: D3, D5, D6, D9, D10, D11)".
void check_pin_map(const PinMap& map);

/// Reads a pin map file (YAML) and checks it; roles it leaves out keep the
/// default's pins, and `null` unwires an optional one (an encoder, a sonar
/// pin, an IR output, or a whole `sonar`, `ir` or `ir.left` section; a
/// motor's pwm, forward and reverse pins cannot be unwired). Every key is
/// optional:
///
///     motors:
///       left:  {pwm: D5, forward: A0, reverse: A1, encoder: D2}
///       right: {pwm: D6, forward: A3, reverse: A2, encoder: D3}
///     sonar: {trigger: D11, echo: D12}
///     ir:
///       left:  {analog: A4, digital: D7}
///       right: {analog: A5, digital: D8}
///     encoder_ticks_per_rev: 40
///     wheel_diameter: 65mm        # a unit is required: mm, cm or m
///
/// Pins are written by their labels, in either case. Throws
/// config::ConfigError at the line of the problem: a file that does not
/// load, an unknown key, a pin the chip lacks, a role its pin cannot serve
/// (at the pin the file gives; a clash with a role that keeps its default
/// pin is reported at the file's side of it). The map's `source` is `path`.
PinMap load_pin_map(const std::filesystem::path& path);
/// The same from text; `source` names it in messages.
PinMap parse_pin_map(std::string_view yaml, const std::string& source);

}  // namespace hil::mocks::avr
