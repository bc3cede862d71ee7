#include "protocol/logi/codec.hpp"

#include <cstdio>
#include <limits>
#include <stdexcept>
#include <utility>

#include "protocol/common/car_profile.hpp"
#include "protocol/common/overloaded.hpp"
#include "protocol/common/text.hpp"

namespace hil::protocol::logi {
namespace {

constexpr char kHex[] = "0123456789ABCDEF";

std::string three_digits(int value) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%03d", value);
  return buf;
}

void require(bool ok, const char* what) {
  if (!ok) throw std::invalid_argument(std::string("LOGI encode: ") + what);
}

bool valid_extra_key(std::string_view key) {
  return !key.empty() && is_printable_ascii(key) &&
         key.find_first_of(":,#") == std::string_view::npos;
}

bool valid_extra_value(std::string_view value) {
  return is_printable_ascii(value) && value.find_first_of(",#") == std::string_view::npos;
}

std::string status_payload(const Status& s) {
  require(s.speed_percent >= 0 && s.speed_percent <= 100, "STAT SP outside 0..100");
  require(s.station >= 0 && s.station <= 999, "STAT STA outside 0..999");
  require(s.distance_cm >= 0, "STAT DIS negative");
  require(s.track_mask <= 0x0F, "STAT TRK has more than four channels");
  std::string p = "STAT:SP:" + three_digits(s.speed_percent) + ",STA:" + three_digits(s.station) +
                  ",RUN:" + (s.running ? "1" : "0") + ",MODE:" + std::string(to_string(s.mode)) +
                  ",MAN:" + std::string(to_string(s.manual)) +
                  ",DIS:" + std::to_string(s.distance_cm) + ",TRK:";
  for (int bit = 3; bit >= 0; --bit)
    p.push_back(((s.track_mask >> bit) & 1) != 0 ? '1' : '0');
  p += ",DEV:" + std::to_string(s.deviation) + ",OBS:" + (s.obstacle ? "1" : "0") +
       ",RPM:" + std::to_string(s.rpm[0]) + ':' + std::to_string(s.rpm[1]) + ':' +
       std::to_string(s.rpm[2]) + ':' + std::to_string(s.rpm[3]);
  for (const auto& [key, value] : s.extra) {
    require(valid_extra_key(key) && valid_extra_value(value),
            "STAT extra field has a reserved character");
    p += ',' + key + ':' + value;
  }
  return p;
}

PayloadError fail(ErrorKind kind, std::string detail, std::string_view context) {
  return PayloadError{kind, std::move(detail), std::string(context)};
}

// Three decimal digits, as the command set writes them (SP:xxx, GS:xxx).
std::optional<int> three_digit_arg(std::string_view arg) {
  if (arg.size() != 3) return std::nullopt;
  const auto v = parse_decimal(arg, false);
  if (!v) return std::nullopt;
  return static_cast<int>(*v);
}

std::variant<Message, PayloadError> parse_status(std::string_view body) {
  constexpr std::string_view ctx = "STAT";
  Status s;
  // Bit per known key, so a missing or repeated one can be named.
  enum Key { kSp, kSta, kRun, kMode, kMan, kDis, kTrk, kDev, kObs, kRpm, kKeys };
  constexpr std::array<std::string_view, kKeys> names = {"SP",  "STA", "RUN", "MODE", "MAN",
                                                         "DIS", "TRK", "DEV", "OBS",  "RPM"};
  std::array<bool, kKeys> seen{};
  for (const std::string_view field : split(body, ',')) {
    const std::size_t colon = field.find(':');
    if (colon == std::string_view::npos || colon == 0) {
      return fail(ErrorKind::bad_format, "STAT field '" + std::string(field) + "' is not KEY:VALUE",
                  ctx);
    }
    const std::string_view key = field.substr(0, colon);
    const std::string_view value = field.substr(colon + 1);
    std::size_t k = 0;
    while (k < kKeys && names[k] != key)
      ++k;
    if (k == kKeys) {
      s.extra.emplace_back(std::string(key), std::string(value));
      continue;
    }
    if (seen[k])
      return fail(ErrorKind::bad_format, "STAT key " + std::string(key) + " repeated", ctx);
    seen[k] = true;
    const auto bad = [&](const char* expected) {
      return fail(ErrorKind::bad_format,
                  "STAT " + std::string(key) + ":" + std::string(value) + ": expected " + expected,
                  ctx);
    };
    const auto flag = [&](bool& out) {
      if (value != "0" && value != "1") return false;
      out = value == "1";
      return true;
    };
    // A decimal of at most `digits` digits and at most `max`, signed when `allow_sign`.
    const auto whole = [&](int& out, bool allow_sign, std::size_t digits = 9,
                           long long max = std::numeric_limits<long long>::max()) {
      const auto v = parse_decimal(value, allow_sign, false, digits);
      if (!v || *v > max) return false;
      out = static_cast<int>(*v);
      return true;
    };
    switch (k) {
      case kSp:
        if (!whole(s.speed_percent, false, 3, 100)) return bad("speed percent 0..100");
        break;
      case kSta:
        if (!whole(s.station, false, 3)) return bad("station 0..999");
        break;
      case kRun:
        if (!flag(s.running)) return bad("0 or 1");
        break;
      case kMode: {
        const auto m = parse_mode(value);
        if (!m) return bad("AUTO or MAN");
        s.mode = *m;
        break;
      }
      case kMan: {
        const auto d = parse_direction(value);
        if (!d) return bad("a direction (STOP, FWD, BWD, LEFT, RIGHT, LF, RF, LB, RB, CW, CCW)");
        s.manual = *d;
        break;
      }
      case kDis:
        if (!whole(s.distance_cm, false)) return bad("distance in whole cm");
        break;
      case kTrk: {
        if (value.size() != 4 || value.find_first_not_of("01") != std::string_view::npos) {
          return bad("four 0/1 channels H4H3H2H1");
        }
        s.track_mask = 0;
        for (const char c : value)
          s.track_mask = static_cast<std::uint8_t>((s.track_mask << 1) | (c - '0'));
        break;
      }
      case kDev:
        if (!whole(s.deviation, true)) return bad("signed integer deviation");
        break;
      case kObs:
        if (!flag(s.obstacle)) return bad("0 or 1");
        break;
      case kRpm: {
        const auto parts = split(value, ':');
        if (parts.size() != 4) return bad("four RPM values M1:M2:M3:M4");
        for (std::size_t i = 0; i < 4; ++i) {
          const auto v = parse_decimal(parts[i], true);
          if (!v) return bad("four signed RPM values M1:M2:M3:M4");
          s.rpm[i] = static_cast<int>(*v);
        }
        break;
      }
      default:
        break;
    }
  }
  for (std::size_t k = 0; k < kKeys; ++k) {
    if (!seen[k])
      return fail(ErrorKind::bad_format, "STAT lacks key " + std::string(names[k]), ctx);
  }
  return s;
}

}  // namespace

std::uint8_t checksum(std::string_view base) {
  unsigned sum = 0;
  for (const char c : base)
    sum += static_cast<unsigned char>(c);
  return static_cast<std::uint8_t>(sum & 0xFFu);
}

std::string payload_of(const Message& m) {
  return std::visit(
      Overloaded{[](const SetSpeed& v) {
                   require(v.percent >= 0 && v.percent <= 100, "SP outside 0..100");
                   return "SP:" + three_digits(v.percent);
                 },
                 [](const SetRun& v) { return std::string(v.run ? "ST:RUN" : "ST:STOP"); },
                 [](const SetStation& v) {
                   require(v.station >= 0 && v.station <= 999, "GS outside 000..999");
                   return "GS:" + three_digits(v.station);
                 },
                 [](const SetMode& v) { return "MD:" + std::string(to_string(v.mode)); },
                 [](const Move& v) { return "MV:" + std::string(to_string(v.direction)); },
                 [](const Status& v) { return status_payload(v); },
                 [](const Feedback& v) {
                   return "FB:" + std::string(to_string(v.command)) + (v.accepted ? ":1" : ":0");
                 }},
      m);
}

std::string frame_text(std::string_view payload) {
  std::string frame(kHeader);
  frame += payload;
  const std::uint8_t cs = checksum(frame);
  frame.push_back(':');
  frame.push_back(kHex[cs >> 4]);
  frame.push_back(kHex[cs & 0x0F]);
  frame.push_back(static_cast<char>(kTail));
  return frame;
}

std::string encode_text(const Message& m) {
  return frame_text(payload_of(m));
}

Bytes encode(const Message& m) {
  return to_bytes(encode_text(m));
}

std::variant<Message, PayloadError> parse_payload(std::string_view payload) {
  const std::size_t colon = payload.find(':');
  if (colon == std::string_view::npos) {
    return fail(ErrorKind::bad_format,
                "payload '" + std::string(payload) + "' has no ':' after its code", payload);
  }
  const std::string_view code = payload.substr(0, colon);
  const std::string_view arg = payload.substr(colon + 1);
  const auto bad_arg = [&](ErrorKind kind, const char* expected) {
    return fail(kind, std::string(code) + ":" + std::string(arg) + ": expected " + expected, code);
  };
  if (code == "SP") {
    const auto v = three_digit_arg(arg);
    if (!v) return bad_arg(ErrorKind::bad_format, "three digits 000..100");
    if (*v > 100) return bad_arg(ErrorKind::bad_value, "speed percent 000..100");
    return SetSpeed{*v};
  }
  if (code == "ST") {
    if (arg == "RUN") return SetRun{true};
    if (arg == "STOP") return SetRun{false};
    return bad_arg(ErrorKind::bad_format, "RUN or STOP");
  }
  if (code == "GS") {
    const auto v = three_digit_arg(arg);
    if (!v) return bad_arg(ErrorKind::bad_format, "three digits 000..999");
    return SetStation{*v};
  }
  if (code == "MD") {
    const auto m = parse_mode(arg);
    if (!m) return bad_arg(ErrorKind::bad_format, "MAN or AUTO");
    return SetMode{*m};
  }
  if (code == "MV") {
    const auto d = parse_direction(arg);
    if (!d)
      return bad_arg(ErrorKind::bad_format,
                     "FWD, BWD, LEFT, RIGHT, LF, RF, LB, RB, CW, CCW or STOP");
    return Move{*d};
  }
  if (code == "STAT") return parse_status(arg);
  if (code == "FB") {
    const std::size_t c2 = arg.find(':');
    if (c2 == std::string_view::npos) return bad_arg(ErrorKind::bad_format, "<CMD>:<0|1>");
    const auto cmd = parse_command(arg.substr(0, c2));
    const std::string_view flag = arg.substr(c2 + 1);
    if (!cmd)
      return bad_arg(ErrorKind::bad_format, "a command SP, ST, GS, MD or MV before the flag");
    if (flag != "0" && flag != "1") return bad_arg(ErrorKind::bad_format, "flag 0 or 1");
    return Feedback{*cmd, flag == "1"};
  }
  return fail(ErrorKind::unknown_code, "unknown command code '" + std::string(code) + "'", code);
}

Item decode_frame(ByteView raw, const DecoderOptions& options) {
  const std::string_view text(reinterpret_cast<const char*>(raw.data()), raw.size());
  const auto error = [&](ErrorKind kind, std::string detail, std::string context = {}) {
    return Item{
        DecodeError{kind, Bytes(raw.begin(), raw.end()), std::move(detail), std::move(context)}};
  };
  if (!text.starts_with(kHeader) || text.size() < kHeader.size() + 1 ||
      static_cast<std::uint8_t>(text.back()) != kTail) {
    return error(ErrorKind::bad_format, "not a LOGI:...# frame");
  }
  const std::string_view inner = text.substr(kHeader.size(), text.size() - kHeader.size() - 1);
  const std::size_t last_colon = inner.rfind(':');
  if (last_colon == std::string_view::npos) {
    return error(ErrorKind::bad_format, "no ':' before the checksum");
  }
  const std::string_view payload = inner.substr(0, last_colon);
  const std::string_view cs_text = inner.substr(last_colon + 1);
  const std::string_view code = payload.substr(0, payload.find(':'));
  bool lowercase = false;
  const auto cs = parse_hex_byte(cs_text, &lowercase);
  if (!cs) {
    return error(ErrorKind::bad_format,
                 "checksum '" + escape(to_bytes(cs_text)) + "' is not two hex digits",
                 std::string(code));
  }
  const std::uint8_t expected = checksum(text.substr(0, kHeader.size() + payload.size()));
  if (*cs != expected) {
    return error(ErrorKind::bad_checksum,
                 "checksum " + std::string(cs_text) + ", computed " + kHex[expected >> 4] +
                     kHex[expected & 0x0F],
                 std::string(code));
  }
  if (!is_printable_ascii(payload)) {
    return error(ErrorKind::bad_format, "payload has a byte outside printable ASCII",
                 std::string(code));
  }
  std::optional<ErrorKind> tolerated;
  if (lowercase) {
    if (!options.accept_lowercase_checksum) {
      return error(
          ErrorKind::lowercase_checksum,
          "checksum " + std::string(cs_text) + " is lowercase; the protocol requires uppercase hex",
          std::string(code));
    }
    tolerated = ErrorKind::lowercase_checksum;
  }
  auto parsed = parse_payload(payload);
  if (auto* e = std::get_if<PayloadError>(&parsed)) {
    return error(e->kind, std::move(e->detail), std::move(e->context));
  }
  return Item{Frame<Message>{std::get<Message>(std::move(parsed)), Bytes(raw.begin(), raw.end()),
                             tolerated}};
}

std::string_view to_string(Dialect dialect) {
  return dialect == Dialect::firmware ? "firmware" : "guide";
}

Dialect dialect_named(std::string_view profile) {
  const CarProfile& p = find_car_profile("logi", profile);
  return p.name == "guide" ? Dialect::guide : Dialect::firmware;
}

Item decode_handover(ByteView raw, const DecoderOptions& options) {
  const auto error = [&](ErrorKind kind, std::string detail) {
    return Item{DecodeError{kind, Bytes(raw.begin(), raw.end()), std::move(detail), {}}};
  };
  if (raw.size() > options.max_frame_bytes) {
    return error(ErrorKind::oversized, "a hand-over of " + std::to_string(raw.size()) +
                                           " bytes, over the " +
                                           std::to_string(options.max_frame_bytes) + "-byte bound");
  }
  if (raw.size() < kFirmwareMinBytes) {
    return error(ErrorKind::bad_format, "a hand-over of " + std::to_string(raw.size()) +
                                            " bytes; the firmware takes 10 or more");
  }
  if (raw.back() != kTail) {
    return error(ErrorKind::bad_format,
                 "the hand-over ends with " + hex_literal(raw.back()) + ", not '#'");
  }
  return decode_frame(raw, options);
}

Decoder::Decoder(DecoderOptions options)
    : DelimitedDecoder(options, kHeader, kTail, options.max_frame_bytes, decode_frame) {}

}  // namespace hil::protocol::logi
