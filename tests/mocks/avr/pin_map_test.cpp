// The emulated Uno's pins and the pin map that wires a sketch to the
// simulated robot: the board's pin facts, the default wiring, the rules a
// map must keep, and the YAML file with errors that say where.

#include "mocks/avr/pin_map.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "config/error.hpp"

namespace hil::mocks::avr {
namespace {

using testing::HasSubstr;

// ------------------------------------------------------------ board pins

/// One pin as the ATmega328P datasheet's pin configuration (28-pin DIP)
/// and the Arduino core's "standard" variant (the tables analogWrite and
/// digitalWrite use) describe it. timer -1: no output compare.
struct UnoFact {
  const char* label;
  int number;
  char port;
  int bit;
  int timer;
  char channel;
  int adc;
};

constexpr UnoFact kUno[] = {
    {"D0", 0, 'D', 0, -1, ' ', -1},   {"D1", 1, 'D', 1, -1, ' ', -1},
    {"D2", 2, 'D', 2, -1, ' ', -1},   {"D3", 3, 'D', 3, 2, 'B', -1},
    {"D4", 4, 'D', 4, -1, ' ', -1},   {"D5", 5, 'D', 5, 0, 'B', -1},
    {"D6", 6, 'D', 6, 0, 'A', -1},    {"D7", 7, 'D', 7, -1, ' ', -1},
    {"D8", 8, 'B', 0, -1, ' ', -1},   {"D9", 9, 'B', 1, 1, 'A', -1},
    {"D10", 10, 'B', 2, 1, 'B', -1},  {"D11", 11, 'B', 3, 2, 'A', -1},
    {"D12", 12, 'B', 4, -1, ' ', -1}, {"D13", 13, 'B', 5, -1, ' ', -1},
    {"A0", 14, 'C', 0, -1, ' ', 0},   {"A1", 15, 'C', 1, -1, ' ', 1},
    {"A2", 16, 'C', 2, -1, ' ', 2},   {"A3", 17, 'C', 3, -1, ' ', 3},
    {"A4", 18, 'C', 4, -1, ' ', 4},   {"A5", 19, 'C', 5, -1, ' ', 5},
};

TEST(UnoPins, EveryPinHasTheChipsPortBitTimerAndAdcChannel) {
  for (const UnoFact& fact : kUno) {
    SCOPED_TRACE(fact.label);
    const auto pin = board_pin(fact.label);
    ASSERT_TRUE(pin.has_value());
    EXPECT_EQ(pin->name, fact.label);
    EXPECT_EQ(pin->number, fact.number);
    EXPECT_EQ(pin->port, fact.port);
    EXPECT_EQ(pin->bit, fact.bit);
    if (fact.timer < 0) {
      EXPECT_FALSE(pin->pwm.has_value());
    } else {
      ASSERT_TRUE(pin->pwm.has_value());
      EXPECT_EQ(pin->pwm->timer, fact.timer);
      EXPECT_EQ(pin->pwm->channel, fact.channel);
    }
    if (fact.adc < 0) {
      EXPECT_FALSE(pin->adc_channel.has_value());
    } else {
      EXPECT_EQ(pin->adc_channel, fact.adc);
    }
  }
}

TEST(UnoPins, LabelsAreReadWhateverTheirCase) {
  for (const UnoFact& fact : kUno) {
    std::string lower = fact.label;
    lower[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(lower[0])));
    EXPECT_EQ(board_pin(lower), board_pin(fact.label)) << lower;
  }
  EXPECT_EQ(board_pin("a5")->name, "A5");
}

TEST(UnoPins, OnlyTheUnosLabelsArePins) {
  // A6/A7 exist only on the surface-mount chip; D14..D19 are the analog
  // pins' numbers, not labels; a bare number or a port name is not a label.
  for (const char* name : {"A6", "A7", "D14", "D20", "D05", "A00", "5", "14", "PD5", "D", "A", "",
                           "DX", "D-1", "D+1", "B5", "D5 ", " D5", "D100"}) {
    EXPECT_FALSE(board_pin(name).has_value()) << "'" << name << "'";
  }
}

TEST(UnoPins, AnalogWriteWorksOnSixPins) {
  std::vector<std::string> pwm;
  for (const UnoFact& fact : kUno) {
    if (board_pin(fact.label)->pwm) pwm.emplace_back(fact.label);
  }
  EXPECT_EQ(pwm, (std::vector<std::string>{"D3", "D5", "D6", "D9", "D10", "D11"}));
}

// ------------------------------------------------------------ the default

BoardPin pin(const char* name) {
  return board_pin(name).value();
}

TEST(DefaultPinMap, IsTheProtocolDocumentsWiringTable) {
  const PinMap m = default_pin_map();
  EXPECT_EQ(m.left.pwm.name, "D5");
  EXPECT_EQ(m.left.forward.name, "A0");
  EXPECT_EQ(m.left.reverse.name, "A1");
  EXPECT_EQ(m.left.encoder, pin("D2"));
  EXPECT_EQ(m.right.pwm.name, "D6");
  EXPECT_EQ(m.right.forward.name, "A3");
  EXPECT_EQ(m.right.reverse.name, "A2");
  EXPECT_EQ(m.right.encoder, pin("D3"));
  EXPECT_EQ(m.sonar_trigger, pin("D11"));
  EXPECT_EQ(m.sonar_echo, pin("D12"));
  EXPECT_EQ(m.ir_left.analog, pin("A4"));
  EXPECT_EQ(m.ir_left.digital, pin("D7"));
  EXPECT_EQ(m.ir_right.analog, pin("A5"));
  EXPECT_EQ(m.ir_right.digital, pin("D8"));
  EXPECT_EQ(m.encoder_ticks_per_rev, 40);
  EXPECT_DOUBLE_EQ(m.wheel_diameter_m, 0.065);
  EXPECT_EQ(m.source, "the default pin map");
  // Whole pins, not only names: the PWM pins carry their timers.
  EXPECT_EQ(m.left.pwm, pin("D5"));
  EXPECT_EQ(m.left.pwm.pwm, (BoardPin::Pwm{0, 'B'}));
  EXPECT_EQ(m.right.pwm.pwm, (BoardPin::Pwm{0, 'A'}));
  EXPECT_NO_THROW(check_pin_map(m));
}

// ------------------------------------------------------------ the rules

/// The message check_pin_map throws for `map`, "" when it accepts it.
std::string rule_broken(const PinMap& map) {
  try {
    check_pin_map(map);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(CheckPinMap, PwmNeedsATimerOutput) {
  PinMap m = default_pin_map();
  m.left.pwm = pin("D4");
  EXPECT_EQ(rule_broken(m),
            "the default pin map: motors.left.pwm: D4 has no PWM output (analogWrite pins: D3, "
            "D5, D6, D9, D10, D11)");
  m.left.pwm = pin("A0");
  m.left.forward = pin("D4");
  EXPECT_THAT(rule_broken(m), HasSubstr("motors.left.pwm: A0 has no PWM output"));
  m = default_pin_map();
  m.right.pwm = pin("D13");
  EXPECT_THAT(rule_broken(m), HasSubstr("motors.right.pwm: D13 has no PWM output"));
  m.right.pwm = pin("D10");
  EXPECT_EQ(rule_broken(m), "");
}

TEST(CheckPinMap, TheSerialPinsAreTheLinks) {
  PinMap m = default_pin_map();
  m.source = "wiring.yaml";
  m.left.encoder = pin("D0");
  EXPECT_EQ(rule_broken(m),
            "wiring.yaml: motors.left.encoder: D0 belongs to the serial link to hil (D0 is RX, D1 "
            "is TX); pick another pin");
  m = default_pin_map();
  m.sonar_trigger = pin("D1");
  EXPECT_THAT(rule_broken(m), HasSubstr("sonar.trigger: D1 belongs to the serial link"));
}

TEST(CheckPinMap, AnalogIrNeedsAnAdcPin) {
  PinMap m = default_pin_map();
  m.ir_right.analog = pin("D9");
  EXPECT_EQ(rule_broken(m),
            "the default pin map: ir.right.analog: D9 is not an analog input (analog pins: "
            "A0..A5)");
  // A digital IR output may go to an analog pin: it reads as a digital input.
  m = default_pin_map();
  m.ir_right.digital = pin("D4");
  m.ir_left.digital = pin("D13");
  m.sonar_echo = pin("D10");
  EXPECT_EQ(rule_broken(m), "");
}

TEST(CheckPinMap, APinServesOneRole) {
  PinMap m = default_pin_map();
  m.sonar_echo = pin("D5");
  EXPECT_EQ(rule_broken(m),
            "the default pin map: sonar.echo: D5 is also motors.left.pwm; a pin serves one role");
  m = default_pin_map();
  m.ir_left.digital = m.ir_left.analog;
  EXPECT_THAT(rule_broken(m), HasSubstr("ir.left.digital: A4 is also ir.left.analog"));
}

TEST(CheckPinMap, UnwiredRolesTakeNoPin) {
  PinMap m = default_pin_map();
  m.sonar_trigger.reset();
  m.sonar_echo.reset();
  m.left.encoder.reset();
  m.right.encoder.reset();
  m.ir_left = {};
  m.ir_right = {};
  EXPECT_EQ(rule_broken(m), "");
}

TEST(CheckPinMap, CountsAndSizesAreAboveZero) {
  PinMap m = default_pin_map();
  m.encoder_ticks_per_rev = 0;
  EXPECT_EQ(rule_broken(m), "the default pin map: encoder_ticks_per_rev: must be above 0, got 0");
  m = default_pin_map();
  m.wheel_diameter_m = -0.065;
  EXPECT_EQ(rule_broken(m),
            "the default pin map: wheel_diameter: must be a distance above 0, got -0.065 m");
  m.wheel_diameter_m = 0;
  EXPECT_THAT(rule_broken(m), HasSubstr("wheel_diameter: must be a distance above 0"));
  m.wheel_diameter_m = std::nan("");
  EXPECT_THAT(rule_broken(m), HasSubstr("wheel_diameter: must be a distance above 0"));
}

TEST(CheckPinMap, APinMustBeTheBoardsOwn) {
  PinMap m = default_pin_map();
  m.left.forward.name = "A7";
  EXPECT_EQ(rule_broken(m),
            "the default pin map: motors.left.forward: the ATmega328P (Uno) has no pin 'A7' "
            "(pins: D0..D13, A0..A5)");
  m = default_pin_map();
  m.left.forward.bit = 3;  // A0 is PC0
  EXPECT_THAT(rule_broken(m), HasSubstr("motors.left.forward: A0 is not the board's A0 (port C, "
                                        "bit 0)"));
}

// ------------------------------------------------------------ the file

TEST(PinMapFile, ReadsEveryRole) {
  const PinMap m = parse_pin_map(R"(# a sketch wired its own way
motors:
  left:  {pwm: D9, forward: d4, reverse: A1, encoder: D2}
  right:
    pwm: D10
    forward: A3
    reverse: A2
    encoder: D3
sonar: {trigger: D11, echo: D12}
ir:
  left:  {analog: A4, digital: D7}
  right: {analog: A5, digital: D8}
encoder_ticks_per_rev: 20
wheel_diameter: 68mm
)",
                                 "pins.yaml");
  EXPECT_EQ(m.left, (MotorPins{pin("D9"), pin("D4"), pin("A1"), pin("D2")}));
  EXPECT_EQ(m.right, (MotorPins{pin("D10"), pin("A3"), pin("A2"), pin("D3")}));
  EXPECT_EQ(m.sonar_trigger, pin("D11"));
  EXPECT_EQ(m.sonar_echo, pin("D12"));
  EXPECT_EQ(m.ir_left, (IrPins{pin("A4"), pin("D7")}));
  EXPECT_EQ(m.ir_right, (IrPins{pin("A5"), pin("D8")}));
  EXPECT_EQ(m.encoder_ticks_per_rev, 20);
  EXPECT_DOUBLE_EQ(m.wheel_diameter_m, 0.068);
  EXPECT_EQ(m.source, "pins.yaml");
}

TEST(PinMapFile, TheDefaultWrittenOutIsTheDefault) {
  PinMap expected = default_pin_map();
  expected.source = "pins.yaml";
  EXPECT_EQ(parse_pin_map(R"(
motors:
  left:  {pwm: D5, forward: A0, reverse: A1, encoder: D2}
  right: {pwm: D6, forward: A3, reverse: A2, encoder: D3}
sonar: {trigger: D11, echo: D12}
ir:
  left:  {analog: A4, digital: D7}
  right: {analog: A5, digital: D8}
encoder_ticks_per_rev: 40
wheel_diameter: 65 mm
)",
                          "pins.yaml"),
            expected);
}

TEST(PinMapFile, AnEmptyFileIsTheDefault) {
  PinMap expected = default_pin_map();
  expected.source = "empty.yaml";
  EXPECT_EQ(parse_pin_map("", "empty.yaml"), expected);
  EXPECT_EQ(parse_pin_map("# nothing to change\n", "empty.yaml"), expected);
}

TEST(PinMapFile, RolesLeftOutKeepTheDefaultsPins) {
  const PinMap m = parse_pin_map("motors:\n  left: {pwm: D10}\nsonar: {echo: D13}\n", "p.yaml");
  PinMap expected = default_pin_map();
  expected.source = "p.yaml";
  expected.left.pwm = pin("D10");
  expected.sonar_echo = pin("D13");
  EXPECT_EQ(m, expected);
}

TEST(PinMapFile, NullUnwiresAnOptionalRole) {
  const PinMap m = parse_pin_map(R"(
motors:
  left: {encoder: null}
  right: {encoder: ~}
sonar: {echo: null}
ir:
  left: {digital: null}
)",
                                 "p.yaml");
  EXPECT_FALSE(m.left.encoder.has_value());
  EXPECT_FALSE(m.right.encoder.has_value());
  EXPECT_EQ(m.sonar_trigger, pin("D11"));
  EXPECT_FALSE(m.sonar_echo.has_value());
  EXPECT_EQ(m.ir_left.analog, pin("A4"));
  EXPECT_FALSE(m.ir_left.digital.has_value());
  EXPECT_EQ(m.ir_right, default_pin_map().ir_right);
}

TEST(PinMapFile, NullUnwiresAWholeSensor) {
  const PinMap no_sonar = parse_pin_map("sonar: null\nir:\n  right: ~\n", "p.yaml");
  EXPECT_FALSE(no_sonar.sonar_trigger.has_value());
  EXPECT_FALSE(no_sonar.sonar_echo.has_value());
  EXPECT_EQ(no_sonar.ir_left, default_pin_map().ir_left);
  EXPECT_EQ(no_sonar.ir_right, IrPins{});
  const PinMap no_ir = parse_pin_map("ir:\n", "p.yaml");
  EXPECT_EQ(no_ir.ir_left, IrPins{});
  EXPECT_EQ(no_ir.ir_right, IrPins{});
  // A freed pin may take another role.
  const PinMap moved = parse_pin_map("sonar: {trigger: null}\nmotors: {left: {pwm: D11}}\n", "p");
  EXPECT_EQ(moved.left.pwm, pin("D11"));
}

struct Failure {
  std::string file;
  int line = 0;
  int column = 0;
  std::string message;
};

/// The ConfigError reading `yaml` as "pins.yaml" raises.
Failure failure_of(const std::string& yaml) {
  try {
    parse_pin_map(yaml, "pins.yaml");
  } catch (const config::ConfigError& e) {
    return {e.file(), e.line(), e.column(), e.message()};
  }
  ADD_FAILURE() << "no error for:\n" << yaml;
  return {};
}

/// Reading `yaml` fails at `line`:`column` with exactly `message`.
void expect_failure(const std::string& yaml, int line, int column, const std::string& message) {
  const Failure f = failure_of(yaml);
  EXPECT_EQ(f.file, "pins.yaml") << yaml;
  EXPECT_EQ(f.line, line) << yaml;
  EXPECT_EQ(f.column, column) << yaml;
  EXPECT_EQ(f.message, message) << yaml;
}

TEST(PinMapFile, APinTheChipLacksIsReportedAtItsValue) {
  try {
    parse_pin_map("# wiring\nsonar: {echo: D12}\nmotors:\n  left: {forward: A0, pwm: A7}\n",
                  "pins.yaml");
    FAIL() << "A7 was accepted";
  } catch (const config::ConfigError& e) {
    // "  left: {forward: A0, pwm: " is 27 characters: A7 starts at column 28.
    EXPECT_STREQ(e.what(),
                 "pins.yaml:4:28: motors.left.pwm: the ATmega328P (Uno) has no pin 'A7' (pins: "
                 "D0..D13, A0..A5)");
  }
  expect_failure("ir:\n  right:\n    analog: D20\n", 3, 13,
                 "ir.right.analog: the ATmega328P (Uno) has no pin 'D20' (pins: D0..D13, A0..A5)");
}

TEST(PinMapFile, ABareNumberIsNotAPin) {
  expect_failure("sonar:\n  trigger: 9\n", 2, 12,
                 "sonar.trigger: the ATmega328P (Uno) has no pin '9' (pins: D0..D13, A0..A5); did "
                 "you mean 'D9'?");
  expect_failure("sonar:\n  trigger: 15\n", 2, 12,
                 "sonar.trigger: the ATmega328P (Uno) has no pin '15' (pins: D0..D13, A0..A5); "
                 "did you mean 'A1'?");
  expect_failure("sonar: {trigger: [D5]}\n", 1, 18,
                 "sonar.trigger: expected a pin like D5 or A0, got a list of 1");
}

TEST(PinMapFile, AnUnknownKeySuggestsTheClosest) {
  expect_failure("motors:\n  left: {pmw: D5}\n", 2, 10,
                 "motors.left: unknown key 'pmw' (allowed: pwm, forward, reverse, encoder); did "
                 "you mean 'pwm'?");
  expect_failure("sonar: {}\nwheel_diametre: 65mm\n", 2, 1,
                 "unknown key 'wheel_diametre' (a pin map takes: motors, sonar, ir, "
                 "encoder_ticks_per_rev, wheel_diameter); did you mean 'wheel_diameter'?");
  expect_failure("ir:\n  centre: {analog: A4}\n", 2, 3,
                 "ir: unknown key 'centre' (allowed: left, right)");
  expect_failure("sonar: {echo: D12, echo: D13}\n", 1, 20, "sonar: key 'echo' is given twice");
}

TEST(PinMapFile, AMotorCannotBeUnwired) {
  expect_failure("motors:\n  right:\n    pwm: null\n", 3, 10,
                 "motors.right.pwm: a motor's pwm, forward and reverse pins cannot be unwired; "
                 "give a pin, or leave the key out to keep the default's D6");
  expect_failure("motors:\n  left: {reverse: ~}\n", 2, 19,
                 "motors.left.reverse: a motor's pwm, forward and reverse pins cannot be "
                 "unwired; give a pin, or leave the key out to keep the default's A1");
  EXPECT_THAT(failure_of("motors:\n  left:\n").message,
              HasSubstr("motors.left: a motor cannot be unwired"));
  EXPECT_THAT(failure_of("motors: ~\n").message, HasSubstr("motors: the motors cannot be unwired"));
}

TEST(PinMapFile, PwmOnAPinWithoutATimerIsReportedAtThePin) {
  expect_failure("motors:\n  right: {forward: A3, pwm: D7}\n", 2, 29,
                 "motors.right.pwm: D7 has no PWM output (analogWrite pins: D3, D5, D6, D9, D10, "
                 "D11)");
}

TEST(PinMapFile, AnalogIrOnADigitalPinIsReportedAtThePin) {
  expect_failure("ir:\n  left:\n    digital: A0\n    analog: D4\n", 4, 13,
                 "ir.left.analog: D4 is not an analog input (analog pins: A0..A5)");
}

TEST(PinMapFile, TheSerialPinsAreRefused) {
  expect_failure("motors: {left: {encoder: D0}}\n", 1, 26,
                 "motors.left.encoder: D0 belongs to the serial link to hil (D0 is RX, D1 is TX); "
                 "pick another pin");
  expect_failure("ir: {right: {digital: d1}}\n", 1, 23,
                 "ir.right.digital: D1 belongs to the serial link to hil (D0 is RX, D1 is TX); "
                 "pick another pin");
}

TEST(PinMapFile, APinGivenTwoRolesIsReportedWhereTheFileGivesIt) {
  // Both roles in the file: at the later one.
  expect_failure("sonar:\n  trigger: D4\n  echo: D4\n", 3, 9,
                 "sonar.echo: D4 is also sonar.trigger; a pin serves one role");
  // The file's role comes after a role that keeps its default pin.
  expect_failure("sonar:\n  echo: D5\n", 2, 9,
                 "sonar.echo: D5 is also motors.left.pwm; a pin serves one role (motors.left.pwm "
                 "keeps the default's pin)");
  // The file's role comes before one that keeps its default pin.
  expect_failure("motors:\n  left:\n    encoder: D12\n", 3, 14,
                 "motors.left.encoder: D12 is also sonar.echo; a pin serves one role (sonar.echo "
                 "keeps the default's pin)");
}

TEST(PinMapFile, AWheelDiameterIsADistanceAboveZeroWithItsUnit) {
  EXPECT_DOUBLE_EQ(parse_pin_map("wheel_diameter: 65 mm\n", "p").wheel_diameter_m, 0.065);
  EXPECT_DOUBLE_EQ(parse_pin_map("wheel_diameter: 6.8cm\n", "p").wheel_diameter_m, 0.068);
  EXPECT_DOUBLE_EQ(parse_pin_map("wheel_diameter: 0.07m\n", "p").wheel_diameter_m, 0.07);
  for (const char* bad : {"0mm", "-65mm", "65", "0.065", "big", "mm", "65 km", "nan m"}) {
    expect_failure(std::string("# size\nwheel_diameter: ") + bad + "\n", 2, 17,
                   std::string("wheel_diameter: expected a distance above 0 with its unit (65mm, "
                               "6.5cm, 0.065m), got '") +
                       bad + "'");
  }
}

TEST(PinMapFile, EncoderTicksAreAWholeNumberAboveZero) {
  EXPECT_EQ(parse_pin_map("encoder_ticks_per_rev: 1\n", "p").encoder_ticks_per_rev, 1);
  for (const char* bad : {"0", "-40", "2.5", "many"}) {
    expect_failure(
        std::string("encoder_ticks_per_rev: ") + bad + "\n", 1, 24,
        std::string("encoder_ticks_per_rev must be a whole number >= 1, got '") + bad + "'");
  }
  expect_failure("encoder_ticks_per_rev: 99999999999\n", 1, 24,
                 "encoder_ticks_per_rev is too large, got '99999999999'");
}

TEST(PinMapFile, TheFileAndItsSectionsMustBeMaps) {
  expect_failure("- D5\n", 1, 1,
                 "a pin map must be a map with keys motors, sonar, ir, encoder_ticks_per_rev, "
                 "wheel_diameter, got a list of 1");
  expect_failure("motors:\n  left: D5\n", 2, 9,
                 "motors.left: expected a map with keys pwm, forward, reverse, encoder, got 'D5'");
  const Failure syntax = failure_of("motors: {left: [\n");
  EXPECT_THAT(syntax.message, HasSubstr("not valid YAML"));
  EXPECT_GT(syntax.line, 0);
}

TEST(PinMapFile, LoadsAFileAndNamesItInMessages) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("hil-pin-map-test-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto good = dir / "pins.yaml";
  const auto bad = dir / "bad.yaml";
  std::ofstream(good) << "motors:\n  right: {pwm: D11}\nsonar: {trigger: D9}\n";
  std::ofstream(bad) << "\n\nmotors:\n  right: {pwm: D4}\n";

  const PinMap m = load_pin_map(good);
  EXPECT_EQ(m.right.pwm, pin("D11"));
  EXPECT_EQ(m.sonar_trigger, pin("D9"));
  EXPECT_EQ(m.source, good.string());
  EXPECT_NO_THROW(check_pin_map(m));
  try {
    load_pin_map(bad);
    ADD_FAILURE() << "D4 was accepted as a PWM pin";
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.file(), bad.string());
    EXPECT_EQ(e.line(), 4);
    EXPECT_THAT(e.what(), HasSubstr(bad.string() + ":4:16: motors.right.pwm: D4 has no PWM"));
  }
  try {
    load_pin_map(dir / "missing.yaml");
    ADD_FAILURE() << "a missing file was read";
  } catch (const config::ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("cannot read the pin map"));
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace hil::mocks::avr
