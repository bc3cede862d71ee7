#include "protocol/leka/message.hpp"

#include <cstdio>

#include "protocol/common/car_profile.hpp"
#include "protocol/common/overloaded.hpp"

namespace hil::protocol::leka {

// Ids: the README's table (readme) and the spec's YAML / Swift tables of
// the same release (comspecs-v3), leka/LKAlphaComSpecs at 381046f.
const std::array<CommandSpec, 16> kCommandSpecs = {{
    {"info", 0x70, 0x70, 0, ""},
    {"stop.led", 0xFD, 0xFD, 0, ""},
    {"stop.motor", 0xFE, 0xFE, 0, ""},
    {"stop.robot", 0xFF, 0xFF, 0, ""},
    {"led.ear.all", 0x11, 0x11, 3, "R G B"},
    {"led.ear.range", 0, 0x12, 5, "FIRST(0..1) LAST(0..1) R G B"},
    {"led.ear.single", 0x12, 0x13, 4, "ID(0..1) R G B"},
    {"led.belt.all", 0x13, 0x14, 3, "R G B"},
    {"led.belt.range", 0x14, 0x15, 5, "FIRST LAST R G B"},
    {"led.belt.single", 0x15, 0x16, 4, "ID R G B"},
    {"motor.all", 0x21, 0x21, 2, "DIRECTION(0|1) SPEED"},
    {"motor.duo", 0x22, 0x22, 4, "LEFT_SPIN(0|1) LEFT_SPEED RIGHT_SPIN(0|1) RIGHT_SPEED"},
    {"motor.left", 0x23, 0x23, 2, "SPIN(0|1) SPEED"},
    {"motor.right", 0x24, 0x24, 2, "SPIN(0|1) SPEED"},
    {"motivator", 0x50, 0x50, 1, "ID(0x51..0x55)"},
    {"guidance", 0x40, 0x40, 1, "ID(0x41..0x4F)"},
}};
static_assert(std::variant_size_v<Command> == kCommandSpecs.size(),
              "one row of kCommandSpecs per alternative of Command, in order");

std::string_view to_string(Dialect dialect) {
  return dialect == Dialect::readme ? "readme" : "comspecs-v3";
}

Dialect dialect_named(std::string_view profile) {
  const CarProfile& p = find_car_profile("leka", profile);
  return p.name == "comspecs-v3" ? Dialect::comspecs_v3 : Dialect::readme;
}

namespace {

Rgb rgb_at(ByteView d, std::size_t i) {
  return Rgb{d[i], d[i + 1], d[i + 2]};
}

std::string rgb_text(const Rgb& c) {
  return "rgb=(" + std::to_string(c.red) + "," + std::to_string(c.green) + "," +
         std::to_string(c.blue) + ")";
}

std::string spin_text(std::uint8_t spin) {
  if (spin == kSpinForward) return "forward";
  if (spin == kSpinBackward) return "backward";
  return "spin?" + hex_literal(spin);
}

std::optional<std::string> check_spin(std::uint8_t spin, const char* field) {
  if (spin <= kSpinBackward) return std::nullopt;
  return std::string(field) + " " + hex_literal(spin) + " is neither 0 (forward) nor 1 (backward)";
}

std::optional<std::string> check_belt(std::uint8_t led, const char* field, const ValueLimits& l) {
  if (led <= l.max_belt_led_id) return std::nullopt;
  return std::string(field) + " " + hex_literal(led) + " outside 0x00.." +
         hex_literal(l.max_belt_led_id);
}

}  // namespace

const CommandSpec* find_spec(std::uint8_t id, Dialect dialect) {
  if (id == 0) return nullptr;
  for (const auto& s : kCommandSpecs) {
    if (s.id(dialect) == id) return &s;
  }
  return nullptr;
}

const CommandSpec* find_spec(std::string_view name) {
  for (const auto& s : kCommandSpecs) {
    if (s.name == name) return &s;
  }
  return nullptr;
}

const CommandSpec& spec_of(const Command& c) {
  // Every alternative of Command has a row in the table, in order.
  return kCommandSpecs[c.index()];
}

Bytes data_of(const Command& c) {
  const auto rgb = [](const Rgb& v) { return Bytes{v.red, v.green, v.blue}; };
  return std::visit(
      Overloaded{[](const Info&) { return Bytes{}; }, [](const StopLed&) { return Bytes{}; },
                 [](const StopMotor&) { return Bytes{}; }, [](const StopRobot&) { return Bytes{}; },
                 [&](const EarAll& v) { return rgb(v.color); },
                 [](const EarRange& v) {
                   return Bytes{v.first, v.last, v.color.red, v.color.green, v.color.blue};
                 },
                 [](const EarSingle& v) {
                   return Bytes{v.led, v.color.red, v.color.green, v.color.blue};
                 },
                 [&](const BeltAll& v) { return rgb(v.color); },
                 [](const BeltRange& v) {
                   return Bytes{v.first, v.last, v.color.red, v.color.green, v.color.blue};
                 },
                 [](const BeltSingle& v) {
                   return Bytes{v.led, v.color.red, v.color.green, v.color.blue};
                 },
                 [](const MotorAll& v) {
                   return Bytes{v.direction, v.speed};
                 },
                 [](const MotorDuo& v) {
                   return Bytes{v.left_spin, v.left_speed, v.right_spin, v.right_speed};
                 },
                 [](const MotorLeft& v) {
                   return Bytes{v.spin, v.speed};
                 },
                 [](const MotorRight& v) {
                   return Bytes{v.spin, v.speed};
                 },
                 [](const Motivator& v) { return Bytes{v.id}; },
                 [](const Guidance& v) { return Bytes{v.id}; }},
      c);
}

std::optional<Command> make_command(const CommandSpec& spec, ByteView d) {
  if (d.size() != spec.data_bytes) return std::nullopt;
  // The row's place in kCommandSpecs is the alternative's index in Command.
  switch (&spec - kCommandSpecs.data()) {
    case 0:
      return Info{};
    case 1:
      return StopLed{};
    case 2:
      return StopMotor{};
    case 3:
      return StopRobot{};
    case 4:
      return EarAll{rgb_at(d, 0)};
    case 5:
      return EarRange{d[0], d[1], rgb_at(d, 2)};
    case 6:
      return EarSingle{d[0], rgb_at(d, 1)};
    case 7:
      return BeltAll{rgb_at(d, 0)};
    case 8:
      return BeltRange{d[0], d[1], rgb_at(d, 2)};
    case 9:
      return BeltSingle{d[0], rgb_at(d, 1)};
    case 10:
      return MotorAll{d[0], d[1]};
    case 11:
      return MotorDuo{d[0], d[1], d[2], d[3]};
    case 12:
      return MotorLeft{d[0], d[1]};
    case 13:
      return MotorRight{d[0], d[1]};
    case 14:
      return Motivator{d[0]};
    case 15:
      return Guidance{d[0]};
    default:
      return std::nullopt;
  }
}

std::optional<std::string> range_problem(const Command& c, const ValueLimits& limits) {
  using R = std::optional<std::string>;
  return std::visit(
      Overloaded{[](const Info&) -> R { return std::nullopt; },
                 [](const StopLed&) -> R { return std::nullopt; },
                 [](const StopMotor&) -> R { return std::nullopt; },
                 [](const StopRobot&) -> R { return std::nullopt; },
                 [](const EarAll&) -> R { return std::nullopt; },
                 [](const EarRange& v) -> R {
                   if (v.first > 1) {
                     return "first ear LED id " + hex_literal(v.first) + " outside 0x00..0x01";
                   }
                   if (v.last > 1) {
                     return "last ear LED id " + hex_literal(v.last) + " outside 0x00..0x01";
                   }
                   if (v.first > v.last) {
                     return "first ear LED id " + hex_literal(v.first) + " is after last " +
                            hex_literal(v.last);
                   }
                   return std::nullopt;
                 },
                 [](const EarSingle& v) -> R {
                   if (v.led <= 1) return std::nullopt;
                   return "ear LED id " + hex_literal(v.led) + " outside 0x00..0x01";
                 },
                 [](const BeltAll&) -> R { return std::nullopt; },
                 [&](const BeltRange& v) -> R {
                   if (auto p = check_belt(v.first, "first belt LED id", limits)) return p;
                   if (auto p = check_belt(v.last, "last belt LED id", limits)) return p;
                   // A robot walking first..last would light nothing: surely a mistake.
                   if (v.first > v.last) {
                     return "first belt LED id " + hex_literal(v.first) + " is after last " +
                            hex_literal(v.last);
                   }
                   return std::nullopt;
                 },
                 [&](const BeltSingle& v) -> R { return check_belt(v.led, "belt LED id", limits); },
                 [](const MotorAll& v) -> R { return check_spin(v.direction, "direction"); },
                 [](const MotorDuo& v) -> R {
                   if (auto p = check_spin(v.left_spin, "left spin")) return p;
                   return check_spin(v.right_spin, "right spin");
                 },
                 [](const MotorLeft& v) -> R { return check_spin(v.spin, "spin"); },
                 [](const MotorRight& v) -> R { return check_spin(v.spin, "spin"); },
                 [](const Motivator& v) -> R {
                   if (v.id >= 0x51 && v.id <= 0x55) return std::nullopt;
                   return "motivator id " + hex_literal(v.id) + " outside 0x51..0x55";
                 },
                 [](const Guidance& v) -> R {
                   if (v.id >= 0x41 && v.id <= 0x4F) return std::nullopt;
                   return "guidance id " + hex_literal(v.id) + " outside 0x41..0x4F";
                 }},
      c);
}

std::string describe(const Command& c) {
  std::string out(spec_of(c).name);
  const auto add = [&](const std::string& text) { out += ' ' + text; };
  std::visit(
      Overloaded{
          [](const Info&) {}, [](const StopLed&) {}, [](const StopMotor&) {},
          [](const StopRobot&) {}, [&](const EarAll& v) { add(rgb_text(v.color)); },
          [&](const EarRange& v) {
            add("leds=" + std::to_string(v.first) + ".." + std::to_string(v.last));
            add(rgb_text(v.color));
          },
          [&](const EarSingle& v) {
            add("led=" + std::to_string(v.led));
            add(rgb_text(v.color));
          },
          [&](const BeltAll& v) { add(rgb_text(v.color)); },
          [&](const BeltRange& v) {
            add("leds=" + std::to_string(v.first) + ".." + std::to_string(v.last));
            add(rgb_text(v.color));
          },
          [&](const BeltSingle& v) {
            add("led=" + std::to_string(v.led));
            add(rgb_text(v.color));
          },
          [&](const MotorAll& v) {
            add(spin_text(v.direction) + " speed=" + std::to_string(v.speed));
          },
          [&](const MotorDuo& v) {
            add("left=" + spin_text(v.left_spin) + "/" + std::to_string(v.left_speed));
            add("right=" + spin_text(v.right_spin) + "/" + std::to_string(v.right_speed));
          },
          [&](const MotorLeft& v) { add(spin_text(v.spin) + " speed=" + std::to_string(v.speed)); },
          [&](const MotorRight& v) {
            add(spin_text(v.spin) + " speed=" + std::to_string(v.speed));
          },
          [&](const Motivator& v) { add("id=" + hex_literal(v.id)); },
          [&](const Guidance& v) { add("id=" + hex_literal(v.id)); }},
      c);
  return out;
}

std::string describe(const CommandGroup& g) {
  if (g.commands.empty()) return "(empty command group)";
  std::string out;
  for (std::size_t i = 0; i < g.commands.size(); ++i) {
    if (i != 0) out += " + ";
    out += describe(g.commands[i]);
  }
  return out;
}

}  // namespace hil::protocol::leka
