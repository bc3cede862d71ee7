#include "protocol/arduino/codec.hpp"

#include <stdexcept>
#include <utility>

#include "protocol/common/car_profile.hpp"
#include "protocol/common/overloaded.hpp"
#include "protocol/common/text.hpp"

namespace hil::protocol::arduino {
namespace {

constexpr char kHex[] = "0123456789ABCDEF";
// A CMD longer than this is not echoed as an error's context: the known
// tokens are at most six characters, and a context is meant to be short.
constexpr std::size_t kMaxContextChars = 16;
// Enough digits that any long number is reported as out of range rather than
// as not a number, and few enough that it cannot overflow a long long.
constexpr std::size_t kMaxDigits = 18;

std::string hex_byte(std::uint8_t v) {
  return {kHex[v >> 4], kHex[v & 0x0F]};
}

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("Arduino encode: " + what);
}

bool all_field_chars(std::string_view text) {
  for (const char c : text) {
    if (!is_field_char(c)) return false;
  }
  return true;
}

// Where the first character outside the field alphabet is, for error details.
std::string first_bad_char(std::string_view text) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (!is_field_char(text[i])) {
      const auto b = static_cast<std::uint8_t>(text[i]);
      return "byte 0x" + hex_byte(b) + " at offset " + std::to_string(i);
    }
  }
  return "none";
}

PayloadError fail(ErrorKind kind, std::string detail, std::string_view context) {
  return PayloadError{kind, std::move(detail), std::string(context)};
}

bool takes_no_payload(std::string_view cmd) {
  return cmd == "PING" || cmd == "STATUS" || cmd == "S" || cmd == "B" || cmd == "I" ||
         cmd == "HELP";
}

Body empty_body(std::string_view cmd) {
  if (cmd == "PING") return Ping{};
  if (cmd == "STATUS") return StatusRequest{};
  if (cmd == "S") return Stop{};
  if (cmd == "B") return SonarRead{};
  if (cmd == "I") return IrRead{};
  return Help{};
}

// The shared framer's error, with the marker characters named and the
// command (when one can be read) as context.
DecodeError framing_error(DelimitedFramer::Event&& event, std::size_t max_frame_bytes) {
  const DelimitedFramer::Kind kind = event.kind;
  DecodeError e = to_error(std::move(event), max_frame_bytes);
  const std::string n = std::to_string(e.raw.size());
  if (kind == DelimitedFramer::Kind::interrupted) {
    e.detail = "frame cut short: a new '^' came after " + n + " byte(s), before any '$' end marker";
  } else if (kind == DelimitedFramer::Kind::oversized) {
    e.detail = "no '$' end marker within " + std::to_string(max_frame_bytes) +
               " bytes of the '^' (frame bound); " + n + " byte(s) dropped";
  } else if (kind == DelimitedFramer::Kind::truncated) {
    e.detail = "stream ended " + n + " byte(s) into a frame, before its '$' end marker";
  }
  if (kind != DelimitedFramer::Kind::garbage) {
    const std::string_view text(reinterpret_cast<const char*>(e.raw.data()), e.raw.size());
    const auto fields = split(text, kFieldSeparator);
    if (fields.size() >= 3 && !fields[1].empty() && fields[1].size() <= kMaxContextChars &&
        all_field_chars(fields[1])) {
      e.context = std::string(fields[1]);
    }
  }
  return e;
}

}  // namespace

std::string_view to_string(Dialect dialect) {
  return dialect == Dialect::firmware ? "firmware" : "readme";
}

Dialect dialect_named(std::string_view profile) {
  const CarProfile& p = find_car_profile("arduino", profile);
  return p.name == "readme" ? Dialect::readme : Dialect::firmware;
}

std::string_view empty_payload(Dialect dialect) {
  return dialect == Dialect::firmware ? " " : "";
}

std::uint8_t checksum(std::string_view body) {
  std::uint8_t x = 0;
  for (const char c : body)
    x = static_cast<std::uint8_t>(x ^ static_cast<std::uint8_t>(c));
  return x;
}

bool is_field_char(char c) {
  const auto u = static_cast<unsigned char>(c);
  return u >= 0x20 && u <= 0x7E && c != '^' && c != '$' && c != '*' && c != '|';
}

std::string frame_body(std::string_view body) {
  std::string frame;
  frame.reserve(body.size() + 5);
  frame.push_back(static_cast<char>(kStart));
  frame.append(body);
  frame.push_back(kChecksumSeparator);
  frame += hex_byte(checksum(body));
  frame.push_back(static_cast<char>(kEnd));
  return frame;
}

std::string frame_text(const Envelope& envelope) {
  return frame_body(hex_byte(envelope.seq) + kFieldSeparator + envelope.cmd + kFieldSeparator +
                    envelope.payload);
}

Envelope to_envelope(const Message& m) {
  Envelope e{m.seq, std::string(command_of(m.body)), {}};
  std::visit(
      Overloaded{[&](const SetSpeed& v) {
                   require(v.pwm >= 0 && v.pwm <= kMaxPwm, "V pwm outside 0..255");
                   e.payload = std::to_string(v.pwm);
                 },
                 [&](const Move& v) {
                   require(v.distance_cm >= kMinSignedArg && v.distance_cm <= kMaxSignedArg,
                           "M distance outside -32768..32767 cm");
                   e.payload = std::to_string(v.distance_cm);
                 },
                 [&](const Rotate& v) {
                   require(v.angle_deg >= kMinSignedArg && v.angle_deg <= kMaxSignedArg,
                           "R angle outside -32768..32767 degrees");
                   e.payload = std::to_string(v.angle_deg);
                 },
                 [&](const Ack& v) {
                   require(all_field_chars(v.info),
                           "ACK info has a character outside printable ASCII or one of ^ $ * |");
                   e.payload = v.info;
                 },
                 [&](const Nack& v) {
                   if (const auto* code = std::get_if<NackCode>(&v.error)) {
                     e.payload = std::string(to_string(*code));
                   } else {
                     const auto& text = std::get<std::string>(v.error);
                     require(all_field_chars(text),
                             "NACK text has a character outside printable ASCII or one of ^ $ * |");
                     e.payload = text;
                   }
                 },
                 [](const auto&) {}},
      m.body);
  return e;
}

std::string encode_text(const Message& m) {
  std::string frame = frame_text(to_envelope(m));
  require(frame.size() <= kMaxFrameBytes,
          "frame of " + std::to_string(frame.size()) + " bytes exceeds the 256-byte receive guard");
  return frame;
}

Bytes encode(const Message& m) {
  return to_bytes(encode_text(m));
}

std::string encode_text(const Message& m, Dialect dialect) {
  if (dialect == Dialect::readme || !is_request(m.body) || !takes_no_payload(command_of(m.body))) {
    return encode_text(m);
  }
  Envelope e = to_envelope(m);
  e.payload = std::string(empty_payload(dialect));
  return frame_text(e);
}

std::variant<Message, PayloadError> to_message(const Envelope& envelope, Dialect dialect) {
  if (dialect == Dialect::firmware && takes_no_payload(envelope.cmd) &&
      envelope.payload == empty_payload(dialect)) {
    Envelope bare = envelope;
    bare.payload.clear();
    return to_message(bare);
  }
  return to_message(envelope);
}

std::variant<Message, PayloadError> to_message(const Envelope& envelope) {
  const std::string_view cmd = envelope.cmd;
  const std::string_view payload = envelope.payload;
  const auto message = [&](Body body) { return Message{envelope.seq, std::move(body)}; };
  if (takes_no_payload(cmd)) {
    if (!payload.empty()) {
      return fail(ErrorKind::bad_format,
                  std::string(cmd) + " takes no payload, got '" + std::string(payload) + "'", cmd);
    }
    return message(empty_body(cmd));
  }
  if (cmd == "V") {
    // The firmware answers both a non-number and an out-of-range speed with
    // BAD_V, so both are bad_value here.
    const auto v = parse_decimal(payload, true, true, kMaxDigits);
    if (!v) {
      return fail(ErrorKind::bad_value,
                  "V payload '" + std::string(payload) + "' is not a whole number 0..255", cmd);
    }
    if (*v < 0 || *v > kMaxPwm) {
      return fail(ErrorKind::bad_value, "V pwm " + std::to_string(*v) + " is outside 0..255", cmd);
    }
    return message(SetSpeed{static_cast<int>(*v)});
  }
  if (cmd == "M" || cmd == "R") {
    const char* what = cmd == "M" ? "distance in cm" : "angle in degrees";
    const auto v = parse_decimal(payload, true, true, kMaxDigits);
    if (!v) {
      return fail(ErrorKind::bad_format,
                  std::string(cmd) + " payload '" + std::string(payload) +
                      "' is not a signed whole " + what,
                  cmd);
    }
    if (*v < kMinSignedArg || *v > kMaxSignedArg) {
      return fail(
          ErrorKind::bad_value,
          std::string(cmd) + " " + what + " " + std::to_string(*v) + " is outside -32768..32767",
          cmd);
    }
    const int value = static_cast<int>(*v);
    return message(cmd == "M" ? Body{Move{value}} : Body{Rotate{value}});
  }
  if (cmd == "ACK") return message(Ack{std::string(payload)});
  if (cmd == "NACK") return message(nack_from_text(payload));
  return fail(ErrorKind::unknown_code, "unknown command '" + std::string(cmd) + "'", cmd);
}

DecodeItem<Envelope> parse_envelope(ByteView raw, const DecoderOptions& options) {
  const std::string_view text(reinterpret_cast<const char*>(raw.data()), raw.size());
  const auto error = [&](ErrorKind kind, std::string detail, std::string context) {
    return DecodeItem<Envelope>{
        DecodeError{kind, Bytes(raw.begin(), raw.end()), std::move(detail), std::move(context)}};
  };
  if (text.size() < 2 || static_cast<std::uint8_t>(text.front()) != kStart ||
      static_cast<std::uint8_t>(text.back()) != kEnd) {
    return error(ErrorKind::bad_format, "not a ^...$ frame", {});
  }
  const std::string_view inner = text.substr(1, text.size() - 2);
  // The checksum follows the last '*', so the separator is found even when a
  // corrupted payload holds another '*' (which the checksum then catches).
  const std::size_t star = inner.rfind(kChecksumSeparator);
  const std::string_view body =
      inner.substr(0, star == std::string_view::npos ? inner.size() : star);
  const auto fields = split(body, kFieldSeparator);
  std::string context;
  if (fields.size() >= 2 && !fields[1].empty() && fields[1].size() <= kMaxContextChars &&
      all_field_chars(fields[1])) {
    context = std::string(fields[1]);
  }
  if (star == std::string_view::npos) {
    return error(ErrorKind::bad_format, "no '*' checksum separator before the '$' end marker",
                 context);
  }
  const std::string_view cs_text = inner.substr(star + 1);
  bool lowercase = false;
  const auto cs = parse_hex_byte(cs_text, &lowercase);
  if (!cs) {
    return error(ErrorKind::bad_format,
                 "checksum '" + escape(to_bytes(cs_text)) + "' after '*' is not two hex digits",
                 context);
  }
  const std::uint8_t expected = checksum(body);
  if (*cs != expected) {
    return error(ErrorKind::bad_checksum,
                 "checksum " + std::string(cs_text) + ", computed " + hex_byte(expected) +
                     " (XOR of the bytes between '^' and '*')",
                 context);
  }
  std::optional<ErrorKind> tolerated;
  if (lowercase) {
    if (!options.accept_lowercase_checksum) {
      return error(ErrorKind::lowercase_checksum,
                   "checksum " + std::string(cs_text) + " is lowercase; uppercase hex required",
                   context);
    }
    tolerated = ErrorKind::lowercase_checksum;
  }
  if (fields.size() != 3) {
    return error(
        ErrorKind::bad_format,
        "expected 3 fields SEQ|CMD|PAYLOAD before '*', found " + std::to_string(fields.size()),
        context);
  }
  const auto seq = parse_hex_byte(fields[0]);
  if (!seq) {
    // Context "SEQ" rather than the command: it is what tells a bad sequence
    // number (NACK BAD_SEQ) from other format errors (NACK BAD_FMT).
    return error(ErrorKind::bad_format,
                 "SEQ '" + escape(to_bytes(fields[0])) + "' is not two hex digits" +
                     (context.empty() ? std::string() : " (command " + context + ")"),
                 "SEQ");
  }
  if (fields[1].empty()) return error(ErrorKind::bad_format, "CMD field is empty", {});
  if (!all_field_chars(fields[1])) {
    return error(ErrorKind::bad_format,
                 "CMD has a character outside printable ASCII or one of ^ $ * |: " +
                     first_bad_char(fields[1]),
                 {});
  }
  if (!all_field_chars(fields[2])) {
    return error(ErrorKind::bad_format,
                 "payload has a character outside printable ASCII or one of ^ $ * |: " +
                     first_bad_char(fields[2]),
                 context);
  }
  return DecodeItem<Envelope>{
      Frame<Envelope>{Envelope{*seq, std::string(fields[1]), std::string(fields[2])},
                      Bytes(raw.begin(), raw.end()), tolerated}};
}

Item decode_frame(ByteView raw, const DecoderOptions& options) {
  return decode_frame(raw, Dialect::readme, options);
}

Item decode_frame(ByteView raw, Dialect dialect, const DecoderOptions& options) {
  auto parsed = parse_envelope(raw, options);
  if (auto* e = std::get_if<DecodeError>(&parsed)) return Item{std::move(*e)};
  auto& frame = std::get<Frame<Envelope>>(parsed);
  auto typed = to_message(frame.message, dialect);
  if (auto* e = std::get_if<PayloadError>(&typed)) {
    return Item{
        DecodeError{e->kind, std::move(frame.raw), std::move(e->detail), std::move(e->context)}};
  }
  // Filled in place: building the frame as a temporary makes GCC 12 report
  // a false "maybe uninitialized" inside the nested variants.
  Item item{std::in_place_type<Frame<Message>>};
  auto& out = std::get<Frame<Message>>(item);
  out.message = std::get<Message>(std::move(typed));
  out.raw = std::move(frame.raw);
  out.tolerated = frame.tolerated;
  return item;
}

std::optional<NackCode> nack_for(const DecodeError& error) {
  // Only a complete frame is answered; the firmware silently drops anything
  // it never saw end.
  if (error.raw.size() < 2 || error.raw.front() != kStart || error.raw.back() != kEnd) {
    return std::nullopt;
  }
  switch (error.kind) {
    case ErrorKind::bad_checksum:
    case ErrorKind::lowercase_checksum:
      return NackCode::bad_cs;
    case ErrorKind::bad_format:
      return error.context == "SEQ" ? NackCode::bad_seq : NackCode::bad_fmt;
    case ErrorKind::bad_value:
      // Only V has its own code; an M/R argument outside the firmware's int
      // is a format problem from the firmware's point of view.
      return error.context == "V" ? NackCode::bad_v : NackCode::bad_fmt;
    case ErrorKind::unknown_code:
      return NackCode::bad_cmd;
    case ErrorKind::garbage:
    case ErrorKind::oversized:
    case ErrorKind::truncated:
      return std::nullopt;
  }
  return std::nullopt;
}

std::optional<std::uint8_t> sequence_of(ByteView raw) {
  if (raw.size() < 4 || raw[0] != kStart || raw[3] != static_cast<std::uint8_t>(kFieldSeparator)) {
    return std::nullopt;
  }
  const std::string_view digits(reinterpret_cast<const char*>(raw.data()) + 1, 2);
  return parse_hex_byte(digits);
}

std::optional<Message> nack_response(const DecodeError& error) {
  const auto code = nack_for(error);
  if (!code) return std::nullopt;
  return Message{sequence_of(error.raw).value_or(0), Nack{*code}};
}

Decoder::Decoder(DecoderOptions options)
    : DelimitedDecoder(options, std::string_view("^", 1), kEnd,
                       options.max_frame_bytes >= kMinFrameBytes
                           ? options.max_frame_bytes
                           : throw std::invalid_argument("Arduino decoder: max_frame_bytes below " +
                                                         std::to_string(kMinFrameBytes)),
                       decode_frame, framing_error) {}

}  // namespace hil::protocol::arduino
