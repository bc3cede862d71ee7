#pragma once
// Typed packets of the WR8 vehicle protocol (docs/protocols/wr8.md).

#include <array>
#include <bit>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "protocol/common/bytes.hpp"
#include "protocol/common/decode.hpp"
#include "protocol/wr8/profile.hpp"

namespace hil::protocol::wr8 {

/// A parameter value exactly as its bits travel, whatever it means: the
/// profile decides whether a person sees an integer or a float, so decoding
/// and re-encoding never round a value.
struct Word {
  std::uint32_t bits = 0;

  static constexpr Word from_i32(std::int32_t v) { return Word{static_cast<std::uint32_t>(v)}; }
  static constexpr Word from_u32(std::uint32_t v) { return Word{v}; }
  static Word from_f32(float v) { return Word{std::bit_cast<std::uint32_t>(v)}; }
  constexpr std::int32_t as_i32() const { return static_cast<std::int32_t>(bits); }
  float as_f32() const { return std::bit_cast<float>(bits); }

  friend bool operator==(const Word&, const Word&) = default;
};

/// The first byte of every packet.
enum class PacketCode : std::uint8_t {
  empty = 0,
  auth = 1,
  auth_reply = 2,
  task = 3,
  settings = 4,
  response = 5,
  data = 6,
};
inline constexpr std::uint8_t kPacketCodeCount = 7;

/// Vehicle state, in AUTH-REPLY and DATA.
enum class State : std::uint8_t { fault = 0, run = 1, stop = 2, wait = 3 };
inline constexpr std::array<State, 4> kAllStates = {State::fault, State::run, State::stop,
                                                    State::wait};

enum class TaskCode : std::uint8_t {
  check = 0,         ///< connection check, no parameters
  drive = 1,         ///< drive forward a distance
  turn = 2,          ///< set the wheel angle
  blink = 3,         ///< blink the turn signals, no parameters
  get_settings = 4,  ///< answered with a SETTINGS packet, then RESPONSE
};
inline constexpr std::array<TaskCode, 5> kAllTaskCodes = {
    TaskCode::check, TaskCode::drive, TaskCode::turn, TaskCode::blink, TaskCode::get_settings};

enum class SettingCode : std::uint8_t { p = 0, i = 1, d = 2, servo_zero = 3 };
inline constexpr std::array<SettingCode, 4> kAllSettingCodes = {
    SettingCode::p, SettingCode::i, SettingCode::d, SettingCode::servo_zero};

enum class ResponseCode : std::uint8_t { error = 0, started = 1, completed = 2 };
inline constexpr std::array<ResponseCode, 3> kAllResponseCodes = {
    ResponseCode::error, ResponseCode::started, ResponseCode::completed};

/// DATA codes of the default profile (a profile may add more).
namespace data_code {
inline constexpr std::uint8_t odometry = 0;
inline constexpr std::uint8_t speed = 1;
inline constexpr std::uint8_t wheel_angle = 2;
inline constexpr std::uint8_t battery = 3;
}  // namespace data_code

// ---- packets ----

/// Code 0: a one-byte packet with no body (treated as a keepalive).
struct Empty {
  friend bool operator==(const Empty&, const Empty&) = default;
};

/// Code 1, GUI -> vehicle: the 10-byte authentication string.
struct Auth {
  std::array<std::uint8_t, kAuthTextBytes> text{};
  friend bool operator==(const Auth&, const Auth&) = default;
};

/// Code 2, vehicle -> GUI: sent when AUTH carried the right string.
struct AuthReply {
  std::uint8_t device_code = 0;
  std::uint8_t device_id = 0;
  State state = State::wait;
  friend bool operator==(const AuthReply&, const AuthReply&) = default;
};

/// Code 3, GUI -> vehicle: an action. `coi` numbers the request so the
/// RESPONSE can be matched to it.
struct Task {
  std::uint8_t coi = 0;
  TaskCode task = TaskCode::check;
  std::vector<Word> params;
  friend bool operator==(const Task&, const Task&) = default;
};

struct Setting {
  SettingCode code = SettingCode::p;
  Word value;
  friend bool operator==(const Setting&, const Setting&) = default;
};

/// Code 4: GUI -> vehicle to change settings; vehicle -> GUI (same COI, all
/// four settings) to answer the get-settings task.
struct Settings {
  std::uint8_t coi = 0;
  std::vector<Setting> params;
  friend bool operator==(const Settings&, const Settings&) = default;
};

/// Code 5, vehicle -> GUI: the outcome of the TASK or SETTINGS with this COI.
struct Response {
  std::uint8_t coi = 0;
  ResponseCode code = ResponseCode::completed;
  friend bool operator==(const Response&, const Response&) = default;
};

/// One DATA parameter. Values narrower than 4 bytes sit in the low bits.
struct DataValue {
  std::uint8_t code = 0;
  Word value;
  friend bool operator==(const DataValue&, const DataValue&) = default;
};

/// Code 6, vehicle -> GUI, sent periodically.
struct Data {
  State state = State::run;
  std::uint32_t timestamp_ms = 0;  ///< milliseconds since the vehicle started
  std::vector<DataValue> values;
  /// Block bytes from the first code the profile does not know to the end
  /// of the block (only when sizes count bytes, so the end is known).
  Bytes unparsed;
  friend bool operator==(const Data&, const Data&) = default;
};

using Message = std::variant<Empty, Auth, AuthReply, Task, Settings, Response, Data>;

using hil::protocol::to_string;  // the shared overloads (bytes, error kinds) stay visible

std::string_view to_string(PacketCode code);    ///< "EMPTY", "AUTH", "AUTH-REPLY", ...
std::string_view to_string(State state);        ///< "FAULT", "RUN", "STOP", "WAIT"
std::string_view to_string(TaskCode task);      ///< "check", "drive", ... (CLI names)
std::string_view to_string(SettingCode code);   ///< "p", "i", "d", "servo-zero"
std::string_view to_string(ResponseCode code);  ///< "error", "started", "completed"

/// Names or numeric codes, as the CLI accepts them ("run" / "RUN" / "1").
std::optional<State> parse_state(std::string_view text);
std::optional<TaskCode> parse_task(std::string_view text);
std::optional<SettingCode> parse_setting(std::string_view text);
std::optional<ResponseCode> parse_response(std::string_view text);

PacketCode code_of(const Message& m);

/// A value as a person reads it: `size_bytes` low bytes of `w`, shown as
/// `type` (float32 only for 4 bytes).
std::string format_value(Word w, ValueType type, std::size_t size_bytes = 4);
/// Reads a value typed by a person: a decimal integer or float as `type`
/// says, or 0x followed by up to 2 * size_bytes hex digits for exact bits.
/// Returns nullopt when it does not fit `size_bytes`.
std::optional<Word> parse_value(std::string_view text, ValueType type, std::size_t size_bytes = 4);

/// One-line human description, e.g. "Task coi=1 drive distance_cm=100".
std::string describe(const Message& m, const Profile& profile = default_profile());

}  // namespace hil::protocol::wr8
