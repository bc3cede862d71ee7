#pragma once
// The packets of the real WR8 programs, smart_vehicle_gui's vehicle and
// GUI, in the two versions that matter (docs/protocols/wr8.md, "The real
// programs"): v2019 (commit 8d80e92), the packet set of the WR8 document
// but with its own layouts, and head (commit 431e8d4), a revised set.
// Packets here are what follows the length byte (protocol/wr8/
// length_prefix.hpp); values are written by Qt's QDataStream (big-endian,
// every float as an 8-byte double, enum codes as 4-byte integers) except
// v2019's TASK and SETTINGS, which the GUI writes little-endian by hand.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "protocol/common/bytes.hpp"
#include "protocol/common/decode.hpp"
#include "protocol/wr8/length_prefix.hpp"
#include "protocol/wr8/message.hpp"

namespace hil::protocol::wr8::svgui {

enum class Version : std::uint8_t {
  v2019,  ///< 8d80e92: TASK, SETTINGS, ANSWER with COI, one DATA packet
  head,   ///< 431e8d4: SET, ANSWER, SET-REQUEST, MAP, two DATA rates, CONTROL
};

std::string_view to_string(Version version);  ///< "v2019", "head"

/// The real-program version a WR8 profile plays: nullopt for `document`
/// (the PDF's packets, no length byte), v2019 for `svgui-2019`, head for
/// `svgui-head`; empty is the default profile. Throws protocol::ProfileError
/// for a name that is not a WR8 profile.
std::optional<Version> version_of_profile(std::string_view profile);
/// The profile that plays `version`: "svgui-2019" or "svgui-head".
std::string_view profile_of(Version version);

/// Code 1, GUI -> vehicle: the bytes after the code as sent. The v2019 GUI
/// sends the ten letters of "konnichiwa", the head GUI the same and a NUL.
struct Auth {
  Bytes text;
  friend bool operator==(const Auth&, const Auth&) = default;
};

/// Code 2, vehicle -> GUI: the document's AUTH-REPLY layout. Both real
/// vehicles always send device 1, id 2, state 3 (WAIT): kProgramAuthReply.
using wr8::AuthReply;
inline constexpr AuthReply kProgramAuthReply{1, 2, State::wait};

/// Code 3 (v2019), GUI -> vehicle: COI, task type (1 forward with a
/// distance, 2 wheels with an angle, 3 turn signals), and a count of int32
/// parameters, little-endian.
struct Task {
  std::uint8_t coi = 0;
  std::uint8_t type = 0;
  std::vector<std::int32_t> params;
  friend bool operator==(const Task&, const Task&) = default;
};

/// Code 4 (v2019), GUI -> vehicle: COI then p, i, d and servo zero as
/// int32 little-endian, with no size or type bytes (18 bytes).
struct Settings {
  std::uint8_t coi = 0;
  std::array<std::int32_t, 4> values{};
  friend bool operator==(const Settings&, const Settings&) = default;
};

/// Code 4 (head), both ways: twelve doubles in the order of kSetNames.
struct Set {
  std::array<double, 12> values{};
  friend bool operator==(const Set&, const Set&) = default;
};
/// "steering-p", "steering-i", ..., "backward-int": the fields of Set.
extern const std::array<std::string_view, 12> kSetNames;

/// Code 5, vehicle -> GUI: v2019 carries the COI of the task (0 error,
/// 1 started, 2 done); head has no COI (1: the settings were applied).
struct Answer {
  std::optional<std::uint8_t> coi;
  std::uint8_t code = 0;
  friend bool operator==(const Answer&, const Answer&) = default;
};

/// Code 6 (head), GUI -> vehicle: asks for the settings in a Set.
struct SetRequest {
  friend bool operator==(const SetRequest&, const SetRequest&) = default;
};

/// Code 6 (v2019), vehicle -> GUI: 42 bytes, big-endian; the four values
/// follow their codes 1 to 4.
struct Data {
  State state = State::wait;
  std::uint32_t timestamp_ms = 0;  ///< milliseconds since local midnight
  std::int32_t encoder = 0;
  double steering = 0;
  std::uint32_t motor_battery = 0;
  std::uint32_t computer_battery = 0;
  friend bool operator==(const Data&, const Data&) = default;
};

/// Code 7 (head), vehicle -> GUI: the arena as a grid of cells (0 empty,
/// 1 wall), rows of int8 in Qt's vector-of-vectors form.
struct Map {
  std::int8_t width = 0;
  std::int8_t height = 0;
  std::vector<std::vector<std::int8_t>> rows;
  friend bool operator==(const Map&, const Map&) = default;
};

/// Code 8 (head), vehicle -> GUI, every second: 34 bytes.
struct LowFreqData {
  State state = State::wait;
  std::uint32_t timestamp_ms = 0;
  std::uint32_t motor_battery = 0;
  std::uint32_t computer_battery = 0;
  double temperature = 0;
  friend bool operator==(const LowFreqData&, const LowFreqData&) = default;
};

/// Code 9 (head), vehicle -> GUI, every 50 ms: 65 bytes.
struct HighFreqData {
  std::uint32_t timestamp_ms = 0;
  double encoder = 0;
  double steering = 0;
  double x = 0;
  double y = 0;
  double angle = 0;
  friend bool operator==(const HighFreqData&, const HighFreqData&) = default;
};

/// Code 10 (head), GUI -> vehicle: the joystick's two axes.
struct Control {
  double x_axis = 0;
  double y_axis = 0;
  friend bool operator==(const Control&, const Control&) = default;
};

using Message = std::variant<Auth, AuthReply, Task, Settings, Set, Answer, SetRequest, Data, Map,
                             LowFreqData, HighFreqData, Control>;

/// The packet's name in `version` ("AUTH-REPLY", "SETTINGS", "SET"); empty
/// for a code the version does not have.
std::string_view packet_name(std::uint8_t code, Version version);
/// The name fault rules, behaviours and scenario matchers know a packet by:
/// packet_name with '_' for '-' ("HIGH_FREQ_DATA"); empty for an unknown code.
std::string kind_name(std::uint8_t code, Version version);

/// The packet code of a message, and whether `version` has that packet.
std::uint8_t code_of(const Message& m);
bool has_packet(Version version, const Message& m);

/// The packet (code first, no length byte). Throws std::invalid_argument
/// for a packet `version` does not have, an ANSWER whose COI does not match
/// the version, an AUTH text over 126 bytes, a TASK of more than 31
/// parameters, or a MAP too large for its length byte.
Bytes encode(const Message& m, Version version);

/// The packet with its length byte, as the real programs send it.
Bytes encode_prefixed(const Message& m, Version version);

using Item = DecodeItem<Message>;

/// Parses one packet (the bytes after a length byte) as `version` lays it
/// out. Never throws: an unknown code is ErrorKind::unknown_code, a packet
/// shorter or longer than its layout bad_format, a state above 3 bad_value.
Item decode_packet(ByteView packet, Version version);

/// The stream decoder (its contract: protocol/common/decode.hpp) of one
/// direction of a real program's stream: the length byte frames each
/// packet (LengthPrefixSplitter) and the packet is then parsed as `version`
/// lays it out. An item's raw bytes include its length byte; it holds at
/// most 128 bytes. This is how hil reads such a
/// stream (wire logs, captures, faults, clients); the real programs read
/// theirs differently (svgui_receiver.hpp).
class Decoder {
 public:
  explicit Decoder(Version version) : version_(version) {}
  void feed(ByteView bytes, std::vector<Item>& out);
  void finish(std::vector<Item>& out);
  std::size_t buffered() const { return splitter_.buffered(); }
  Version version() const { return version_; }

 private:
  void convert(std::vector<Item>& out);
  Version version_;
  LengthPrefixSplitter splitter_;
  std::vector<PrefixedItem> framed_;
};

/// One line for a person, e.g. "HighFreqData t=36000000ms encoder=1.5 ...".
std::string describe(const Message& m);

}  // namespace hil::protocol::wr8::svgui
