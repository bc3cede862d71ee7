#pragma once
// Typed messages of the Arduino serial robot protocol (docs/protocols/arduino.md).

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include "protocol/common/bytes.hpp"
#include "protocol/common/decode.hpp"

namespace hil::protocol::arduino {

// ---- PC -> Arduino (requests) ----

/// PING: link health check, empty payload.
struct Ping {
  friend bool operator==(const Ping&, const Ping&) = default;
};
/// STATUS: ask for the robot's status text, empty payload.
struct StatusRequest {
  friend bool operator==(const StatusRequest&, const StatusRequest&) = default;
};
/// V:<pwm>: set the linear speed as a motor PWM duty, 0..255.
struct SetSpeed {
  int pwm = 0;
  friend bool operator==(const SetSpeed&, const SetSpeed&) = default;
};
/// M:<cm>: drive a distance; positive is forward, negative backward.
struct Move {
  int distance_cm = 0;
  friend bool operator==(const Move&, const Move&) = default;
};
/// R:<deg>: turn on the spot; positive is right (clockwise seen from above).
struct Rotate {
  int angle_deg = 0;
  friend bool operator==(const Rotate&, const Rotate&) = default;
};
/// S: emergency stop, empty payload.
struct Stop {
  friend bool operator==(const Stop&, const Stop&) = default;
};
/// B: read the sonar; the ACK carries the distance in cm.
struct SonarRead {
  friend bool operator==(const SonarRead&, const SonarRead&) = default;
};
/// I: read the IR sensors; the ACK carries their value as text.
struct IrRead {
  friend bool operator==(const IrRead&, const IrRead&) = default;
};
/// HELP: ask for the firmware's help text (debugging aid).
struct Help {
  friend bool operator==(const Help&, const Help&) = default;
};

// ---- Arduino -> PC (responses, same SEQ as the request) ----

/// ACK:<info>: success; the info text is defined by each command (may be empty).
struct Ack {
  std::string info;
  friend bool operator==(const Ack&, const Ack&) = default;
};

/// The firmware's documented NACK error codes.
enum class NackCode : std::uint8_t { bad_cs, bad_fmt, bad_seq, bad_cmd, bad_v };
inline constexpr std::array<NackCode, 5> kAllNackCodes = {
    NackCode::bad_cs, NackCode::bad_fmt, NackCode::bad_seq, NackCode::bad_cmd, NackCode::bad_v};

/// NACK:<error>: failure. A documented code is kept as NackCode; any other
/// text (e.g. OUT_OF_RANGE) is kept verbatim, so a firmware with more codes
/// still decodes.
struct Nack {
  std::variant<NackCode, std::string> error;
  friend bool operator==(const Nack&, const Nack&) = default;
};

using Body = std::variant<Ping, StatusRequest, SetSpeed, Move, Rotate, Stop, SonarRead, IrRead,
                          Help, Ack, Nack>;

/// One frame's meaning: the 8-bit sequence number every frame carries, and
/// what the frame says.
struct Message {
  std::uint8_t seq = 0;
  Body body;
  friend bool operator==(const Message&, const Message&) = default;
};

using hil::protocol::to_string;  // the shared overloads (bytes, error kinds) stay visible

std::string_view to_string(NackCode code);  ///< "BAD_CS", ... as on the wire
std::optional<NackCode> parse_nack_code(std::string_view text);

/// The NACK body for an error text: a documented code when it is one.
Nack nack_from_text(std::string_view text);

/// The CMD token of a body as on the wire: "PING", "V", "ACK", ...
std::string_view command_of(const Body& body);

/// True for the PC's requests, false for ACK and NACK.
bool is_request(const Body& body);

/// One-line human description, e.g. "SetSpeed seq=02 pwm=160".
std::string describe(const Message& m);

}  // namespace hil::protocol::arduino
