#include "mocks/avr/pin_map.hpp"

#include <yaml-cpp/yaml.h>

#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <utility>
#include <vector>

#include "config/error.hpp"
#include "config/yaml.hpp"

namespace hil::mocks::avr {
// The whole of hil_mocks compiles as one unity source: these names stay in
// a namespace of their own.
namespace pin_map_detail {
namespace {

/// One pin of the Uno's ATmega328P (28-pin DIP). The facts are those of the
/// Arduino core's "standard" variant (variants/standard/pins_arduino.h: the
/// digital_pin_to_port, _bit_mask and _timer tables, which analogWrite()
/// and digitalWrite() use) and of the ATmega328P datasheet's pin
/// configuration (PC0..PC5 are ADC0..ADC5).
struct PinFact {
  char port;
  int bit;
  int timer;     ///< -1: no output compare on this pin
  char channel;  ///< 'A' or 'B' when `timer` is one
};

constexpr int kDigitalPins = 14;  // D0..D13
constexpr int kAnalogPins = 6;    // A0..A5, Arduino numbers 14..19
constexpr int kNoTimer = -1;

constexpr std::array<PinFact, kDigitalPins + kAnalogPins> kPins = {{
    {'D', 0, kNoTimer, ' '},  // D0: RXD, the serial link
    {'D', 1, kNoTimer, ' '},  // D1: TXD, the serial link
    {'D', 2, kNoTimer, ' '},  // D2: INT0
    {'D', 3, 2, 'B'},         // D3: OC2B
    {'D', 4, kNoTimer, ' '},  // D4
    {'D', 5, 0, 'B'},         // D5: OC0B
    {'D', 6, 0, 'A'},         // D6: OC0A
    {'D', 7, kNoTimer, ' '},  // D7
    {'B', 0, kNoTimer, ' '},  // D8
    {'B', 1, 1, 'A'},         // D9: OC1A
    {'B', 2, 1, 'B'},         // D10: OC1B
    {'B', 3, 2, 'A'},         // D11: OC2A
    {'B', 4, kNoTimer, ' '},  // D12
    {'B', 5, kNoTimer, ' '},  // D13: the on-board LED
    {'C', 0, kNoTimer, ' '},  // A0: ADC0
    {'C', 1, kNoTimer, ' '},  // A1: ADC1
    {'C', 2, kNoTimer, ' '},  // A2: ADC2
    {'C', 3, kNoTimer, ' '},  // A3: ADC3
    {'C', 4, kNoTimer, ' '},  // A4: ADC4
    {'C', 5, kNoTimer, ' '},  // A5: ADC5
}};

const char* const kChip = "the ATmega328P (Uno)";
const char* const kPinList = "D0..D13, A0..A5";

std::string label_of(int number) {
  return number < kDigitalPins ? "D" + std::to_string(number)
                               : "A" + std::to_string(number - kDigitalPins);
}

BoardPin make_pin(int number) {
  const PinFact& fact = kPins[static_cast<std::size_t>(number)];
  BoardPin pin;
  pin.name = label_of(number);
  pin.number = number;
  pin.port = fact.port;
  pin.bit = fact.bit;
  if (fact.timer != kNoTimer) pin.pwm = BoardPin::Pwm{fact.timer, fact.channel};
  if (number >= kDigitalPins) pin.adc_channel = number - kDigitalPins;
  return pin;
}

/// "D3, D5, D6, D9, D10, D11": the pins analogWrite() drives with a timer.
std::string pwm_pin_list() {
  std::string text;
  for (int n = 0; n < kDigitalPins + kAnalogPins; ++n) {
    if (kPins[static_cast<std::size_t>(n)].timer == kNoTimer) continue;
    text += (text.empty() ? "" : ", ") + label_of(n);
  }
  return text;
}

/// A pin this file knows the Uno has.
BoardPin uno(std::string_view name) {
  return *board_pin(name);
}

/// What a role asks of its pin beyond being a pin.
enum class Need { any, pwm, adc };

struct Role {
  std::string path;  ///< as the pin map file spells it: "motors.left.pwm"
  Need need;
  const BoardPin* pin;  ///< nullptr: not wired
};

std::vector<Role> roles_of(const PinMap& m) {
  const auto wired = [](const std::optional<BoardPin>& p) { return p ? &*p : nullptr; };
  return {
      {"motors.left.pwm", Need::pwm, &m.left.pwm},
      {"motors.left.forward", Need::any, &m.left.forward},
      {"motors.left.reverse", Need::any, &m.left.reverse},
      {"motors.left.encoder", Need::any, wired(m.left.encoder)},
      {"motors.right.pwm", Need::pwm, &m.right.pwm},
      {"motors.right.forward", Need::any, &m.right.forward},
      {"motors.right.reverse", Need::any, &m.right.reverse},
      {"motors.right.encoder", Need::any, wired(m.right.encoder)},
      {"sonar.trigger", Need::any, wired(m.sonar_trigger)},
      {"sonar.echo", Need::any, wired(m.sonar_echo)},
      {"ir.left.analog", Need::adc, wired(m.ir_left.analog)},
      {"ir.left.digital", Need::any, wired(m.ir_left.digital)},
      {"ir.right.analog", Need::adc, wired(m.ir_right.analog)},
      {"ir.right.digital", Need::any, wired(m.ir_right.digital)},
  };
}

/// The first rule a map breaks: `role` and the text after "ROLE: ". A pin
/// given two roles names the earlier one as `other_role`.
struct Problem {
  std::string role;
  std::string message;
  std::string other_role;
  std::string pin;
};

/// "0.065 m": the shortest text that reads back to `value`.
std::string metres_text(double value) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, ec == std::errc{} ? end : buffer) + " m";
}

Problem broken(std::string role, std::string message) {
  return Problem{std::move(role), std::move(message), {}, {}};
}

std::string two_roles(const std::string& pin, const std::string& other) {
  return pin + " is also " + other + "; a pin serves one role";
}

std::optional<Problem> find_problem(const PinMap& map) {
  const std::vector<Role> roles = roles_of(map);
  std::map<int, std::string> taken;  // Arduino pin number -> the role that has it
  for (const Role& role : roles) {
    if (role.pin == nullptr) continue;
    const BoardPin& p = *role.pin;
    const auto known = board_pin(p.name);
    if (!known) {
      return broken(role.path,
                    kChip + std::string(" has no pin '") + p.name + "' (pins: " + kPinList + ")");
    }
    if (*known != p) {
      return broken(role.path, p.name + " is not the board's " + p.name + " (port " + known->port +
                                   ", bit " + std::to_string(known->bit) +
                                   "); take pins from board_pin()");
    }
    if (p.number <= 1) {
      return broken(role.path, p.name +
                                   " belongs to the serial link to hil (D0 is RX, D1 is TX); "
                                   "pick another pin");
    }
    if (role.need == Need::pwm && !p.pwm) {
      return broken(role.path,
                    p.name + " has no PWM output (analogWrite pins: " + pwm_pin_list() + ")");
    }
    if (role.need == Need::adc && !p.adc_channel) {
      return broken(role.path, p.name + " is not an analog input (analog pins: A0..A5)");
    }
    const auto [it, fresh] = taken.emplace(p.number, role.path);
    if (!fresh) return Problem{role.path, two_roles(p.name, it->second), it->second, p.name};
  }
  if (map.encoder_ticks_per_rev <= 0) {
    return broken("encoder_ticks_per_rev",
                  "must be above 0, got " + std::to_string(map.encoder_ticks_per_rev));
  }
  if (!(map.wheel_diameter_m > 0) || !std::isfinite(map.wheel_diameter_m)) {
    return broken("wheel_diameter",
                  "must be a distance above 0, got " + metres_text(map.wheel_diameter_m));
  }
  return std::nullopt;
}

// --- the pin map file ---------------------------------------------------

const config::Keys kTopKeys = {"motors", "sonar", "ir", "encoder_ticks_per_rev", "wheel_diameter"};
const config::Keys kSideKeys = {"left", "right"};
const config::Keys kMotorKeys = {"pwm", "forward", "reverse", "encoder"};
const config::Keys kSonarKeys = {"trigger", "echo"};
const config::Keys kIrKeys = {"analog", "digital"};

/// Reads a pin map file over the default map, remembering where each role
/// it sets is written so that a rule the result breaks is reported there.
class PinMapReader {
 public:
  explicit PinMapReader(const std::string& source) : reader_(source) { map_.source = source; }

  PinMap read(const YAML::Node& doc) {
    if (!doc.IsNull()) {
      if (!doc.IsMap()) {
        reader_.fail(doc, "a pin map must be a map with keys " + config::join(kTopKeys) + ", got " +
                              config::describe(doc));
      }
      reader_.check_keys(doc, kTopKeys, "", "a pin map takes");
      if (const YAML::Node n = doc["motors"]) motors(n);
      if (const YAML::Node n = doc["sonar"]) sonar(n);
      if (const YAML::Node n = doc["ir"]) ir(n);
      if (const YAML::Node n = doc["encoder_ticks_per_rev"]) ticks(n);
      if (const YAML::Node n = doc["wheel_diameter"]) wheel_diameter(n);
    }
    if (auto problem = find_problem(map_)) report(*problem);
    return map_;
  }

 private:
  /// `node`, a map of `keys` at `path`; false when it is null (which
  /// unwires every role in it).
  bool section(const YAML::Node& node, const std::string& path, const config::Keys& keys) const {
    if (node.IsNull()) return false;
    if (!node.IsMap()) {
      reader_.fail(node, path + ": expected a map with keys " + config::join(keys) + ", got " +
                             config::describe(node));
    }
    reader_.check_keys(node, keys, path);
    return true;
  }

  void motors(const YAML::Node& node) {
    if (!section(node, "motors", kSideKeys)) {
      reader_.fail(node,
                   "motors: the motors cannot be unwired (each needs pwm, forward and "
                   "reverse pins); leave 'motors' out to keep the default's");
    }
    if (const YAML::Node n = node["left"]) motor(n, "motors.left", map_.left);
    if (const YAML::Node n = node["right"]) motor(n, "motors.right", map_.right);
  }

  void motor(const YAML::Node& node, const std::string& path, MotorPins& pins) {
    if (!section(node, path, kMotorKeys)) {
      reader_.fail(node, path +
                             ": a motor cannot be unwired (it needs pwm, forward and "
                             "reverse pins); leave it out to keep the default's");
    }
    if (const YAML::Node n = node["pwm"]) pins.pwm = required_pin(n, path + ".pwm", pins.pwm);
    if (const YAML::Node n = node["forward"])
      pins.forward = required_pin(n, path + ".forward", pins.forward);
    if (const YAML::Node n = node["reverse"])
      pins.reverse = required_pin(n, path + ".reverse", pins.reverse);
    if (const YAML::Node n = node["encoder"]) pins.encoder = optional_pin(n, path + ".encoder");
  }

  void sonar(const YAML::Node& node) {
    if (!section(node, "sonar", kSonarKeys)) {
      map_.sonar_trigger.reset();
      map_.sonar_echo.reset();
      return;
    }
    if (const YAML::Node n = node["trigger"]) map_.sonar_trigger = optional_pin(n, "sonar.trigger");
    if (const YAML::Node n = node["echo"]) map_.sonar_echo = optional_pin(n, "sonar.echo");
  }

  void ir(const YAML::Node& node) {
    if (!section(node, "ir", kSideKeys)) {
      map_.ir_left = {};
      map_.ir_right = {};
      return;
    }
    if (const YAML::Node n = node["left"]) ir_side(n, "ir.left", map_.ir_left);
    if (const YAML::Node n = node["right"]) ir_side(n, "ir.right", map_.ir_right);
  }

  void ir_side(const YAML::Node& node, const std::string& path, IrPins& pins) {
    if (!section(node, path, kIrKeys)) {
      pins = {};
      return;
    }
    if (const YAML::Node n = node["analog"]) pins.analog = optional_pin(n, path + ".analog");
    if (const YAML::Node n = node["digital"]) pins.digital = optional_pin(n, path + ".digital");
  }

  std::optional<BoardPin> optional_pin(const YAML::Node& n, const std::string& path) {
    if (n.IsNull()) return std::nullopt;
    return board_pin_at(n, path);
  }

  BoardPin required_pin(const YAML::Node& n, const std::string& path, const BoardPin& fallback) {
    if (n.IsNull()) {
      reader_.fail(n, path +
                          ": a motor's pwm, forward and reverse pins cannot be unwired; give "
                          "a pin, or leave the key out to keep the default's " +
                          fallback.name);
    }
    return board_pin_at(n, path);
  }

  BoardPin board_pin_at(const YAML::Node& n, const std::string& path) {
    if (!n.IsScalar()) {
      reader_.fail(n, path + ": expected a pin like D5 or A0, got " + config::describe(n));
    }
    const std::string& text = n.Scalar();
    auto found = board_pin(text);
    if (!found) {
      // A bare Arduino number is a likely slip; the file names pins by label.
      std::string hint;
      if (const auto number = config::parse_whole(text);
          number && *number < kDigitalPins + kAnalogPins)
        hint = "; did you mean '" + label_of(static_cast<int>(*number)) + "'?";
      reader_.fail(n, path + ": " + kChip + " has no pin " + config::describe(n) +
                          " (pins: " + kPinList + ")" + hint);
    }
    marks_[path] = n.Mark();
    return *found;
  }

  void ticks(const YAML::Node& n) {
    const std::uint64_t value = reader_.whole(n, "encoder_ticks_per_rev", 1);
    if (value > static_cast<std::uint64_t>(std::numeric_limits<int>::max()))
      reader_.fail(n, "encoder_ticks_per_rev is too large, got " + config::describe(n));
    map_.encoder_ticks_per_rev = static_cast<int>(value);
  }

  /// A distance with its unit: 65mm, 65 mm, 6.5cm, 0.065m. A bare number is
  /// refused: a wheel's size is written in millimetres as often as in
  /// metres, and a guess would be off by a thousand.
  void wheel_diameter(const YAML::Node& n) {
    const std::string what =
        "wheel_diameter: expected a distance above 0 with its unit "
        "(65mm, 6.5cm, 0.065m), got " +
        config::describe(n);
    if (!n.IsScalar()) reader_.fail(n, what);
    std::string_view text = n.Scalar();
    double per_metre = 1.0;  // dividing reads 65mm as the same double as 0.065
    if (text.ends_with("mm")) {
      per_metre = 1000.0;
      text.remove_suffix(2);
    } else if (text.ends_with("cm")) {
      per_metre = 100.0;
      text.remove_suffix(2);
    } else if (text.ends_with("m")) {
      text.remove_suffix(1);
    } else {
      reader_.fail(n, what);
    }
    while (!text.empty() && text.back() == ' ')
      text.remove_suffix(1);
    const auto value = config::parse_number(text);
    if (!value || !(*value > 0)) reader_.fail(n, what);
    map_.wheel_diameter_m = *value / per_metre;
    marks_["wheel_diameter"] = n.Mark();
  }

  /// A rule the map breaks, at the line of the role the file set, or at the
  /// file when the problem lies in the default's pins alone.
  [[noreturn]] void report(const Problem& problem) const {
    const auto mark_of = [this](const std::string& role) -> std::optional<YAML::Mark> {
      const auto it = marks_.find(role);
      if (it == marks_.end()) return std::nullopt;
      return it->second;
    };
    if (const auto mark = mark_of(problem.role)) {
      std::string message = problem.role + ": " + problem.message;
      if (!problem.other_role.empty() && !mark_of(problem.other_role))
        message += " (" + problem.other_role + " keeps the default's pin)";
      reader_.fail(*mark, message);
    }
    if (!problem.other_role.empty()) {
      if (const auto mark = mark_of(problem.other_role)) {
        reader_.fail(*mark, problem.other_role + ": " + two_roles(problem.pin, problem.role) +
                                " (" + problem.role + " keeps the default's pin)");
      }
    }
    throw config::ConfigError(reader_.file(), 0, 0, problem.role + ": " + problem.message);
  }

  config::Reader reader_;
  PinMap map_ = default_pin_map();
  std::map<std::string, YAML::Mark, std::less<>> marks_;
};

}  // namespace
}  // namespace pin_map_detail

std::optional<BoardPin> board_pin(std::string_view name) {
  using pin_map_detail::kAnalogPins;
  using pin_map_detail::kDigitalPins;
  using pin_map_detail::make_pin;
  if (name.size() < 2 || name.size() > 3) return std::nullopt;
  const char kind = static_cast<char>(std::toupper(static_cast<unsigned char>(name[0])));
  const std::string_view digits = name.substr(1);
  // "D05" is not a label; "D0" is.
  if (digits.size() > 1 && digits[0] == '0') return std::nullopt;
  const auto index = config::parse_whole(digits);
  if (!index) return std::nullopt;
  if (kind == 'D' && *index < kDigitalPins) return make_pin(static_cast<int>(*index));
  if (kind == 'A' && *index < kAnalogPins) return make_pin(kDigitalPins + static_cast<int>(*index));
  return std::nullopt;
}

PinMap default_pin_map() {
  using pin_map_detail::uno;
  PinMap map;
  map.left = MotorPins{uno("D5"), uno("A0"), uno("A1"), uno("D2")};
  map.right = MotorPins{uno("D6"), uno("A3"), uno("A2"), uno("D3")};
  map.sonar_trigger = uno("D11");
  map.sonar_echo = uno("D12");
  map.ir_left = IrPins{uno("A4"), uno("D7")};
  map.ir_right = IrPins{uno("A5"), uno("D8")};
  return map;
}

void check_pin_map(const PinMap& map) {
  if (const auto problem = pin_map_detail::find_problem(map))
    throw std::invalid_argument(map.source + ": " + problem->role + ": " + problem->message);
}

PinMap load_pin_map(const std::filesystem::path& path) {
  const std::string file = path.string();
  return parse_pin_map(config::read_file(file, "pin map"), file);
}

PinMap parse_pin_map(std::string_view yaml, const std::string& source) {
  const config::Reader reader(source);
  return pin_map_detail::PinMapReader(source).read(reader.parse(yaml));
}

}  // namespace hil::mocks::avr
