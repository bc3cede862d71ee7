#pragma once
// Arduino serial frames ^SEQ|CMD|PAYLOAD*CS$: encode, incremental decode, and
// the error-to-NACK mapping the mock firmware answers with.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "protocol/arduino/message.hpp"
#include "protocol/common/bytes.hpp"
#include "protocol/common/decode.hpp"
#include "protocol/common/delimited_decoder.hpp"

namespace hil::protocol::arduino {

inline constexpr std::uint8_t kStart = '^';
inline constexpr std::uint8_t kEnd = '$';
inline constexpr char kFieldSeparator = '|';
inline constexpr char kChecksumSeparator = '*';

/// The PC side's receive guard: a frame (markers included) longer than this
/// is dropped. It is also the most a default decoder ever holds.
inline constexpr std::size_t kMaxFrameBytes = 256;
/// The firmware's own receive buffer: the longest frame it can take in,
/// markers included. DecoderOptions::firmware() decodes with this bound.
inline constexpr std::size_t kFirmwareMaxFrameBytes = 96;
/// The shortest well-formed frame, "^00|S|*00$"; a smaller bound is refused.
inline constexpr std::size_t kMinFrameBytes = 10;

/// Signed M/R arguments are the firmware's 16-bit int.
inline constexpr int kMinSignedArg = -32768;
inline constexpr int kMaxSignedArg = 32767;
inline constexpr int kMaxPwm = 255;

/// The two dialects of the protocol (the car's profiles, see
/// protocol/common/car_profile.hpp): the real sketch and its client
/// (`firmware`), and the README's examples (`readme`). They differ in what a
/// request without an argument carries (one space, or nothing) and in the
/// board's replies (docs/protocols/arduino.md, "Profiles").
enum class Dialect : std::uint8_t { firmware, readme };

/// The default profile's dialect: the real sketch, the board people own
/// (the registry's default, protocol/common/car_profile.cpp, says the same).
inline constexpr Dialect kDefaultDialect = Dialect::firmware;

/// "firmware" or "readme".
std::string_view to_string(Dialect dialect);
/// The dialect of an Arduino profile name; empty is the default profile.
/// Throws protocol::ProfileError for a name that is not an Arduino profile.
Dialect dialect_named(std::string_view profile);

/// The payload a request without an argument carries in a dialect: one
/// space for the real sketch, which refuses an empty payload, else nothing.
std::string_view empty_payload(Dialect dialect);

/// XOR of every byte of `body` (the text between '^' and '*': SEQ|CMD|PAYLOAD).
std::uint8_t checksum(std::string_view body);

/// A frame's three fields before any typing: the generic layer under Message.
struct Envelope {
  std::uint8_t seq = 0;
  std::string cmd;
  std::string payload;
  friend bool operator==(const Envelope&, const Envelope&) = default;
};

/// True for characters a CMD or PAYLOAD field may hold: printable ASCII
/// except the markers and separators ^ $ * |.
bool is_field_char(char c);

/// "^" + body + "*" + CS + "$" with the correct uppercase checksum. `body` is
/// taken as is (it need not be SEQ|CMD|PAYLOAD): for deliberately odd frames.
std::string frame_body(std::string_view body);

/// The frame for an envelope's fields, unchecked (any cmd/payload text is
/// framed, for fault injection and QA). SEQ is written as two uppercase hex digits.
std::string frame_text(const Envelope& envelope);

/// The fields of a message. Throws std::invalid_argument for a value the
/// protocol cannot carry: V outside 0..255, M/R outside the 16-bit range, ACK
/// or NACK text with a character that is not a field character.
Envelope to_envelope(const Message& m);

/// A complete frame, e.g. "^02|V|160*63$". Throws like to_envelope, and also
/// when the frame would exceed kMaxFrameBytes (no receiver would take it).
std::string encode_text(const Message& m);
Bytes encode(const Message& m);
/// The frame in a dialect: in `firmware` a request without an argument
/// carries one space ("^01|PING| *31$", as the real client sends it), which
/// the real sketch needs; in `readme` it is encode_text(m).
std::string encode_text(const Message& m, Dialect dialect);

/// Why an envelope does not make a typed message.
struct PayloadError {
  ErrorKind kind;  ///< bad_format, bad_value or unknown_code
  std::string detail;
  std::string context;  ///< the CMD token
};

/// Types an envelope's CMD and PAYLOAD (the SEQ is copied).
std::variant<Message, PayloadError> to_message(const Envelope& envelope);
/// to_message as a client of `dialect` means the frame: in `firmware` the
/// one space of a request without an argument ("^01|PING| *31$", the real
/// client's PING) types as that request; in `readme` it is to_message.
std::variant<Message, PayloadError> to_message(const Envelope& envelope, Dialect dialect);

struct DecoderOptions {
  /// Longest frame, markers included; also the most the decoder holds.
  /// At least kMinFrameBytes.
  std::size_t max_frame_bytes = kMaxFrameBytes;
  /// The protocol does not say whether checksum hex is upper or lower case.
  /// When true, a lowercase checksum is accepted and the frame comes out with
  /// `tolerated = lowercase_checksum`; when false it is a lowercase_checksum
  /// error (which the firmware answers with NACK BAD_CS).
  bool accept_lowercase_checksum = true;

  /// The firmware's view: frames over kFirmwareMaxFrameBytes are oversized.
  static DecoderOptions firmware() {
    return DecoderOptions{.max_frame_bytes = kFirmwareMaxFrameBytes};
  }
};

using Item = DecodeItem<Message>;

/// Checks framing, checksum, field count and SEQ of one complete candidate
/// frame ('^' through '$'), without looking at CMD or PAYLOAD meaning.
/// A frame's `tolerated` is set as decode_frame would set it.
DecodeItem<Envelope> parse_envelope(ByteView raw, const DecoderOptions& options = {});

/// parse_envelope, then to_message.
Item decode_frame(ByteView raw, const DecoderOptions& options = {});
/// parse_envelope, then to_message in `dialect`.
Item decode_frame(ByteView raw, Dialect dialect, const DecoderOptions& options = {});

/// The NACK code the firmware answers a decode error with; nullopt when there
/// is no complete frame to answer (garbage, oversized, truncated, or a frame
/// cut short by the next '^').
std::optional<NackCode> nack_for(const DecodeError& error);

/// The SEQ of a frame's raw bytes when it starts "^HH|" with two hex digits,
/// so a NACK can carry the sequence number of the request it refuses.
std::optional<std::uint8_t> sequence_of(ByteView raw);

/// The NACK the firmware answers a decode error with: the code from nack_for,
/// with the request's SEQ from sequence_of, or SEQ 00 when the SEQ cannot be
/// read (the protocol leaves that case open). nullopt when nack_for is.
std::optional<Message> nack_response(const DecodeError& error);

/// Incremental stream decoder for either direction, '^' to '$'
/// (protocol/common/delimited_decoder.hpp). Holds at most `max_frame_bytes`
/// bytes: 256 by default (the PC's receive guard), 96 with
/// DecoderOptions::firmware() (the firmware's buffer).
class Decoder : public DelimitedDecoder<Message, DecoderOptions> {
 public:
  /// Throws std::invalid_argument when max_frame_bytes < kMinFrameBytes.
  explicit Decoder(DecoderOptions options = {});
};

}  // namespace hil::protocol::arduino
