#pragma once
// What an ACK's text means, per request and dialect: the same typed reply
// whether the board is the real sketch ("B:232", "STATUS:V=160,DIR=fwd,...")
// or speaks the README's examples ("232", "IDLE PWM=160 ..."). The texts of
// both are in docs/protocols/arduino.md ("Replies" and "Profiles").

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "protocol/arduino/codec.hpp"
#include "protocol/arduino/message.hpp"

namespace hil::protocol::arduino {

/// PING answered: the link is alive (`PONG` from the sketch, `OK` or any
/// other text from a README board).
struct PongReply {
  friend bool operator==(const PongReply&, const PongReply&) = default;
};

/// V, M, R or S taken. `pwm` is the speed a README board echoes to V.
struct DoneReply {
  std::optional<int> pwm;
  friend bool operator==(const DoneReply&, const DoneReply&) = default;
};

enum class MotionKind : std::uint8_t { idle, move, rotate, fault };
std::string_view to_string(MotionKind kind);

/// STATUS. Each dialect reports a part: the sketch the direction of the last
/// move, a README board its argument, uptime and battery.
struct StatusReply {
  int pwm = 0;
  MotionKind motion = MotionKind::idle;
  std::optional<long> time_left_ms;  ///< while moving
  std::optional<std::string> dir;    ///< sketch: "fwd", "rev" or "stop"
  std::optional<int> motion_arg;     ///< README: the running M or R argument
  std::optional<std::uint32_t> uptime_ms;
  std::optional<long> battery_mv;
  friend bool operator==(const StatusReply&, const StatusReply&) = default;
};

/// B. A board reads 0 (or its own no-echo value) when no echo came back.
struct SonarReply {
  long distance_cm = 0;
  friend bool operator==(const SonarReply&, const SonarReply&) = default;
};

/// I: both IR modules, analog 0..1023 and the digital obstacle pin.
struct IrReply {
  int left_analog = 0;
  int right_analog = 0;
  bool left_obstacle = false;
  bool right_obstacle = false;
  friend bool operator==(const IrReply&, const IrReply&) = default;
};

/// HELP: the command names the board lists.
struct HelpReply {
  std::vector<std::string> commands;
  friend bool operator==(const HelpReply&, const HelpReply&) = default;
};

using Reply = std::variant<PongReply, DoneReply, StatusReply, SonarReply, IrReply, HelpReply>;

/// The typed meaning of `info`, the ACK text answering `request` (a request
/// body) from a board of `dialect`; nullopt when the text is not what such a
/// board answers that request.
std::optional<Reply> parse_reply(Dialect dialect, const Body& request, std::string_view info);

/// One line for a person: "sonar 232 cm", "idle pwm=160 dir=stop", ...
std::string describe(const Reply& reply);

}  // namespace hil::protocol::arduino
