// hil encode wr8 / hil decode wr8 for the real programs' profiles,
// svgui-2019 and svgui-head (protocol/wr8/svgui.hpp): every packet with the
// length byte the programs put before it.

#include <algorithm>
#include <charconv>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <variant>
#include <vector>

#include "apps/hil/wr8_cli.hpp"
#include "link/capture/wire_log.hpp"
#include "protocol/common/text.hpp"
#include "protocol/wr8/length_prefix.hpp"

namespace hil::apps::wr8_cli {

namespace svgui = protocol::wr8::svgui;
using svgui::Version;

const char* const kSvguiEncodeForms = R"(

Forms of --profile svgui-2019 (the real smart_vehicle_gui programs at 8d80e92; prints the
packet as spaced hex, the length byte first, as the programs send it):
  auth [TEXT]                     TEXT: the login (default konnichiwa, as the GUI sends it)
  auth --text-hex HEX             the bytes after the code, exactly
  auth-reply [DEVICE ID STATE]    default: 1 2 wait, the only reply the vehicle sends
  task COI TYPE [VALUE...]        TYPE: forward DISTANCE | wheels ANGLE | turn-signals
                                  (or a number 0..255 with any VALUEs); int32 little-endian
  settings COI P I D SERVO_ZERO   four int32, little-endian, no size or type bytes
  answer COI CODE                 CODE: error | started | done (or 0..255)
  data STATE TIMESTAMP_MS [NAME=VALUE...]   NAME: encoder (int32) | steering (double)
                                  | motor-battery | computer-battery (uint32); 0 if not given
  packet CODE [HEX...]            any code and bytes, unchecked, with their length byte

Forms of --profile svgui-head (smart_vehicle_gui at 431e8d4; the length byte first too):
  auth [TEXT]                     the login and a NUL (default konnichiwa and a NUL)
  auth --text-hex HEX             the bytes after the code, exactly
  auth-reply [DEVICE ID STATE]    default: 1 2 wait
  set [NAME=VALUE...]             twelve doubles, 0 if not given; NAME: steering-p,
                                  steering-i, steering-d, steering-zero, forward-p, forward-i,
                                  forward-d, forward-int, backward-p, backward-i,
                                  backward-d, backward-int
  answer CODE                     no COI; CODE: applied (1) or 0..255
  set-request                     asks the vehicle for its settings
  map ROW...                      one argument per row of cells: digits (01100000) or
                                  comma-separated -128..127; the width is the row length
  low-freq-data STATE TIMESTAMP_MS [NAME=VALUE...]   NAME: motor-battery,
                                  computer-battery (uint32) | temperature (double)
  high-freq-data TIMESTAMP_MS [NAME=VALUE...]   NAME: encoder, steering, x, y, angle (double)
  control X Y                     the joystick's two axes (double)
  packet CODE [HEX...]            any code and bytes, unchecked, with their length byte

  STATE: fault | run | stop | wait (or 0..3). Values are big-endian except v2019's TASK and
  SETTINGS. A packet may not pass 127 bytes: one length byte frames no more.
)";

namespace {

const std::vector<std::string_view> kV2019Forms = {"auth",   "auth-reply", "task",  "settings",
                                                   "answer", "data",       "packet"};
const std::vector<std::string_view> kHeadForms = {
    "auth",          "auth-reply",     "set",     "answer", "set-request", "map",
    "low-freq-data", "high-freq-data", "control", "packet"};

const std::vector<std::string_view>& forms_of(Version version) {
  return version == Version::v2019 ? kV2019Forms : kHeadForms;
}

bool has_form(Version version, std::string_view form) {
  const auto& forms = forms_of(version);
  return std::any_of(forms.begin(), forms.end(),
                     [&](std::string_view f) { return normalised(f) == normalised(form); });
}

std::string profile_name(Version version) {
  return std::string(svgui::profile_of(version));
}

bool starts_with_digit(std::string_view text) {
  return !text.empty() && text[0] >= '0' && text[0] <= '9';
}

std::int32_t parse_int32(std::string_view text, std::string_view what) {
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
    return static_cast<std::int32_t>(parse_unsigned(text, 0xFFFFFFFFu, what));
  }
  long long value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || ec != std::errc{} || end != text.data() + text.size() ||
      value < std::numeric_limits<std::int32_t>::min() ||
      value > std::numeric_limits<std::int32_t>::max()) {
    throw UsageError(std::string(what) + " '" + std::string(text) +
                     "' is not a whole number that fits 32 bits (or 0x and hex digits)");
  }
  return static_cast<std::int32_t>(value);
}

double parse_double(std::string_view text, std::string_view what) {
  double value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || ec != std::errc{} || end != text.data() + text.size()) {
    throw UsageError(std::string(what) + " '" + std::string(text) + "' is not a number");
  }
  return value;
}

/// NAME=VALUE arguments from `first` on, each NAME one of `names` (compared
/// as normalised()); a name given twice is an error.
std::map<std::string, std::string_view> assignments(const std::vector<std::string>& w,
                                                    std::size_t first,
                                                    const std::vector<std::string_view>& names) {
  std::map<std::string, std::string_view> out;
  for (std::size_t i = first; i < w.size(); ++i) {
    const auto [name, value] = split_assignment(w[i]);
    const std::string key = normalised(name);
    const bool known = std::any_of(names.begin(), names.end(),
                                   [&](std::string_view n) { return normalised(n) == key; });
    if (!known) {
      std::string list;
      for (const auto n : names)
        list += (list.empty() ? "" : ", ") + std::string(n);
      throw UsageError(w[0] + ": '" + std::string(name) + "' is none of " + list);
    }
    if (!out.emplace(key, value).second) {
      throw UsageError(w[0] + ": '" + std::string(name) + "' is given twice");
    }
  }
  return out;
}

template <class Parse>
auto value_or(const std::map<std::string, std::string_view>& values, std::string_view name,
              Parse parse) -> decltype(parse(std::string_view{}, std::string_view{})) {
  const auto it = values.find(normalised(name));
  if (it == values.end()) return {};
  return parse(it->second, name);
}

std::uint32_t parse_u32(std::string_view text, std::string_view what) {
  return parse_unsigned(text, 0xFFFFFFFFu, what);
}

svgui::Auth auth_of(const std::vector<std::string>& w, const std::string& text_hex,
                    Version version) {
  expect_count(w, 0, 1, "[TEXT] or --text-hex HEX");
  if (!text_hex.empty() && w.size() > 1)
    throw UsageError("auth takes TEXT or --text-hex, not both");
  if (!text_hex.empty()) return svgui::Auth{parse_hex_arg(text_hex, "--text-hex")};
  protocol::Bytes text = protocol::to_bytes(w.size() > 1 ? std::string_view(w[1]) : "konnichiwa");
  // The head GUI sends its login as a C string, terminator and all.
  if (version == Version::head) text.push_back(0);
  return svgui::Auth{std::move(text)};
}

svgui::AuthReply auth_reply_of(const std::vector<std::string>& w) {
  if (w.size() == 1) return svgui::kProgramAuthReply;
  if (w.size() != 4) throw UsageError("auth-reply takes nothing, or DEVICE ID STATE");
  return svgui::AuthReply{parse_byte(w[1], "device code"), parse_byte(w[2], "device id"),
                          parse_state_arg(w[3])};
}

svgui::Task task_of(const std::vector<std::string>& w) {
  expect_count(w, 2, 255, "COI TYPE [VALUE...]");
  svgui::Task t;
  t.coi = parse_byte(w[1], "COI");
  // The types the v2019 vehicle acts on, and how many values it reads.
  struct Named {
    std::string_view name;
    std::uint8_t type;
    std::size_t values;
  };
  static constexpr Named kTypes[] = {{"forward", 1, 1}, {"wheels", 2, 1}, {"turn-signals", 3, 0}};
  const std::string type = normalised(w[2]);
  const Named* named = nullptr;
  for (const Named& n : kTypes) {
    if (normalised(n.name) == type) named = &n;
  }
  if (named == nullptr && !starts_with_digit(w[2])) {
    throw UsageError("task type '" + w[2] + "': expected forward, wheels, turn-signals or 0..255");
  }
  t.type = named != nullptr ? named->type : parse_byte(w[2], "task type");
  for (std::size_t i = 3; i < w.size(); ++i)
    t.params.push_back(parse_int32(w[i], "task value"));
  if (named != nullptr && t.params.size() != named->values) {
    throw UsageError("task " + std::string(named->name) + " takes " +
                     std::to_string(named->values) + " value(s), got " +
                     std::to_string(t.params.size()) + " (a number as TYPE takes any)");
  }
  return t;
}

std::uint8_t answer_code(std::string_view text, Version version) {
  const std::string code = normalised(text);
  const bool v2019 = version == Version::v2019;
  if (v2019 && code == "error") return 0;
  if (v2019 && code == "started") return 1;
  if (v2019 && code == "done") return 2;
  if (!v2019 && code == "applied") return 1;
  if (!starts_with_digit(text)) {
    throw UsageError("answer code '" + std::string(text) + "': expected " +
                     (v2019 ? "error, started, done" : "applied") + " or 0..255");
  }
  return parse_byte(text, "answer code");
}

svgui::Map map_of(const std::vector<std::string>& w) {
  svgui::Map map;
  for (std::size_t i = 1; i < w.size(); ++i) {
    std::vector<std::int8_t> row;
    const std::string what = "map row " + std::to_string(i);
    if (w[i].find(',') != std::string::npos) {
      for (const std::string_view cell : protocol::split(w[i], ',')) {
        const std::int32_t v = parse_int32(cell, what + " cell");
        if (v < -128 || v > 127)
          throw UsageError(what + ": cell " + std::to_string(v) + " is not -128..127");
        row.push_back(static_cast<std::int8_t>(v));
      }
    } else {
      for (const char c : w[i]) {
        if (c < '0' || c > '9') {
          throw UsageError(what + " '" + w[i] +
                           "': expected digits (01100000) or comma-separated numbers");
        }
        row.push_back(static_cast<std::int8_t>(c - '0'));
      }
    }
    if (!map.rows.empty() && row.size() != map.rows.front().size()) {
      throw UsageError(what + " has " + std::to_string(row.size()) + " cells, row 1 has " +
                       std::to_string(map.rows.front().size()));
    }
    if (row.size() > 127 || map.rows.size() >= 127)
      throw UsageError("map: too large for one packet");
    map.rows.push_back(std::move(row));
  }
  map.height = static_cast<std::int8_t>(map.rows.size());
  map.width = static_cast<std::int8_t>(map.rows.empty() ? 0 : map.rows.front().size());
  return map;
}

protocol::Bytes raw_prefixed(const std::vector<std::string>& w) {
  expect_count(w, 1, 100000, "CODE [HEX...]");
  protocol::Bytes packet{parse_byte(w[1], "packet code")};
  for (std::size_t i = 2; i < w.size(); ++i) {
    const auto b = parse_hex_arg(w[i], "packet byte(s)");
    packet.insert(packet.end(), b.begin(), b.end());
  }
  return protocol::wr8::prefix_length(packet);
}

// `STATE TIMESTAMP_MS [NAME=VALUE...]` of a DATA packet: the state and the
// time stamp into `d`; the values by name, of `names`.
template <class StateData>
std::map<std::string, std::string_view> read_state_and_time(
    const std::vector<std::string>& w, const std::vector<std::string_view>& names, StateData& d) {
  expect_count(w, 2, 2 + names.size(), "STATE TIMESTAMP_MS [NAME=VALUE...]");
  auto values = assignments(w, 3, names);
  d.state = parse_state_arg(w[1]);
  d.timestamp_ms = parse_u32(w[2], "timestamp");
  return values;
}

svgui::Message v2019_message(const std::vector<std::string>& w, const std::string& form) {
  if (form == "task") return task_of(w);
  if (form == "settings") {
    expect_count(w, 5, 5, "COI P I D SERVO_ZERO");
    return svgui::Settings{parse_byte(w[1], "COI"),
                           {parse_int32(w[2], "P"), parse_int32(w[3], "I"), parse_int32(w[4], "D"),
                            parse_int32(w[5], "SERVO_ZERO")}};
  }
  if (form == "answer") {
    expect_count(w, 2, 2, "COI CODE");
    return svgui::Answer{parse_byte(w[1], "COI"), answer_code(w[2], Version::v2019)};
  }
  // data
  svgui::Data d;
  const auto values =
      read_state_and_time(w, {"encoder", "steering", "motor-battery", "computer-battery"}, d);
  d.encoder = value_or(values, "encoder", parse_int32);
  d.steering = value_or(values, "steering", parse_double);
  d.motor_battery = value_or(values, "motor-battery", parse_u32);
  d.computer_battery = value_or(values, "computer-battery", parse_u32);
  return d;
}

svgui::Message head_message(const std::vector<std::string>& w, const std::string& form) {
  if (form == "set") {
    const std::vector<std::string_view> names(svgui::kSetNames.begin(), svgui::kSetNames.end());
    const auto values = assignments(w, 1, names);
    svgui::Set s;
    for (std::size_t i = 0; i < names.size(); ++i)
      s.values[i] = value_or(values, names[i], parse_double);
    return s;
  }
  if (form == "answer") {
    expect_count(w, 1, 1, "CODE (the head programs' ANSWER has no COI)");
    return svgui::Answer{std::nullopt, answer_code(w[1], Version::head)};
  }
  if (form == "set_request") {
    expect_count(w, 0, 0, "no arguments");
    return svgui::SetRequest{};
  }
  if (form == "map") return map_of(w);
  if (form == "low_freq_data") {
    svgui::LowFreqData d;
    const auto values =
        read_state_and_time(w, {"motor-battery", "computer-battery", "temperature"}, d);
    d.motor_battery = value_or(values, "motor-battery", parse_u32);
    d.computer_battery = value_or(values, "computer-battery", parse_u32);
    d.temperature = value_or(values, "temperature", parse_double);
    return d;
  }
  if (form == "high_freq_data") {
    expect_count(w, 1, 6, "TIMESTAMP_MS [NAME=VALUE...]");
    const auto values = assignments(w, 2, {"encoder", "steering", "x", "y", "angle"});
    svgui::HighFreqData d;
    d.timestamp_ms = parse_u32(w[1], "timestamp");
    d.encoder = value_or(values, "encoder", parse_double);
    d.steering = value_or(values, "steering", parse_double);
    d.x = value_or(values, "x", parse_double);
    d.y = value_or(values, "y", parse_double);
    d.angle = value_or(values, "angle", parse_double);
    return d;
  }
  // control
  expect_count(w, 2, 2, "X Y");
  return svgui::Control{parse_double(w[1], "X"), parse_double(w[2], "Y")};
}

/// The decoded line: an AUTH's text is masked as everywhere hil shows
/// decoded packets, with whether it is the login the version's GUI sends.
std::string describe_for_person(const svgui::Message& m, Version version) {
  std::string text = svgui::describe(m);
  const auto* auth = std::get_if<svgui::Auth>(&m);
  if (auth == nullptr) return text;
  protocol::Bytes gui = protocol::to_bytes("konnichiwa");
  if (version == Version::head) gui.push_back(0);
  text += auth->text == gui
              ? " (the GUI's login)"
              : " (not the GUI's login; " + std::to_string(auth->text.size()) + " bytes)";
  return link::masked_frame_text("AUTH", text);
}

}  // namespace

std::string svgui_forms(Version version) {
  std::string out;
  for (const auto f : forms_of(version))
    out += (out.empty() ? "" : ", ") + std::string(f);
  return out;
}

std::string_view svgui_profile_with_form(std::string_view form) {
  if (has_form(Version::head, form)) return svgui::profile_of(Version::head);
  if (has_form(Version::v2019, form)) return svgui::profile_of(Version::v2019);
  return {};
}

protocol::Bytes build_svgui_packet(const std::vector<std::string>& w, const std::string& text_hex,
                                   Version version) {
  if (!has_form(version, w[0])) {
    const Version other = version == Version::v2019 ? Version::head : Version::v2019;
    const std::string hint =
        has_form(other, w[0]) ? "; profile " + profile_name(other) + " has it" : std::string();
    throw UsageError("profile " + profile_name(version) + " has no form '" + w[0] +
                     "'; its forms are " + svgui_forms(version) + hint + " (see --help)");
  }
  const std::string form = normalised(w[0]);
  if (!text_hex.empty() && form != "auth") throw UsageError("--text-hex is for auth only");
  if (form == "packet") return raw_prefixed(w);
  if (form == "auth") return svgui::encode_prefixed(auth_of(w, text_hex, version), version);
  if (form == "auth_reply") return svgui::encode_prefixed(auth_reply_of(w), version);
  const svgui::Message m =
      version == Version::v2019 ? v2019_message(w, form) : head_message(w, form);
  return svgui::encode_prefixed(m, version);
}

int decode_svgui(protocol::ByteView bytes, const DecodeInput& input, Version version) {
  return print_items<svgui::Message>(
      svgui::Decoder(version), bytes, true, input,
      [version](const svgui::Message& m) { return describe_for_person(m, version); });
}

}  // namespace hil::apps::wr8_cli
