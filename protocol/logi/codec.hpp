#pragma once
// LOGI frames: LOGI:<payload>:<CS>#, encode and incremental decode.

#include <cstdint>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "protocol/common/bytes.hpp"
#include "protocol/common/decode.hpp"
#include "protocol/common/delimited_decoder.hpp"
#include "protocol/logi/message.hpp"

namespace hil::protocol::logi {

inline constexpr std::string_view kHeader = "LOGI:";
inline constexpr std::uint8_t kTail = '#';
/// A full STAT frame is about 110 bytes; 256 leaves room for fields a newer
/// firmware may add, and is the most a decoder ever holds.
inline constexpr std::size_t kDefaultMaxFrameBytes = 256;

/// The two ways a LOGI car can read its input (the car's profiles, see
/// protocol/common/car_profile.hpp). `guide` (the default): the stream rule
/// of the upper-computer guide's section 8 applied to the car's input,
/// header to first '#' (Decoder). `firmware`: the STM32 parser, one
/// hand-over at a time (decode_handover).
enum class Dialect : std::uint8_t { firmware, guide };

/// "firmware" or "guide".
std::string_view to_string(Dialect dialect);
/// The dialect of a LOGI profile name; empty is the default profile.
/// Throws protocol::ProfileError for a name that is not a LOGI profile.
Dialect dialect_named(std::string_view profile);

/// Low 8 bits of the byte sum of `base` ("LOGI:" + payload).
std::uint8_t checksum(std::string_view base);

/// The payload text of a message, e.g. "SP:050". Throws std::invalid_argument
/// for a message whose values the protocol cannot carry (a programming error).
std::string payload_of(const Message& m);

/// Wraps any payload text into a frame: "LOGI:" + payload + ":" + CS + "#".
/// Used for messages and for deliberately odd payloads (fault injection, QA).
std::string frame_text(std::string_view payload);

/// A complete frame for the message, e.g. "LOGI:SP:050:D7#".
std::string encode_text(const Message& m);
Bytes encode(const Message& m);

struct PayloadError {
  ErrorKind kind;  ///< bad_format, bad_value or unknown_code
  std::string detail;
  std::string context;  ///< the command code ("SP", "STAT", ...) when recognised
};

/// Parses payload text (no header, checksum or tail) into a message.
std::variant<Message, PayloadError> parse_payload(std::string_view payload);

struct DecoderOptions {
  std::size_t max_frame_bytes = kDefaultMaxFrameBytes;
  /// The profile requires uppercase checksum hex. When false, a lowercase
  /// checksum is an ErrorKind::lowercase_checksum error; when true the frame
  /// is delivered with `tolerated = lowercase_checksum`.
  bool accept_lowercase_checksum = false;
};

using Item = DecodeItem<Message>;

/// Checks and parses one complete candidate frame (header through tail).
Item decode_frame(ByteView raw, const DecoderOptions& options = {});

/// The STM32 firmware's shortest message: "LOGI:" and at least one byte
/// before ":CS#" (car_stm32f103vet6, Core/Bsp/protocol.c).
inline constexpr std::size_t kFirmwareMinBytes = 10;

/// The firmware's check of one hand-over: the bytes the Wi-Fi module passed
/// to the STM32 in one piece, taken as one message whatever they hold.
/// Refused: fewer than 10 bytes, a last byte other than '#', more than
/// `options.max_frame_bytes`; the rest is decode_frame's (the header at
/// index 0, the checksum field after the last ':', two hex digits, the sum
/// from index 0 up to that colon). So a frame with a line end after its
/// '#', two frames in one hand-over, bytes before the header and a frame in
/// two hand-overs are all refused, where Decoder (the guide's stream rule,
/// header to first '#') takes them (docs/protocols/logi.md, "Profiles").
Item decode_handover(ByteView handover, const DecoderOptions& options = {});

/// Incremental stream decoder, header to first '#'
/// (protocol/common/delimited_decoder.hpp); holds at most `max_frame_bytes`
/// bytes.
class Decoder : public DelimitedDecoder<Message, DecoderOptions> {
 public:
  explicit Decoder(DecoderOptions options = {});
};

}  // namespace hil::protocol::logi
