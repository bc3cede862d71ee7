#include "protocol/wr8/message.hpp"

#include <charconv>
#include <sstream>
#include <system_error>

#include "protocol/common/overloaded.hpp"

namespace hil::protocol::wr8 {
namespace {

constexpr std::array<std::string_view, kPacketCodeCount> kPacketNames = {
    "EMPTY", "AUTH", "AUTH-REPLY", "TASK", "SETTINGS", "RESPONSE", "DATA"};
constexpr std::array<std::string_view, 4> kStateNames = {"FAULT", "RUN", "STOP", "WAIT"};
constexpr std::array<std::string_view, 5> kTaskNames = {"check", "drive", "turn", "blink",
                                                        "get_settings"};
constexpr std::array<std::string_view, 4> kSettingNames = {"p", "i", "d", "servo_zero"};
constexpr std::array<std::string_view, 3> kResponseNames = {"error", "started", "completed"};
// What a task's first parameter means, for describe().
constexpr std::array<std::string_view, 5> kTaskParamLabels = {"", "distance_cm", "angle_deg", "",
                                                              ""};

// Lowercase, '-' read as '_', so "GET-SETTINGS" and "get_settings" match.
std::string normalised(std::string_view text) {
  std::string out(text);
  for (char& c : out) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    if (c == '-') c = '_';
  }
  return out;
}

template <class Enum, std::size_t N>
std::optional<Enum> parse_name_or_code(std::string_view text,
                                       const std::array<std::string_view, N>& names) {
  const std::string key = normalised(text);
  for (std::size_t i = 0; i < N; ++i) {
    if (normalised(names[i]) == key) return static_cast<Enum>(i);
  }
  unsigned value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec == std::errc{} && end == text.data() + text.size() && !text.empty() && value < N) {
    return static_cast<Enum>(value);
  }
  return std::nullopt;
}

template <std::size_t N>
std::string name_or_number(std::uint8_t value, const std::array<std::string_view, N>& names,
                           std::string_view prefix) {
  if (value < N) return std::string(names[value]);
  return std::string(prefix) + std::to_string(value);
}

/// The name of `value` in `names`, or `unknown` for a value past the table.
template <class Enum, std::size_t N>
std::string_view name_in(const std::array<std::string_view, N>& names, Enum value,
                         std::string_view unknown) {
  const auto i = static_cast<std::size_t>(value);
  return i < N ? names[i] : unknown;
}

std::uint32_t mask_of(std::size_t size_bytes) {
  return size_bytes >= 4 ? 0xFFFFFFFFu : (1u << (8 * size_bytes)) - 1u;
}

}  // namespace

std::string_view to_string(PacketCode code) {
  return name_in(kPacketNames, code, "UNKNOWN");
}

std::string_view to_string(State state) {
  return name_in(kStateNames, state, "UNKNOWN");
}

std::string_view to_string(TaskCode task) {
  return name_in(kTaskNames, task, "unknown");
}

std::string_view to_string(SettingCode code) {
  return name_in(kSettingNames, code, "unknown");
}

std::string_view to_string(ResponseCode code) {
  return name_in(kResponseNames, code, "unknown");
}

std::optional<State> parse_state(std::string_view text) {
  return parse_name_or_code<State>(text, kStateNames);
}
std::optional<TaskCode> parse_task(std::string_view text) {
  return parse_name_or_code<TaskCode>(text, kTaskNames);
}
std::optional<SettingCode> parse_setting(std::string_view text) {
  return parse_name_or_code<SettingCode>(text, kSettingNames);
}
std::optional<ResponseCode> parse_response(std::string_view text) {
  return parse_name_or_code<ResponseCode>(text, kResponseNames);
}

PacketCode code_of(const Message& m) {
  return std::visit(Overloaded{[](const Empty&) { return PacketCode::empty; },
                               [](const Auth&) { return PacketCode::auth; },
                               [](const AuthReply&) { return PacketCode::auth_reply; },
                               [](const Task&) { return PacketCode::task; },
                               [](const Settings&) { return PacketCode::settings; },
                               [](const Response&) { return PacketCode::response; },
                               [](const Data&) { return PacketCode::data; }},
                    m);
}

std::string format_value(Word w, ValueType type, std::size_t size_bytes) {
  const std::uint32_t bits = w.bits & mask_of(size_bytes);
  if (type == ValueType::float32 && size_bytes == 4) {
    char buf[32];
    const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, w.as_f32());
    return ec == std::errc{} ? std::string(buf, end) : std::string("?");
  }
  if (type == ValueType::signed_int) {
    const std::uint32_t sign = 1u << (8 * std::min<std::size_t>(size_bytes, 4) - 1);
    const auto value =
        static_cast<std::int64_t>(bits) -
        ((bits & sign) != 0 ? static_cast<std::int64_t>(mask_of(size_bytes)) + 1 : 0);
    return std::to_string(value);
  }
  return std::to_string(bits);
}

std::optional<Word> parse_value(std::string_view text, ValueType type, std::size_t size_bytes) {
  if (size_bytes != 1 && size_bytes != 2 && size_bytes != 4) return std::nullopt;
  const char* first = text.data();
  const char* last = text.data() + text.size();
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
    if (text.size() - 2 > 2 * size_bytes) return std::nullopt;
    std::uint32_t bits = 0;
    const auto [end, ec] = std::from_chars(first + 2, last, bits, 16);
    if (ec != std::errc{} || end != last) return std::nullopt;
    return Word{bits};
  }
  if (type == ValueType::float32) {
    if (size_bytes != 4) return std::nullopt;
    float value = 0;
    const auto [end, ec] = std::from_chars(first, last, value);
    if (ec != std::errc{} || end != last) return std::nullopt;
    return Word::from_f32(value);
  }
  std::int64_t value = 0;
  const auto [end, ec] = std::from_chars(first, last, value);
  if (ec != std::errc{} || end != last || text.empty()) return std::nullopt;
  const auto span = static_cast<std::int64_t>(mask_of(size_bytes)) + 1;  // 2^(8 * size)
  const std::int64_t low = type == ValueType::signed_int ? -span / 2 : 0;
  const std::int64_t high = type == ValueType::signed_int ? span / 2 - 1 : span - 1;
  if (value < low || value > high) return std::nullopt;
  return Word{static_cast<std::uint32_t>(value) & mask_of(size_bytes)};
}

std::string describe(const Message& m, const Profile& profile) {
  std::ostringstream os;
  std::visit(
      Overloaded{[&](const Empty&) { os << "Empty"; },
                 [&](const Auth& v) {
                   os << "Auth text=\"" << escape(v.text) << '"';
                   if (v.text == profile.auth_text) os << " (profile string)";
                 },
                 [&](const AuthReply& v) {
                   os << "AuthReply device_code=" << int{v.device_code}
                      << " device_id=" << int{v.device_id} << " state=" << to_string(v.state);
                 },
                 [&](const Task& v) {
                   const auto t = static_cast<std::uint8_t>(v.task);
                   os << "Task coi=" << int{v.coi} << ' ' << name_or_number(t, kTaskNames, "task=");
                   const ValueType type =
                       t < kTaskCount ? profile.task_value_type[t] : ValueType::signed_int;
                   for (std::size_t i = 0; i < v.params.size(); ++i) {
                     const bool labelled = t < kTaskCount && i == 0 && !kTaskParamLabels[t].empty();
                     os << ' '
                        << (labelled ? std::string(kTaskParamLabels[t])
                                     : "param" + std::to_string(i + 1))
                        << '=' << format_value(v.params[i], type);
                   }
                 },
                 [&](const Settings& v) {
                   os << "Settings coi=" << int{v.coi};
                   if (v.params.empty()) os << " (none)";
                   for (const auto& s : v.params) {
                     const auto c = static_cast<std::uint8_t>(s.code);
                     const ValueType type =
                         c < kSettingCount ? profile.setting_value_type[c] : ValueType::signed_int;
                     os << ' ' << name_or_number(c, kSettingNames, "setting") << '='
                        << format_value(s.value, type);
                   }
                 },
                 [&](const Response& v) {
                   os << "Response coi=" << int{v.coi} << ' '
                      << name_or_number(static_cast<std::uint8_t>(v.code), kResponseNames, "code=");
                 },
                 [&](const Data& v) {
                   os << "Data state=" << to_string(v.state) << " timestamp_ms=" << v.timestamp_ms;
                   for (const auto& d : v.values) {
                     if (const auto* p = profile.data_parameter(d.code)) {
                       os << ' ' << p->name << (p->unit.empty() ? "" : "_") << p->unit << '='
                          << format_value(d.value, p->type, p->size_bytes);
                     } else {
                       os << " param" << int{d.code} << "=" << d.value.bits;
                     }
                   }
                   if (!v.unparsed.empty()) os << " unparsed=[" << to_hex(v.unparsed) << ']';
                 }},
      m);
  return os.str();
}

}  // namespace hil::protocol::wr8
