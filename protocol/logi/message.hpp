#pragma once
// Typed messages of the LOGI logistics car protocol (docs/protocols/logi.md).

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "protocol/common/bytes.hpp"
#include "protocol/common/decode.hpp"

namespace hil::protocol::logi {

/// Manual-mode motion: the MV commands and the MAN telemetry field.
enum class Direction : std::uint8_t { stop, fwd, bwd, left, right, lf, rf, lb, rb, cw, ccw };
inline constexpr std::array<Direction, 11> kAllDirections = {
    Direction::stop,  Direction::fwd, Direction::bwd, Direction::left,
    Direction::right, Direction::lf,  Direction::rf,  Direction::lb,
    Direction::rb,    Direction::cw,  Direction::ccw};

enum class Mode : std::uint8_t { automatic, manual };

/// The command a feedback frame answers.
enum class Command : std::uint8_t { sp, st, gs, md, mv };
inline constexpr std::array<Command, 5> kAllCommands = {Command::sp, Command::st, Command::gs,
                                                        Command::md, Command::mv};

// ---- upper computer -> car ----

/// SP:xxx, speed percent 000..100.
struct SetSpeed {
  int percent = 0;
  friend bool operator==(const SetSpeed&, const SetSpeed&) = default;
};
/// ST:RUN (run = true) or ST:STOP.
struct SetRun {
  bool run = false;
  friend bool operator==(const SetRun&, const SetRun&) = default;
};
/// GS:xxx, target station 000..999 (the firmware accepts 001 and 002).
struct SetStation {
  int station = 0;
  friend bool operator==(const SetStation&, const SetStation&) = default;
};
/// MD:MAN or MD:AUTO.
struct SetMode {
  Mode mode = Mode::automatic;
  friend bool operator==(const SetMode&, const SetMode&) = default;
};
/// MV:<direction>, only honoured in manual mode.
struct Move {
  Direction direction = Direction::stop;
  friend bool operator==(const Move&, const Move&) = default;
};

// ---- car -> upper computer ----

/// STAT telemetry, sent about every 500 ms.
struct Status {
  int speed_percent = 0;               ///< SP, 0..100
  int station = 0;                     ///< STA, target station 0..999
  bool running = false;                ///< RUN
  Mode mode = Mode::automatic;         ///< MODE
  Direction manual = Direction::stop;  ///< MAN
  int distance_cm = 0;                 ///< DIS, ultrasonic range, >= 0
  std::uint8_t track_mask = 0;         ///< TRK, bit 3 = H4 ... bit 0 = H1 (written H4 H3 H2 H1)
  int deviation = 0;                   ///< DEV, signed track deviation
  bool obstacle = false;               ///< OBS, obstacle lock
  std::array<int, 4> rpm{};            ///< RPM, M1..M4 = LR, LF, RF, RR; signed
  /// Keys the profile does not know, kept in arrival order (forward compatibility).
  std::vector<std::pair<std::string, std::string>> extra;
  friend bool operator==(const Status&, const Status&) = default;
};

/// FB:<CMD>:<0|1>, immediate answer to a command.
struct Feedback {
  Command command = Command::sp;
  bool accepted = false;
  friend bool operator==(const Feedback&, const Feedback&) = default;
};

using Message = std::variant<SetSpeed, SetRun, SetStation, SetMode, Move, Status, Feedback>;

using hil::protocol::to_string;  // the shared overloads (bytes, error kinds) stay visible

std::string_view to_string(Direction d);  ///< "STOP", "FWD", ... as on the wire
std::string_view to_string(Mode m);       ///< "AUTO" or "MAN"
std::string_view to_string(Command c);    ///< "SP", "ST", ...
std::optional<Direction> parse_direction(std::string_view text);
std::optional<Mode> parse_mode(std::string_view text);
std::optional<Command> parse_command(std::string_view text);

/// The command a feedback frame would answer for this message, if it is a command.
std::optional<Command> command_of(const Message& m);

/// The frame's kind as fault rules and mock behaviours match it: the payload
/// code plus the argument of ST, MD and MV ("SP", "ST:RUN", "MV:FWD",
/// "STAT", "FB:ST").
std::string kind_of(const Message& m);

/// One-line human description, e.g. "SetSpeed percent=50".
std::string describe(const Message& m);

}  // namespace hil::protocol::logi
