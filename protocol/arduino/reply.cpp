#include "protocol/arduino/reply.hpp"

#include <utility>

#include "base/enum_names.hpp"
#include "protocol/common/overloaded.hpp"
#include "protocol/common/text.hpp"

namespace hil::protocol::arduino {
namespace {

std::optional<long> number(std::string_view text, bool allow_sign = false) {
  const auto value = parse_decimal(text, allow_sign);
  if (!value) return std::nullopt;
  return static_cast<long>(*value);
}

/// "KEY<sep>value" with the key as given: the value, or nullopt.
std::optional<std::string_view> after(std::string_view field, std::string_view key) {
  if (field.substr(0, key.size()) != key) return std::nullopt;
  return field.substr(key.size());
}

std::optional<long> keyed_number(std::string_view field, std::string_view key) {
  const auto value = after(field, key);
  return value ? number(*value) : std::nullopt;
}

std::optional<bool> bit(std::string_view text) {
  if (text == "0") return false;
  if (text == "1") return true;
  return std::nullopt;
}

std::optional<int> analog(std::optional<long> v) {
  if (!v || *v > 1023) return std::nullopt;
  return static_cast<int>(*v);
}

std::optional<int> pwm_of(std::optional<long> v) {
  if (!v || *v > kMaxPwm) return std::nullopt;
  return static_cast<int>(*v);
}

// ---- the sketch (arduino.ino at 8dcfab0) ----

// STATUS:V=<pwm>,DIR=<fwd|rev|stop>,MOT:IDLE | MOT:MOVE,tleft:<ms> | MOT:ROT,tleft:<ms>
std::optional<Reply> sketch_status(std::string_view info) {
  const auto rest = after(info, "STATUS:");
  if (!rest) return std::nullopt;
  const auto fields = split(*rest, ',');
  if (fields.size() != 3 && fields.size() != 4) return std::nullopt;
  StatusReply s;
  const auto pwm = pwm_of(keyed_number(fields[0], "V="));
  const auto dir = after(fields[1], "DIR=");
  if (!pwm || !dir || (*dir != "fwd" && *dir != "rev" && *dir != "stop")) return std::nullopt;
  s.pwm = *pwm;
  s.dir = std::string(*dir);
  if (fields.size() == 3) {
    if (fields[2] != "MOT:IDLE") return std::nullopt;
    return s;
  }
  if (fields[2] == "MOT:MOVE") {
    s.motion = MotionKind::move;
  } else if (fields[2] == "MOT:ROT") {
    s.motion = MotionKind::rotate;
  } else {
    return std::nullopt;
  }
  s.time_left_ms = keyed_number(fields[3], "tleft:");
  if (!s.time_left_ms) return std::nullopt;
  return s;
}

// I:AL=<a>,AR=<a>,DL=<0|1>,DR=<0|1>
std::optional<Reply> sketch_ir(std::string_view info) {
  const auto rest = after(info, "I:");
  if (!rest) return std::nullopt;
  const auto f = split(*rest, ',');
  if (f.size() != 4) return std::nullopt;
  const auto al = analog(keyed_number(f[0], "AL="));
  const auto ar = analog(keyed_number(f[1], "AR="));
  const auto dl = after(f[2], "DL=");
  const auto dr = after(f[3], "DR=");
  const auto dlb = dl ? bit(*dl) : std::nullopt;
  const auto drb = dr ? bit(*dr) : std::nullopt;
  if (!al || !ar || !dlb || !drb) return std::nullopt;
  return IrReply{*al, *ar, *dlb, *drb};
}

/// DoneReply when the board answered exactly `expected` (OK, ACCEPTED, STOPPED).
std::optional<Reply> done_if(std::string_view info, std::string_view expected) {
  if (info != expected) return std::nullopt;
  return DoneReply{};
}

std::optional<Reply> sketch_reply(const Body& request, std::string_view info) {
  const auto word = [&](std::string_view expected) { return done_if(info, expected); };
  return std::visit(Overloaded{
                        [&](const Ping&) -> std::optional<Reply> {
                          if (info != "PONG") return std::nullopt;
                          return PongReply{};
                        },
                        [&](const SetSpeed&) { return word("OK"); },
                        [&](const Move&) { return word("ACCEPTED"); },
                        [&](const Rotate&) { return word("ACCEPTED"); },
                        [&](const Stop&) { return word("STOPPED"); },
                        [&](const StatusRequest&) { return sketch_status(info); },
                        [&](const SonarRead&) -> std::optional<Reply> {
                          const auto cm = keyed_number(info, "B:");
                          if (!cm) return std::nullopt;
                          return SonarReply{*cm};
                        },
                        [&](const IrRead&) { return sketch_ir(info); },
                        [&](const Help&) -> std::optional<Reply> {
                          const auto rest = after(info, "CMDS:");
                          if (!rest) return std::nullopt;
                          HelpReply h;
                          for (auto name : split(*rest, ','))
                            h.commands.emplace_back(name);
                          return h;
                        },
                        [&](const auto&) -> std::optional<Reply> { return std::nullopt; },
                    },
                    request);
}

// ---- the README's examples (what hil's readme profile answers) ----

// <IDLE|FAULT|MOVING M:<arg>|MOVING R:<arg>> PWM=<pwm> [REM_MS=<ms>] UP_MS=<ms> BAT_MV=<mv>
std::optional<Reply> readme_status(std::string_view info) {
  const auto words = split(info, ' ');
  std::size_t i = 0;
  StatusReply s;
  if (words.empty()) return std::nullopt;
  if (words[0] == "IDLE") {
    i = 1;
  } else if (words[0] == "FAULT") {
    s.motion = MotionKind::fault;
    i = 1;
  } else if (words[0] == "MOVING" && words.size() > 1) {
    const auto m = after(words[1], "M:");
    const auto r = after(words[1], "R:");
    const auto arg = m ? number(*m, true) : r ? number(*r, true) : std::nullopt;
    if (!arg) return std::nullopt;
    s.motion = m ? MotionKind::move : MotionKind::rotate;
    s.motion_arg = static_cast<int>(*arg);
    i = 2;
  } else {
    return std::nullopt;
  }
  bool have_pwm = false;
  for (; i < words.size(); ++i) {
    if (auto v = keyed_number(words[i], "PWM=")) {
      const auto pwm = pwm_of(v);
      if (!pwm) return std::nullopt;
      s.pwm = *pwm;
      have_pwm = true;
    } else if (auto rem = keyed_number(words[i], "REM_MS=")) {
      s.time_left_ms = *rem;
    } else if (auto up = keyed_number(words[i], "UP_MS=")) {
      s.uptime_ms = static_cast<std::uint32_t>(*up);
    } else if (auto mv = keyed_number(words[i], "BAT_MV=")) {
      s.battery_mv = *mv;
    } else {
      return std::nullopt;
    }
  }
  if (!have_pwm) return std::nullopt;
  return s;
}

// L=<a>,<0|1> R=<a>,<0|1>
std::optional<Reply> readme_ir(std::string_view info) {
  const auto sides = split(info, ' ');
  if (sides.size() != 2) return std::nullopt;
  const auto side = [](std::string_view text,
                       std::string_view key) -> std::optional<std::pair<int, bool>> {
    const auto rest = after(text, key);
    if (!rest) return std::nullopt;
    const auto parts = split(*rest, ',');
    if (parts.size() != 2) return std::nullopt;
    const auto a = analog(number(parts[0]));
    const auto d = bit(parts[1]);
    if (!a || !d) return std::nullopt;
    return std::pair{*a, *d};
  };
  const auto left = side(sides[0], "L=");
  const auto right = side(sides[1], "R=");
  if (!left || !right) return std::nullopt;
  return IrReply{left->first, right->first, left->second, right->second};
}

std::optional<Reply> readme_reply(const Body& request, std::string_view info) {
  return std::visit(Overloaded{
                        [&](const Ping&) -> std::optional<Reply> { return PongReply{}; },
                        [&](const SetSpeed&) -> std::optional<Reply> {
                          const auto pwm = pwm_of(number(info));
                          if (!pwm) return std::nullopt;
                          return DoneReply{pwm};
                        },
                        [&](const Move&) { return done_if(info, "OK"); },
                        [&](const Rotate&) { return done_if(info, "OK"); },
                        [&](const Stop&) { return done_if(info, "OK"); },
                        [&](const StatusRequest&) { return readme_status(info); },
                        [&](const SonarRead&) -> std::optional<Reply> {
                          const auto cm = number(info);
                          if (!cm) return std::nullopt;
                          return SonarReply{*cm};
                        },
                        [&](const IrRead&) { return readme_ir(info); },
                        [&](const Help&) -> std::optional<Reply> {
                          // "PING STATUS V<pwm> M<cm> R<deg> S B I HELP": a name, then
                          // its argument in angle brackets.
                          HelpReply h;
                          for (auto word : split(info, ' ')) {
                            if (word.empty()) return std::nullopt;
                            h.commands.emplace_back(word.substr(0, word.find('<')));
                          }
                          return h;
                        },
                        [&](const auto&) -> std::optional<Reply> { return std::nullopt; },
                    },
                    request);
}

}  // namespace

constexpr auto kMotionKindNames =
    base::enum_names<MotionKind>({MotionKind::idle, "idle"}, {MotionKind::move, "move"},
                                 {MotionKind::rotate, "rotate"}, {MotionKind::fault, "fault"});

std::string_view to_string(MotionKind kind) {
  return kMotionKindNames.name(kind);
}

std::optional<Reply> parse_reply(Dialect dialect, const Body& request, std::string_view info) {
  return dialect == Dialect::firmware ? sketch_reply(request, info) : readme_reply(request, info);
}

std::string describe(const Reply& reply) {
  return std::visit(
      Overloaded{
          [](const PongReply&) -> std::string { return "alive"; },
          [](const DoneReply& d) -> std::string {
            return d.pwm ? "done, pwm=" + std::to_string(*d.pwm) : "done";
          },
          [](const StatusReply& s) {
            std::string text = std::string(to_string(s.motion)) + " pwm=" + std::to_string(s.pwm);
            if (s.dir) text += " dir=" + *s.dir;
            if (s.motion_arg) text += " arg=" + std::to_string(*s.motion_arg);
            if (s.time_left_ms) text += " left=" + std::to_string(*s.time_left_ms) + "ms";
            if (s.battery_mv) text += " battery=" + std::to_string(*s.battery_mv) + "mV";
            return text;
          },
          [](const SonarReply& s) { return "sonar " + std::to_string(s.distance_cm) + " cm"; },
          [](const IrReply& ir) {
            return "ir left=" + std::to_string(ir.left_analog) + (ir.left_obstacle ? "*" : "") +
                   " right=" + std::to_string(ir.right_analog) + (ir.right_obstacle ? "*" : "");
          },
          [](const HelpReply& h) {
            std::string text = "commands";
            for (const auto& c : h.commands)
              text += " " + c;
            return text;
          },
      },
      reply);
}

}  // namespace hil::protocol::arduino
